//! Mirror of `glsl/include/sampling.glsl`: BRDF importance sampling and MIS.

use super::brdf::{expm1_accurate, log1p_accurate, log_accurate, HalfVector, Lobes, View};
use super::common::{luminance, mix, INV_PI, ONE_MINUS_EPSILON, TWO_PI};
use super::model::SpecularD;
use glam::{Vec2, Vec3};

/// Probabilities of picking each lobe for one-sample MIS; they sum to 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LobeChoice {
    /// Diffuse, subsurface and sheen: cosine sampling.
    pub diffuse: f32,
    /// GGX visible normals, or the model's distribution of normals.
    pub specular: f32,
    /// GTR1 half vectors.
    pub clearcoat: f32,
}

/// Picks lobes in proportion to an estimate of their reflectance at this view angle.
pub fn choose_lobes(s: &Lobes, view: &View) -> LobeChoice {
    let mut w_diffuse = (1.0 - s.metallic) * (luminance(s.base_color) + 0.25 * luminance(s.sheen_color));
    if s.model.energy_compensation {
        // The multiple-scattering lobe is nearly cosine-shaped; its albedo is F_ms·(1 − E(μv)).
        w_diffuse += luminance(s.ms_fresnel) * view.ms_v;
    }
    let w_specular = luminance(s.cspec0.lerp(Vec3::ONE, view.fv));
    let w_clearcoat = s.clearcoat * mix(0.04, 1.0, view.fv);
    let total = w_diffuse + w_specular + w_clearcoat;
    // Written so that a NaN total also falls back to the diffuse lobe.
    if total.is_nan() || total <= 0.0 {
        return LobeChoice { diffuse: 1.0, specular: 0.0, clearcoat: 0.0 };
    }
    LobeChoice { diffuse: w_diffuse / total, specular: w_specular / total, clearcoat: w_clearcoat / total }
}

/// (cos φ, sin φ) for φ = 2π·x.
pub fn azimuth(x: f32) -> Vec2 {
    let phi = TWO_PI * x;
    Vec2::new(phi.cos(), phi.sin())
}

/// Cosine-weighted hemisphere: a uniform disk (r = √u) lifted to the hemisphere.
pub fn sample_cosine(azimuth: Vec2, u: f32) -> Vec3 {
    let r = u.sqrt();
    (r * azimuth).extend((1.0 - u).max(0.0).sqrt())
}

pub fn pdf_cosine(l: Vec3) -> f32 {
    l.z.max(0.0) * INV_PI
}

/// A GGX microfacet normal visible from v, by Dupuy and Benyoub's spherical caps (2023).
pub fn sample_ggx_visible_normal(v_stretched: Vec3, ax: f32, ay: f32, azimuth: Vec2, u: f32) -> Vec3 {
    let z = (1.0 - u) * (1.0 + v_stretched.z) - v_stretched.z;
    let sin_theta = (1.0 - z * z).clamp(0.0, 1.0).sqrt();
    let h = (sin_theta * azimuth).extend(z) + v_stretched;
    Vec3::new(ax * h.x, ay * h.y, h.z).normalize()
}

/// pdf of l = reflect(−v, h) for visible-normal sampling: g(v)·D(h)/2.
pub fn pdf_ggx_reflection(view: &View, hv: &HalfVector) -> f32 {
    if hv.h.z > 0.0 {
        0.5 * view.g_vndf * hv.d_spec
    } else {
        0.0
    }
}

/// A Beckmann normal, from the distribution of normals D(h)·cosθh.
pub fn sample_beckmann_normal(ax: f32, ay: f32, azimuth: Vec2, u: f32) -> Vec3 {
    let r = (-(1.0 - u).ln()).sqrt();
    Vec3::new(ax * r * azimuth.x, ay * r * azimuth.y, 1.0).normalize()
}

/// A GTR-γ normal from D(h)·cosθh (Burley 2012, appendix B), accurate as α → 1.
pub fn sample_gtr_normal(alpha2: f32, gamma: f32, azimuth: Vec2, u: f32) -> Vec3 {
    let cos2 = if alpha2 >= 1.0 {
        1.0 - u
    } else {
        let log_alpha2 = log_accurate(alpha2);
        let one_minus_s = if (gamma - 1.0).abs() < 1e-4 {
            -expm1_accurate(log_alpha2 * (1.0 - u))
        } else {
            // ln s = ln((1−u)·e^l + u)/(1−γ); for l > 0 as l + ln(1 + u·(e^−l − 1)), where e^l
            // would overflow at the ends of γ's range.
            let e = 1.0 - gamma;
            let l = e * log_alpha2;
            let log_s = if l > 0.0 {
                l + log1p_accurate(u * expm1_accurate(-l))
            } else {
                log1p_accurate((1.0 - u) * expm1_accurate(l))
            } / e;
            -expm1_accurate(log_s)
        };
        one_minus_s / (1.0 - alpha2)
    };
    let cos2 = cos2.clamp(0.0, 1.0);
    ((1.0 - cos2).sqrt() * azimuth).extend(cos2.sqrt())
}

/// pdf of l = reflect(−v, h) when h is drawn from D(h)·cosθh: D(h)·|N·h|/(4·|v·h|).
pub fn pdf_normal_reflection(d: f32, view: &View, h: Vec3) -> f32 {
    let vh = view.v.dot(h).abs();
    if vh > 0.0 {
        d * h.z.abs() / (4.0 * vh)
    } else {
        0.0
    }
}

/// pdf of the specular sampler of the model.
pub fn pdf_specular_reflection(view: &View, hv: &HalfVector) -> f32 {
    if view.model.specular_d == SpecularD::Gtr2 {
        return pdf_ggx_reflection(view, hv);
    }
    pdf_normal_reflection(hv.d_spec, view, hv.h)
}

/// A specular half vector of the model: GGX visible normals, or the distribution of normals.
pub fn sample_specular_normal(s: &Lobes, view: &View, azimuth: Vec2, u: f32) -> Vec3 {
    match s.model.specular_d {
        SpecularD::Beckmann => sample_beckmann_normal(s.ax, s.ay, azimuth, u),
        SpecularD::Gtr => sample_gtr_normal(s.ax * s.ax, s.model.gtr_gamma, azimuth, u),
        SpecularD::Gtr2 => sample_ggx_visible_normal(view.v_stretched, s.ax, s.ay, azimuth, u),
    }
}

/// A GTR1 half vector (Burley 2012, appendix B): cos²θh = (1 − α^(2(1−u)))/(1 − α²).
pub fn sample_gtr1_normal(alpha2: f32, log2_alpha2: f32, azimuth: Vec2, u: f32) -> Vec3 {
    let cos2 = if alpha2 >= 1.0 { 1.0 - u } else { (1.0 - (log2_alpha2 * (1.0 - u)).exp2()) / (1.0 - alpha2) };
    let cos2 = cos2.clamp(0.0, 1.0);
    ((1.0 - cos2).sqrt() * azimuth).extend(cos2.sqrt())
}

/// pdf of l = reflect(−v, h) for GTR1 half-vector sampling: D(h)·|N·h|/(4·|v·h|).
pub fn pdf_gtr1_reflection(view: &View, hv: &HalfVector) -> f32 {
    let vh = view.v.dot(hv.h).abs();
    if vh > 0.0 {
        hv.d_coat * hv.h.z.abs() / (4.0 * vh)
    } else {
        0.0
    }
}

/// The one-sample MIS pdf of [`sample_brdf`]: Σ pᵢ·pdfᵢ(l).
pub fn brdf_pdf(c: &LobeChoice, view: &View, l: Vec3, hv: &HalfVector) -> f32 {
    let mut pdf = c.diffuse * pdf_cosine(l);
    if c.specular > 0.0 {
        pdf += c.specular * pdf_specular_reflection(view, hv);
    }
    if c.clearcoat > 0.0 {
        pdf += c.clearcoat * pdf_gtr1_reflection(view, hv);
    }
    pdf
}

/// GLSL's `reflect(i, n)`.
pub fn reflect(i: Vec3, n: Vec3) -> Vec3 {
    i - 2.0 * n.dot(i) * n
}

/// Picks a lobe with u.x, then reuses u.x, rescaled to [0, 1), for the azimuth.
pub fn sample_brdf(s: &Lobes, c: &LobeChoice, view: &View, u: Vec2) -> Vec3 {
    let (lobe, x) = if u.x < c.diffuse {
        (0, u.x / c.diffuse)
    } else if u.x < c.diffuse + c.specular || c.clearcoat <= 0.0 {
        (1, (u.x - c.diffuse) / c.specular)
    } else {
        (2, (u.x - c.diffuse - c.specular) / c.clearcoat)
    };
    let phi = azimuth(x.min(ONE_MINUS_EPSILON));
    if lobe == 0 {
        return sample_cosine(phi, u.y);
    }
    let h = if lobe == 1 {
        sample_specular_normal(s, view, phi, u.y)
    } else {
        sample_gtr1_normal(s.cc_alpha2, s.cc_log2_alpha2, phi, u.y)
    };
    reflect(-view.v, h)
}

/// The power heuristic (β = 2) for one sample from each of two techniques, divided by the
/// sampling technique's own pdf.
pub fn mis_weight_over_pdf(own: f32, other: f32) -> f32 {
    own / (own * own + other * other)
}
