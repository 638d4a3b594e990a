//! Mirror of `glsl/include/sampling.glsl`: BRDF importance sampling and MIS.

use super::brdf::{gtr1, gtr2_aniso, schlick_weight, smith_g_aniso, Lobes};
use super::common::{luminance, mix, INV_PI, ONE_MINUS_EPSILON, PI, TWO_PI};
use glam::{Vec2, Vec3};

/// Probabilities of picking each lobe for one-sample MIS; they sum to 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LobeChoice {
    /// Diffuse, subsurface and sheen: cosine sampling.
    pub diffuse: f32,
    /// GGX visible normals.
    pub specular: f32,
    /// GTR1 half vectors.
    pub clearcoat: f32,
}

/// Picks lobes in proportion to an estimate of their reflectance at this view angle.
pub fn choose_lobes(s: &Lobes, cos_v: f32) -> LobeChoice {
    let fv = schlick_weight(cos_v);
    let w_diffuse = (1.0 - s.metallic) * (luminance(s.base_color) + 0.25 * luminance(s.sheen_color));
    let w_specular = luminance(s.cspec0.lerp(Vec3::ONE, fv));
    let w_clearcoat = s.clearcoat * mix(0.04, 1.0, fv);
    let total = w_diffuse + w_specular + w_clearcoat;
    if !(total > 0.0) {
        return LobeChoice { diffuse: 1.0, specular: 0.0, clearcoat: 0.0 };
    }
    LobeChoice { diffuse: w_diffuse / total, specular: w_specular / total, clearcoat: w_clearcoat / total }
}

/// Cosine-weighted hemisphere, by Shirley and Chiu's concentric disk mapping.
pub fn sample_cosine(u: Vec2) -> Vec3 {
    let d = 2.0 * u - Vec2::ONE;
    if d.x == 0.0 && d.y == 0.0 {
        return Vec3::Z;
    }
    let (r, phi) = if d.x.abs() > d.y.abs() {
        (d.x, (PI / 4.0) * (d.y / d.x))
    } else {
        (d.y, (PI / 2.0) - (PI / 4.0) * (d.x / d.y))
    };
    let z = (1.0 - r * r).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

pub fn pdf_cosine(l: Vec3) -> f32 {
    l.z.max(0.0) * INV_PI
}

/// A GGX microfacet normal visible from `v`, by Dupuy and Benyoub's spherical caps (2023).
pub fn sample_ggx_visible_normal(v: Vec3, ax: f32, ay: f32, u: Vec2) -> Vec3 {
    let vh = Vec3::new(ax * v.x, ay * v.y, v.z).normalize();
    let phi = TWO_PI * u.x;
    let z = (1.0 - u.y) * (1.0 + vh.z) - vh.z;
    let sin_theta = (1.0 - z * z).clamp(0.0, 1.0).sqrt();
    let hh = Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), z) + vh;
    Vec3::new(ax * hh.x, ay * hh.y, hh.z).normalize()
}

/// pdf of l = reflect(−v, h) for visible-normal sampling: G1(v)·D(h)/(4·N·v) = g(v)·D(h)/2.
pub fn pdf_ggx_reflection(v: Vec3, h: Vec3, ax: f32, ay: f32) -> f32 {
    if h.z > 0.0 {
        0.5 * smith_g_aniso(v, ax, ay) * gtr2_aniso(h, ax, ay)
    } else {
        0.0
    }
}

/// A GTR1 half vector (Burley 2012, appendix B): cos²θh = (1 − α^(2(1−u)))/(1 − α²).
pub fn sample_gtr1_normal(alpha2: f32, u: Vec2) -> Vec3 {
    let phi = TWO_PI * u.x;
    let cos2 = if alpha2 >= 1.0 { 1.0 - u.y } else { (1.0 - alpha2.powf(1.0 - u.y)) / (1.0 - alpha2) };
    let cos2 = cos2.clamp(0.0, 1.0);
    let sin_theta = (1.0 - cos2).sqrt();
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos2.sqrt())
}

/// pdf of l = reflect(−v, h) for GTR1 half-vector sampling: D(h)·(N·h)/(4·|v·h|), with h taken
/// in the upper hemisphere (see the GLSL for why).
pub fn pdf_gtr1_reflection(v: Vec3, h: Vec3, alpha2: f32, norm: f32) -> f32 {
    let h = if h.z < 0.0 { -h } else { h };
    let vh = v.dot(h).abs();
    if vh > 0.0 {
        gtr1(h, alpha2, norm) * h.z / (4.0 * vh)
    } else {
        0.0
    }
}

/// The one-sample MIS pdf of [`sample_brdf`]: Σ pᵢ·pdfᵢ(l).
pub fn brdf_pdf(s: &Lobes, c: &LobeChoice, l: Vec3, v: Vec3) -> f32 {
    let sum = l + v;
    let len2 = sum.dot(sum);
    let mut pdf = c.diffuse * pdf_cosine(l);
    if len2 > 0.0 {
        let h = sum / len2.sqrt();
        if c.specular > 0.0 {
            pdf += c.specular * pdf_ggx_reflection(v, h, s.ax, s.ay);
        }
        if c.clearcoat > 0.0 {
            pdf += c.clearcoat * pdf_gtr1_reflection(v, h, s.cc_alpha2, s.cc_norm);
        }
    }
    pdf
}

/// GLSL's `reflect(i, n)`.
pub fn reflect(i: Vec3, n: Vec3) -> Vec3 {
    i - 2.0 * n.dot(i) * n
}

/// Picks a lobe with u.x, then reuses u.x, rescaled to [0, 1), for that lobe's own sample.
pub fn sample_brdf(s: &Lobes, c: &LobeChoice, v: Vec3, mut u: Vec2) -> Vec3 {
    if u.x < c.diffuse {
        u.x = (u.x / c.diffuse).min(ONE_MINUS_EPSILON);
        return sample_cosine(u);
    }
    u.x -= c.diffuse;
    if u.x < c.specular || c.clearcoat <= 0.0 {
        u.x = (u.x / c.specular).min(ONE_MINUS_EPSILON);
        let h = sample_ggx_visible_normal(v, s.ax, s.ay, u);
        return reflect(-v, h);
    }
    u.x = ((u.x - c.specular) / c.clearcoat).min(ONE_MINUS_EPSILON);
    let h = sample_gtr1_normal(s.cc_alpha2, u);
    reflect(-v, h)
}

/// The power heuristic (β = 2) for one sample from each of two techniques, divided by the
/// sampling technique's own pdf.
pub fn mis_weight_over_pdf(own: f32, other: f32) -> f32 {
    own / (own * own + other * other)
}
