//! Mirror of `glsl/include/brdf.glsl`: the Disney 2012 principled BRDF, BRDF Explorer revision.
//!
//! Every vector is in the shading frame: N = +Z, tangent X = +X, bitangent Y = +Y.

use super::common::{mix, INV_PI, PI};
use crate::material::Params;
use glam::Vec3;

/// What the BRDF needs of a material, derived once per pixel rather than once per sample.
#[derive(Clone, Copy, Debug)]
pub struct Lobes {
    pub base_color: Vec3,
    /// Specular reflectance at normal incidence.
    pub cspec0: Vec3,
    /// sheen · Csheen.
    pub sheen_color: Vec3,
    pub metallic: f32,
    pub subsurface: f32,
    pub roughness: f32,
    /// Anisotropic GGX alphas.
    pub ax: f32,
    pub ay: f32,
    /// 0.25 · clearcoat: the clearcoat lobe's weight in the total.
    pub clearcoat: f32,
    /// GTR1 alpha², at most 1.
    pub cc_alpha2: f32,
    /// For sampling GTR1.
    pub cc_log2_alpha2: f32,
    /// GTR1 normalisation (α²−1)/(π·ln α²), or 1/π when α ≥ 1.
    pub cc_norm: f32,
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

pub fn make_lobes(m: &Params) -> Lobes {
    let base_color = Vec3::from(m.base_color);
    let lum = tint_luminance(base_color);
    let ctint = if lum > 0.0 { base_color / lum } else { Vec3::ONE };
    let cspec0 = (m.specular * 0.08 * Vec3::ONE.lerp(ctint, m.specular_tint)).lerp(base_color, m.metallic);
    let sheen_color = m.sheen * Vec3::ONE.lerp(ctint, m.sheen_tint);
    let aspect = (1.0 - 0.9 * m.anisotropic).sqrt();
    let r2 = m.roughness * m.roughness;
    let a = mix(0.1, 0.001, m.clearcoat_gloss);
    let cc_alpha2 = (a * a).min(1.0);
    Lobes {
        base_color,
        cspec0,
        sheen_color,
        metallic: m.metallic,
        subsurface: m.subsurface,
        roughness: m.roughness,
        ax: (r2 / aspect).max(0.001),
        ay: (r2 * aspect).max(0.001),
        clearcoat: 0.25 * m.clearcoat,
        cc_alpha2,
        cc_log2_alpha2: cc_alpha2.log2(),
        cc_norm: gtr1_norm(cc_alpha2),
    }
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

/// Smith G for anisotropic GGX with 1/(4·N·W) folded in: g(W) of the README's shading model.
pub fn smith_g_aniso(w: Vec3, ax: f32, ay: f32) -> f32 {
    let x = w.x * ax;
    let y = w.y * ay;
    1.0 / (w.z + (x * x + y * y + w.z * w.z).sqrt())
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
    /// g(V) of the specular lobe.
    pub g_spec: f32,
    /// g25(V) of the clearcoat.
    pub g_coat: f32,
}

pub fn make_view(s: &Lobes, v: Vec3) -> View {
    View {
        v,
        v_stretched: Vec3::new(s.ax * v.x, s.ay * v.y, v.z).normalize(),
        fv: schlick_weight(v.z),
        g_spec: smith_g_aniso(v, s.ax, s.ay),
        g_coat: smith_g_clearcoat(v.z),
    }
}

/// The half vector of a pair of directions and the two microfacet distributions at it.
#[derive(Clone, Copy, Debug)]
pub struct HalfVector {
    /// normalize(l + v), or 0 when l = −v.
    pub h: Vec3,
    /// GGX D(h).
    pub d_spec: f32,
    /// GTR1 D(h).
    pub d_coat: f32,
}

pub fn make_half_vector(s: &Lobes, l: Vec3, v: Vec3) -> HalfVector {
    let sum = l + v;
    let len2 = sum.dot(sum);
    if len2 > 0.0 {
        let h = sum / len2.sqrt();
        HalfVector { h, d_spec: gtr2_aniso(h, s.ax, s.ay), d_coat: gtr1(h, s.cc_alpha2, s.cc_norm) }
    } else {
        HalfVector { h: Vec3::ZERO, d_spec: 0.0, d_coat: 0.0 }
    }
}

/// f(l, v), without the cosine; zero unless both directions are above the surface.
pub fn disney_brdf(s: &Lobes, view: &View, l: Vec3, hv: &HalfVector) -> Vec3 {
    let cl = l.z;
    let cv = view.v.z;
    if cl <= 0.0 || cv <= 0.0 {
        return Vec3::ZERO;
    }
    let cd = l.dot(hv.h);
    let fl = schlick_weight(cl);
    let fh = schlick_weight(cd);

    // Diffuse: Schlick-style retro-reflection, and the Hanrahan–Krueger-like subsurface.
    let cd2r = cd * cd * s.roughness;
    let fd90 = 0.5 + 2.0 * cd2r;
    let fd = mix(1.0, fd90, fl) * mix(1.0, fd90, view.fv);
    let fss = mix(1.0, cd2r, fl) * mix(1.0, cd2r, view.fv);
    let ss = 1.25 * (fss * (1.0 / (cl + cv) - 0.5) + 0.5);
    let diffuse = (INV_PI * mix(fd, ss, s.subsurface)) * s.base_color + fh * s.sheen_color;

    // Specular: anisotropic GGX.
    let fs = s.cspec0.lerp(Vec3::ONE, fh);
    let gs = smith_g_aniso(l, s.ax, s.ay) * view.g_spec;

    // Clearcoat: GTR1 with a fixed IOR 1.5.
    let fr = mix(0.04, 1.0, fh);
    let gr = smith_g_clearcoat(cl) * view.g_coat;

    diffuse * (1.0 - s.metallic) + (gs * hv.d_spec) * fs + Vec3::splat(s.clearcoat * gr * fr * hv.d_coat)
}

/// f(l, v) for a material, from scratch: what the per-pixel and per-pair steps compute together.
pub fn evaluate(params: &Params, l: Vec3, v: Vec3) -> Vec3 {
    let s = make_lobes(params);
    disney_brdf(&s, &make_view(&s, v), l, &make_half_vector(&s, l, v))
}
