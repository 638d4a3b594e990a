//! Mirror of `glsl/include/brdf.glsl`: the Disney 2012 principled BRDF, BRDF Explorer revision,
//! and the BRDF lab's variants of its terms (docs/shading.md#brdf-models).
//!
//! Every vector is in the shading frame: N = +Z, tangent X = +X, bitangent Y = +Y. The GLSL reads
//! the model as specialization constants; here [`Lobes`] and [`View`] carry it, and the energy
//! table, from [`make_lobes_with`].

use super::common::{mix, INV_PI, PI};
use super::material::Material;
use super::model::{Diffuse, Fresnel, Model, SpecularD, SpecularG};
use glam::Vec3;
use std::sync::Arc;

/// A model and what it needs at run time: its energy table when compensation is on.
#[derive(Clone, Debug, Default)]
pub struct Shading {
    pub model: Model,
    pub energy: Option<Arc<EnergyTable>>,
}

impl Shading {
    /// The model with its table (which must be given when compensation is on).
    pub fn new(model: Model, energy: Option<Arc<EnergyTable>>) -> Shading {
        assert!(!model.energy_compensation || energy.is_some(), "energy compensation needs its table");
        Shading { model, energy }
    }
}

/// What the BRDF needs of a material, derived once per pixel rather than once per sample.
#[derive(Clone, Debug)]
pub struct Lobes {
    pub base_color: Vec3,
    /// Specular reflectance at normal incidence.
    pub cspec0: Vec3,
    /// sheen · Csheen.
    pub sheen_color: Vec3,
    pub metallic: f32,
    pub subsurface: f32,
    pub roughness: f32,
    /// The specular parameter, for models with a scalar dielectric F0.
    pub specular: f32,
    /// Anisotropic alphas of the distribution (GTR-γ: isotropic).
    pub ax: f32,
    pub ay: f32,
    /// Alphas of the shadowing term: ax, ay, or the 2012 notes' remap.
    pub gx: f32,
    pub gy: f32,
    /// ln of the GTR-γ normalisation.
    pub d_log_norm: f32,
    /// 0.25 · clearcoat: the clearcoat lobe's weight in the total.
    pub clearcoat: f32,
    /// GTR1 alpha², at most 1.
    pub cc_alpha2: f32,
    /// For sampling GTR1.
    pub cc_log2_alpha2: f32,
    /// GTR1 normalisation (α²−1)/(π·ln α²), or 1/π when α ≥ 1.
    pub cc_norm: f32,
    /// Complex IOR per channel, for the exact Fresnel variants.
    pub ior_n: Vec3,
    pub ior_k: Vec3,
    /// Energy compensation: F_ms/(π·(1 − E_avg)).
    pub ms_scale: Vec3,
    /// F_ms, the Fresnel colour of multiple scattering.
    pub ms_fresnel: Vec3,
    /// The specialization constants of the GLSL.
    pub model: Model,
    /// The energy table (GLSL: the `energy_table` buffer).
    pub energy: Option<Arc<EnergyTable>>,
}

/// Burley's luminance approximation, used only to isolate the base colour's hue for the tints.
pub fn tint_luminance(c: Vec3) -> f32 {
    0.3 * c.x + 0.6 * c.y + 0.1 * c.z
}

pub fn gtr1_norm(alpha2: f32) -> f32 {
    if alpha2 >= 1.0 {
        INV_PI
    } else {
        (alpha2 - 1.0) / (PI * alpha2.ln())
    }
}

/// e^x − 1 without cancellation for small x (the series to x⁵: relative error below 2e-8).
pub fn expm1_accurate(x: f32) -> f32 {
    if x.abs() < 0.1 {
        x * (1.0 + x * (0.5 + x * (1.0 / 6.0 + x * (1.0 / 24.0 + x / 120.0))))
    } else {
        x.exp() - 1.0
    }
}

/// ln(1 + y) without cancellation for small y.
pub fn log1p_accurate(y: f32) -> f32 {
    if y.abs() < 0.05 {
        y * (1.0 - y * (0.5 - y * (1.0 / 3.0 - y * (0.25 - y * 0.2))))
    } else {
        (1.0 + y).ln()
    }
}

/// ln x, accurate relative to the result also near x = 1.
pub fn log_accurate(x: f32) -> f32 {
    if (x - 1.0).abs() < 0.05 {
        log1p_accurate(x - 1.0)
    } else {
        x.ln()
    }
}

/// ln of GTR's normalisation for exponent γ (Burley 2012, appendix B): (γ−1)(α²−1)/(π(1 −
/// α^(2(1−γ)))), the γ → 1 limit (α²−1)/(π ln α²), and 1/π for α ≥ 1. A logarithm, because
/// α^(2(1−γ)) overflows a float at the ends of the range (e^124 at γ = 10, α = 0.001) where the
/// distribution itself is finite.
pub fn gtr_log_norm(alpha2: f32, gamma: f32) -> f32 {
    if alpha2 >= 1.0 {
        return -PI.ln();
    }
    let log_alpha2 = log_accurate(alpha2);
    if (gamma - 1.0).abs() < 1e-4 {
        return ((alpha2 - 1.0) / log_alpha2).ln() - PI.ln();
    }
    let l = (1.0 - gamma) * log_alpha2;
    // ln|e^l − 1|; for l > 0, l + ln(1 − e^−l), which cannot overflow.
    let log_expm1 = if l > 0.0 { l + (-expm1_accurate(-l)).ln() } else { (-expm1_accurate(l)).ln() };
    ((gamma - 1.0).abs() * (1.0 - alpha2)).ln() - PI.ln() - log_expm1
}

/// (n, k) of the complex IOR whose normal reflectance is `r` and whose edge parameter is `e`.
pub fn complex_ior(r: f32, e: f32) -> (f32, f32) {
    let rc = r.clamp(0.0, 0.9999);
    let sr = rc.sqrt();
    let n_hi = (1.0 + sr) / (1.0 - sr);
    let n_lo = (1.0 - sr) / (1.0 + sr);
    let n = n_hi + (n_lo - n_hi) * e;
    let k2 = (rc * (n + 1.0) * (n + 1.0) - (n - 1.0) * (n - 1.0)) / (1.0 - rc);
    (n, k2.max(0.0).sqrt())
}

/// The edge parameter of a complex IOR n + ik: where n lies between the two dielectric IORs of
/// the same normal reflectance, so that [`complex_ior`] gives (n, k) back.
pub fn ior_edge(n: f32, k: f32) -> f32 {
    let r = normal_reflectance(n as f64, k as f64).min(0.9999);
    let sr = r.sqrt();
    let (n_hi, n_lo) = ((1.0 + sr) / (1.0 - sr), (1.0 - sr) / (1.0 + sr));
    ((n_hi - n as f64) / (n_hi - n_lo)).clamp(0.0, 1.0) as f32
}

/// F0 = ((n−1)² + k²)/((n+1)² + k²).
pub fn normal_reflectance(n: f64, k: f64) -> f64 {
    ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
}

/// Nodes per axis of the energy table: √μ and roughness, each from 0 to 1 (GLSL
/// `ENERGY_TABLE_SIZE`).
pub const ENERGY_TABLE_SIZE: usize = 32;

/// The energy-compensation table of a model (Kulla and Conty 2017), the layout of the
/// `energy_table` buffer: the directional albedo E(μ, roughness) of the single-scattering
/// specular lobe with F = 1 on the grid (μ fastest), then its average E_avg per roughness node.
/// [`super::energy`] builds it.
#[derive(Clone, Debug, PartialEq)]
pub struct EnergyTable {
    pub values: Vec<f32>,
}

impl EnergyTable {
    /// A table of zeros, bound where compensation is off (the shaders never read it then).
    pub fn placeholder() -> EnergyTable {
        EnergyTable { values: vec![0.0; ENERGY_TABLE_SIZE * ENERGY_TABLE_SIZE + ENERGY_TABLE_SIZE] }
    }
}

/// Directional albedo of the specular lobe, bilinear in (√μ, roughness) (GLSL `energy_albedo`).
/// Reads only the E part of `values`, so the builder can average a table still without E_avg.
pub fn energy_albedo(values: &[f32], mu: f32, roughness: f32) -> f32 {
    let n = ENERGY_TABLE_SIZE as i32;
    let x = mu.clamp(0.0, 1.0).sqrt() * (n - 1) as f32;
    let y = roughness.clamp(0.0, 1.0) * (n - 1) as f32;
    let x0 = (x as i32).min(n - 2);
    let y0 = (y as i32).min(n - 2);
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let i = (y0 * n + x0) as usize;
    let bottom = mix(values[i], values[i + 1], fx);
    let top = mix(values[i + ENERGY_TABLE_SIZE], values[i + ENERGY_TABLE_SIZE + 1], fx);
    mix(bottom, top, fy)
}

/// E_avg(roughness) from the energy table (GLSL `energy_average`).
pub fn energy_average(table: &EnergyTable, roughness: f32) -> f32 {
    let n = ENERGY_TABLE_SIZE as i32;
    let y = roughness.clamp(0.0, 1.0) * (n - 1) as f32;
    let y0 = (y as i32).min(n - 2);
    let i = (n * n + y0) as usize;
    mix(table.values[i], table.values[i + 1], y - y0 as f32)
}

/// Kulla and Conty's multiple-scattering colour and scale.
pub fn add_energy_compensation(s: &mut Lobes, table: &EnergyTable) {
    let e_avg = energy_average(table, s.roughness);
    let f_avg = s.cspec0 + (Vec3::ONE - s.cspec0) / 21.0;
    s.ms_fresnel = f_avg * f_avg * e_avg / (Vec3::ONE - f_avg * (1.0 - e_avg));
    s.ms_scale = if 1.0 - e_avg > 1e-6 { s.ms_fresnel / (PI * (1.0 - e_avg)) } else { Vec3::ZERO };
}

/// [`make_lobes_with`] for the default (Disney 2012) model.
pub fn make_lobes(m: impl Into<Material>) -> Lobes {
    make_lobes_with(m, &Shading::default())
}

/// GLSL `make_lobes`, for a model and its table.
pub fn make_lobes_with(m: impl Into<Material>, shading: &Shading) -> Lobes {
    let m: Material = m.into();
    let model = shading.model;
    let base_color = m.base_color;
    let lum = tint_luminance(base_color);
    let ctint = if lum > 0.0 { base_color / lum } else { Vec3::ONE };
    let cspec0 = (m.specular * 0.08 * Vec3::ONE.lerp(ctint, m.specular_tint)).lerp(base_color, m.metallic);
    let sheen_color = m.sheen * Vec3::ONE.lerp(ctint, m.sheen_tint);
    let aspect = (1.0 - 0.9 * m.anisotropic).sqrt();
    let r2 = m.roughness * m.roughness;
    let mut ax = (r2 / aspect).max(0.001);
    let mut ay = (r2 * aspect).max(0.001);
    let mut d_log_norm = 0.0;
    if model.specular_d == SpecularD::Gtr {
        let a = (ax * ay).sqrt();
        ax = a;
        ay = a;
        d_log_norm = gtr_log_norm(a * a, model.gtr_gamma);
    }
    let (mut gx, mut gy) = (ax, ay);
    if model.specular_g == SpecularG::Burley2012 {
        let rg = 0.5 + 0.5 * m.roughness;
        gx = (rg * rg / aspect).max(0.001);
        gy = (rg * rg * aspect).max(0.001);
        if model.specular_d == SpecularD::Gtr {
            gx = rg * rg;
            gy = rg * rg;
        }
    }
    let a = mix(0.1, 0.001, m.clearcoat_gloss);
    let cc_alpha2 = (a * a).min(1.0);
    let (mut ior_n, mut ior_k) = (Vec3::ONE, Vec3::ZERO);
    if model.fresnel != Fresnel::Schlick {
        let edge = if model.fresnel == Fresnel::Conductor { m.ior_edge } else { Vec3::ZERO };
        for c in 0..3 {
            let (n, k) = complex_ior(cspec0[c], edge[c]);
            ior_n[c] = n;
            ior_k[c] = k;
        }
    }
    let mut s = Lobes {
        base_color,
        cspec0,
        sheen_color,
        metallic: m.metallic,
        subsurface: m.subsurface,
        roughness: m.roughness,
        specular: m.specular,
        ax,
        ay,
        gx,
        gy,
        d_log_norm,
        clearcoat: 0.25 * m.clearcoat,
        cc_alpha2,
        cc_log2_alpha2: cc_alpha2.log2(),
        cc_norm: gtr1_norm(cc_alpha2),
        ior_n,
        ior_k,
        ms_scale: Vec3::ZERO,
        ms_fresnel: Vec3::ZERO,
        model,
        energy: shading.energy.clone(),
    };
    if model.energy_compensation {
        let table = shading.energy.clone().expect("energy compensation needs its table");
        add_energy_compensation(&mut s, &table);
    }
    s
}

/// S(u) = clamp(1 − u, 0, 1)^5.
pub fn schlick_weight(u: f32) -> f32 {
    let m = (1.0 - u).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// GTR1 (Berry) distribution of the clearcoat, for a unit half vector `h`, with the
/// denominator written as α²·cos²θh + sin²θh to avoid cancellation near the peak.
pub fn gtr1(h: Vec3, alpha2: f32, norm: f32) -> f32 {
    norm / (alpha2 * h.z * h.z + h.x * h.x + h.y * h.y)
}

/// Anisotropic GTR2 (GGX) distribution; `h` is the half vector in the shading frame.
pub fn gtr2_aniso(h: Vec3, ax: f32, ay: f32) -> f32 {
    let x = h.x / ax;
    let y = h.y / ay;
    let d = x * x + y * y + h.z * h.z;
    1.0 / (PI * ax * ay * d * d)
}

/// GTR with exponent γ, isotropic: c/(α²·cos²θh + sin²θh)^γ, from ln c, in logarithms (both
/// c and the power leave a float's range at the ends of γ's).
pub fn gtr_gamma(h: Vec3, alpha2: f32, log_norm: f32, gamma: f32) -> f32 {
    (log_norm - gamma * (alpha2 * h.z * h.z + h.x * h.x + h.y * h.y).ln()).exp()
}

/// Anisotropic Beckmann.
pub fn beckmann_aniso(h: Vec3, ax: f32, ay: f32) -> f32 {
    let z2 = h.z * h.z;
    if z2 <= 0.0 {
        return 0.0;
    }
    let x = h.x / ax;
    let y = h.y / ay;
    (-(x * x + y * y) / z2).exp() / (PI * ax * ay * z2 * z2)
}

/// The specular distribution of the model.
pub fn specular_d(s: &Lobes, h: Vec3) -> f32 {
    match s.model.specular_d {
        SpecularD::Beckmann => beckmann_aniso(h, s.ax, s.ay),
        SpecularD::Gtr => gtr_gamma(h, s.ax * s.ax, s.d_log_norm, s.model.gtr_gamma),
        SpecularD::Gtr2 => gtr2_aniso(h, s.ax, s.ay),
    }
}

/// Smith G for anisotropic GGX with 1/(4·N·W) folded in: g(W) of the shading model in docs/shading.md.
pub fn smith_g_aniso(w: Vec3, ax: f32, ay: f32) -> f32 {
    let x = w.x * ax;
    let y = w.y * ay;
    1.0 / (w.z + (x * x + y * y + w.z * w.z).sqrt())
}

/// erfc(x)·e^(x²) for x ≥ 0 (Abramowitz and Stegun 7.1.26).
#[allow(clippy::excessive_precision)] // the coefficients as Abramowitz and Stegun give them
pub fn erfc_poly(x: f32) -> f32 {
    let t = 1.0 / (1.0 + 0.3275911 * x);
    t * (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))))
}

/// Smith Λ of anisotropic Beckmann.
pub fn beckmann_lambda(w: Vec3, ax: f32, ay: f32) -> f32 {
    let x = w.x * ax;
    let y = w.y * ay;
    let t = (x * x + y * y).sqrt();
    if t <= 0.0 {
        return 0.0;
    }
    let a = w.z / t;
    let e = (-a * a).exp();
    e * (0.282_094_8 / a - 0.5 * erfc_poly(a)) // 1/(2√π)
}

/// Smith Λ of the model's distribution family (GTR-γ uses GGX's).
pub fn smith_lambda(model: &Model, w: Vec3, gx: f32, gy: f32) -> f32 {
    if model.specular_d == SpecularD::Beckmann {
        return beckmann_lambda(w, gx, gy);
    }
    let x = w.x * gx;
    let y = w.y * gy;
    0.5 * ((x * x + y * y + w.z * w.z).sqrt() / w.z - 1.0)
}

/// G1(W)/(2·N·W) of the model's distribution family: the separable g(W).
pub fn smith_g(model: &Model, w: Vec3, gx: f32, gy: f32) -> f32 {
    if model.specular_d == SpecularD::Beckmann {
        return 1.0 / (2.0 * w.z * (1.0 + beckmann_lambda(w, gx, gy)));
    }
    smith_g_aniso(w, gx, gy)
}

/// The same for the clearcoat's fixed alpha 0.25: g25(W).
pub fn smith_g_clearcoat(cos_w: f32) -> f32 {
    let c2 = cos_w * cos_w;
    1.0 / (cos_w + (0.0625 + c2 - 0.0625 * c2).sqrt())
}

/// What depends only on the view direction, derived once per pixel.
#[derive(Clone, Copy, Debug)]
pub struct View {
    pub v: Vec3,
    /// `v` in the GGX hemisphere configuration, for visible-normal sampling.
    pub v_stretched: Vec3,
    /// S(N·V).
    pub fv: f32,
    /// g(V) of the specular lobe's shadowing.
    pub g_spec: f32,
    /// g(V) of GGX at the distribution's alphas, for the visible-normal pdf.
    pub g_vndf: f32,
    /// Λ(V) of the shadowing, for the height-correlated G.
    pub lambda_v: f32,
    /// g25(V) of the clearcoat.
    pub g_coat: f32,
    /// 1 − E(N·V) of the energy compensation.
    pub ms_v: f32,
    /// The specialization constants of the GLSL.
    pub model: Model,
}

pub fn make_view(s: &Lobes, v: Vec3) -> View {
    let model = s.model;
    View {
        v,
        v_stretched: Vec3::new(s.ax * v.x, s.ay * v.y, v.z).normalize(),
        fv: schlick_weight(v.z),
        g_spec: smith_g(&model, v, s.gx, s.gy),
        g_vndf: smith_g_aniso(v, s.ax, s.ay),
        lambda_v: if model.specular_g == SpecularG::SmithHeightCorrelated {
            smith_lambda(&model, v, s.gx, s.gy)
        } else {
            0.0
        },
        g_coat: smith_g_clearcoat(v.z),
        ms_v: match (&s.energy, model.energy_compensation) {
            (Some(table), true) => 1.0 - energy_albedo(&table.values, v.z, s.roughness),
            _ => 0.0,
        },
        model,
    }
}

/// The half vector of a pair of directions and the two microfacet distributions at it.
#[derive(Clone, Copy, Debug)]
pub struct HalfVector {
    /// normalize(l + v), or 0 when l = −v.
    pub h: Vec3,
    /// The specular D(h).
    pub d_spec: f32,
    /// GTR1 D(h).
    pub d_coat: f32,
}

pub fn make_half_vector(s: &Lobes, l: Vec3, v: Vec3) -> HalfVector {
    let sum = l + v;
    let len2 = sum.dot(sum);
    if len2 > 0.0 {
        let h = sum / len2.sqrt();
        HalfVector { h, d_spec: specular_d(s, h), d_coat: gtr1(h, s.cc_alpha2, s.cc_norm) }
    } else {
        HalfVector { h: Vec3::ZERO, d_spec: 0.0, d_coat: 0.0 }
    }
}

/// The unpolarised Fresnel reflectance of complex IOR n + ik at incidence cos θ = c.
pub fn fresnel_complex(n: f32, k: f32, c: f32) -> f32 {
    let c2 = c * c;
    let s2 = 1.0 - c2;
    let t0 = n * n - k * k - s2;
    let a2b2 = (t0 * t0 + 4.0 * n * n * k * k).sqrt();
    let a = (0.5 * (a2b2 + t0)).max(0.0).sqrt();
    let t1 = a2b2 + c2;
    let t2 = 2.0 * a * c;
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = c2 * a2b2 + s2 * s2;
    let t4 = t2 * s2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    0.5 * (rp + rs)
}

/// The specular Fresnel colour at cos θd = cd, with fh = S(cd).
pub fn specular_fresnel(s: &Lobes, cd: f32, fh: f32) -> Vec3 {
    if s.model.fresnel == Fresnel::Schlick {
        return s.cspec0.lerp(Vec3::ONE, fh);
    }
    let c = cd.clamp(0.0, 1.0);
    Vec3::new(
        fresnel_complex(s.ior_n.x, s.ior_k.x, c),
        fresnel_complex(s.ior_n.y, s.ior_k.y, c),
        fresnel_complex(s.ior_n.z, s.ior_k.z, c),
    )
}

/// cos(φl − φv), or 0 when either direction is along the normal.
pub fn cos_phi_difference(l: Vec3, v: Vec3) -> f32 {
    let ll = l.x * l.x + l.y * l.y;
    let vv = v.x * v.x + v.y * v.y;
    if ll > 0.0 && vv > 0.0 {
        (l.x * v.x + l.y * v.y) / (ll * vv).sqrt()
    } else {
        0.0
    }
}

/// The diffuse BRDFs of seed 004 other than Burley's, with the base colour.
pub fn diffuse_model(s: &Lobes, l: Vec3, v: Vec3, h: Vec3, cd: f32, fl: f32, fv: f32) -> Vec3 {
    let (cl, cv) = (l.z, v.z);
    let rho = s.base_color;
    let r = s.roughness;
    match s.model.diffuse {
        Diffuse::Frostbite => {
            let energy_bias = 0.5 * r;
            let energy_factor = mix(1.0, 1.0 / 1.51, r);
            let fd90 = energy_bias + 2.0 * cd * cd * r;
            rho * (INV_PI * mix(1.0, fd90, fl) * mix(1.0, fd90, fv) * energy_factor)
        }
        Diffuse::OrenNayar | Diffuse::OrenNayarQualitative => {
            let sigma2 = r * r;
            let cos_alpha = cl.min(cv);
            let cos_beta = cl.max(cv);
            let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
            let sin_beta = (1.0 - cos_beta * cos_beta).max(0.0).sqrt();
            let tan_beta = sin_beta / cos_beta;
            let cos_phi = cos_phi_difference(l, v);
            if s.model.diffuse == Diffuse::OrenNayarQualitative {
                let a = 1.0 - 0.5 * sigma2 / (sigma2 + 0.33);
                let b = 0.45 * sigma2 / (sigma2 + 0.09);
                return rho * (INV_PI * (a + b * cos_phi.max(0.0) * sin_alpha * tan_beta));
            }
            let alpha = cos_alpha.clamp(-1.0, 1.0).acos();
            let beta = cos_beta.clamp(-1.0, 1.0).acos();
            let s9 = sigma2 / (sigma2 + 0.09);
            let c1 = 1.0 - 0.5 * sigma2 / (sigma2 + 0.33);
            let two_beta_pi = 2.0 * beta * INV_PI;
            let c2 = 0.45
                * s9
                * if cos_phi >= 0.0 { sin_alpha } else { sin_alpha - two_beta_pi * two_beta_pi * two_beta_pi };
            let four_ab = 4.0 * alpha * beta * INV_PI * INV_PI;
            let c3 = 0.125 * s9 * four_ab * four_ab;
            let tan_half = (sin_alpha + sin_beta) / (cos_alpha + cos_beta);
            let direct = c1 + cos_phi * c2 * tan_beta + (1.0 - cos_phi.abs()) * c3 * tan_half;
            let inter = 0.17 * sigma2 / (sigma2 + 0.13) * (1.0 - cos_phi * two_beta_pi * two_beta_pi);
            INV_PI * (rho * direct + rho * rho * inter)
        }
        Diffuse::OrenNayarFujii => {
            let st = l.dot(v) - cl * cv;
            let t = if st <= 0.0 { 1.0 } else { cl.max(cv) };
            let a = 1.0 / (PI + (0.5 * PI - 2.0 / 3.0) * r);
            rho * (a + r * a * st / t)
        }
        Diffuse::Gotanda => {
            let sg = r * r;
            let sg2 = sg * sg;
            let f0 = (0.08 * s.specular).min(1.0);
            let fr = (1.0 - (0.542026 * sg2 + 0.303573 * sg) / (sg2 + 1.36053))
                * (1.0 - (1.0 - cv).powf(5.0 - 4.0 * sg2) / (sg2 + 1.36053))
                * ((-0.733996 * sg2 * sg + 1.50912 * sg2 - 1.16402 * sg)
                    * (1.0 - cv).powf(1.0 + 1.0 / (39.0 * sg2 * sg2 + 1.0))
                    + 1.0);
            let lm_over_cl = ((1.0 - 2.0 * sg).max(0.0) * (1.0 - schlick_weight(cl)) + (2.0 * sg).min(1.0))
                * ((1.0 - 0.5 * sg) + 0.5 * sg * cl);
            let vd = (sg2 / ((sg2 + 0.09) * (1.31072 + 0.995584 * cv)))
                * (1.0 - (1.0 - cl).powf((1.0 - 0.3726732 * cv * cv) / (0.188566 + 0.38841 * cv)));
            let mut bp = l.dot(v) - cv * cl;
            if bp < 0.0 {
                bp *= 1.4 * cv * cl;
            }
            rho * (21.0 / (20.0 * PI) * (1.0 - f0) * (fr * lm_over_cl + vd * bp / cl))
        }
        Diffuse::Hammon => {
            let alpha = r * r;
            let facing = 0.5 + 0.5 * l.dot(v);
            let rough = if h.z > 0.0 { facing * (0.9 - 0.4 * facing) * ((0.5 + h.z) / h.z) } else { 0.0 };
            let smooth_term = 1.05 * (1.0 - fl) * (1.0 - fv);
            let single = INV_PI * mix(smooth_term, rough, alpha);
            let multi = 0.1159 * alpha;
            rho * (single + rho * multi)
        }
        Diffuse::Lambert | Diffuse::Burley2012 => rho * INV_PI,
    }
}

/// The specular lobe's shadowing with 1/(4·N·L·N·V) folded in.
pub fn specular_shadowing(s: &Lobes, view: &View, l: Vec3) -> f32 {
    if s.model.specular_g == SpecularG::SmithHeightCorrelated {
        return 1.0 / (4.0 * l.z * view.v.z * (1.0 + smith_lambda(&s.model, l, s.gx, s.gy) + view.lambda_v));
    }
    smith_g(&s.model, l, s.gx, s.gy) * view.g_spec
}

/// f(l, v) by lobe, each term as it enters f: diffuse (with subsurface) and sheen are still to
/// be weighted by 1 − metallic, which [`lobes_total`] applies. Zero unless both directions are
/// above the surface.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BrdfLobes {
    pub diffuse: Vec3,
    pub sheen: Vec3,
    pub specular: Vec3,
    pub clearcoat: f32,
}

pub fn disney_lobes(s: &Lobes, view: &View, l: Vec3, hv: &HalfVector) -> BrdfLobes {
    let mut b = BrdfLobes::default();
    let cl = l.z;
    let cv = view.v.z;
    if cl <= 0.0 || cv <= 0.0 {
        return b;
    }
    let cd = l.dot(hv.h);
    let fl = schlick_weight(cl);
    let fh = schlick_weight(cd);

    // Diffuse: Schlick-style retro-reflection, and the Hanrahan–Krueger-like subsurface.
    let cd2r = cd * cd * s.roughness;
    let fss = mix(1.0, cd2r, fl) * mix(1.0, cd2r, view.fv);
    let ss = 1.25 * (fss * (1.0 / (cl + cv) - 0.5) + 0.5);
    b.diffuse = if s.model.diffuse == Diffuse::Burley2012 {
        let fd90 = 0.5 + 2.0 * cd2r;
        let fd = mix(1.0, fd90, fl) * mix(1.0, fd90, view.fv);
        (INV_PI * mix(fd, ss, s.subsurface)) * s.base_color
    } else {
        let fd = diffuse_model(s, l, view.v, hv.h, cd, fl, view.fv);
        fd.lerp((INV_PI * ss) * s.base_color, s.subsurface)
    };
    b.sheen = fh * s.sheen_color;

    // Specular: the model's D, G and F (anisotropic GGX, separable Smith, Schlick by default).
    let fs = specular_fresnel(s, cd, fh);
    let gs = specular_shadowing(s, view, l);
    b.specular = (gs * hv.d_spec) * fs;
    if let (Some(table), true) = (&s.energy, s.model.energy_compensation) {
        b.specular += s.ms_scale * ((1.0 - energy_albedo(&table.values, cl, s.roughness)) * view.ms_v);
    }

    // Clearcoat: GTR1 with a fixed IOR 1.5.
    let fr = mix(0.04, 1.0, fh);
    let gr = smith_g_clearcoat(cl) * view.g_coat;
    b.clearcoat = s.clearcoat * gr * fr * hv.d_coat;
    b
}

/// f, the lobes together.
pub fn lobes_total(s: &Lobes, b: &BrdfLobes) -> Vec3 {
    (b.diffuse + b.sheen) * (1.0 - s.metallic) + b.specular + Vec3::splat(b.clearcoat)
}

/// f(l, v), without the cosine.
pub fn disney_brdf(s: &Lobes, view: &View, l: Vec3, hv: &HalfVector) -> Vec3 {
    lobes_total(s, &disney_lobes(s, view, l, hv))
}

/// f(l, v) for a material, from scratch: what the per-pixel and per-pair steps compute together.
pub fn evaluate(params: impl Into<Material>, l: Vec3, v: Vec3) -> Vec3 {
    evaluate_with(params, &Shading::default(), l, v)
}

/// [`evaluate`] for a model.
pub fn evaluate_with(params: impl Into<Material>, shading: &Shading, l: Vec3, v: Vec3) -> Vec3 {
    let s = make_lobes_with(params, shading);
    disney_brdf(&s, &make_view(&s, v), l, &make_half_vector(&s, l, v))
}
