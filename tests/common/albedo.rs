//! Directional albedo E(v) = ∫ f(l, v)·cosθ_l dl by deterministic quadrature.
//!
//! The lobes of the BRDF range from nearly flat (diffuse) to nearly a delta (GGX at α = 0.001,
//! GTR1 at clearcoat_gloss 1), so no single grid resolves them all. Three midpoint grids, each
//! uniform in the inverse-CDF coordinates of one analytic density (cosine, GGX half vectors,
//! GTR1 half vectors), are combined with the balance heuristic. The result is an independent
//! check of the renderer: it shares only `disney_brdf`, not its samplers or pdfs.

use glam::Vec3;
use lookdev::material::Params;
use lookdev::shading::brdf::{disney_brdf, make_half_vector, make_lobes_with, make_view, Shading};
use std::f64::consts::PI;

struct Density {
    alpha_ggx: f64,
    alpha2_gtr1: f64,
}

impl Density {
    fn cosine_pdf(&self, l: [f64; 3]) -> f64 {
        l[2].max(0.0) / PI
    }
    fn ggx_d(&self, cos_h: f64) -> f64 {
        let a2 = self.alpha_ggx * self.alpha_ggx;
        let d = cos_h * cos_h * (a2 - 1.0) + 1.0;
        a2 / (PI * d * d)
    }
    fn gtr1_d(&self, cos_h: f64) -> f64 {
        let a2 = self.alpha2_gtr1;
        (a2 - 1.0) / (PI * a2.ln() * (1.0 + (a2 - 1.0) * cos_h * cos_h))
    }
    /// pdf over l of reflecting v about a half vector h drawn ∝ D(h)·cosθh.
    fn reflection_pdf(&self, d: f64, h: [f64; 3], v: [f64; 3]) -> f64 {
        let vh = dot(v, h);
        if h[2] <= 0.0 || vh <= 0.0 {
            return 0.0;
        }
        d * h[2] / (4.0 * vh)
    }
    fn pdfs(&self, l: [f64; 3], v: [f64; 3]) -> [f64; 3] {
        let h = normalize(add(l, v));
        [self.cosine_pdf(l), self.reflection_pdf(self.ggx_d(h[2]), h, v), self.reflection_pdf(self.gtr1_d(h[2]), h, v)]
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn normalize(a: [f64; 3]) -> [f64; 3] {
    let len = dot(a, a).sqrt();
    [a[0] / len, a[1] / len, a[2] / len]
}
fn spherical(cos_t: f64, phi: f64) -> [f64; 3] {
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    [sin_t * phi.cos(), sin_t * phi.sin(), cos_t]
}
fn reflect_about(v: [f64; 3], h: [f64; 3]) -> [f64; 3] {
    let k = 2.0 * dot(v, h);
    [k * h[0] - v[0], k * h[1] - v[1], k * h[2] - v[2]]
}

/// E(θv) per colour channel for view direction (sinθv, 0, cosθv), in the shading frame.
pub fn directional_albedo(params: &Params, theta_v: f64) -> [f64; 3] {
    directional_albedo_at(params, [theta_v.sin(), 0.0, theta_v.cos()])
}

pub fn directional_albedo_at(params: &Params, v: [f64; 3]) -> [f64; 3] {
    directional_albedo_at_with(params, &Shading::default(), v)
}

/// The same for a BRDF model. The densities stay GGX's and GTR1's whatever the model's own
/// distribution: they only need to cover the lobes, not to match them.
pub fn directional_albedo_with(params: &Params, shading: &Shading, theta_v: f64) -> [f64; 3] {
    directional_albedo_at_with(params, shading, [theta_v.sin(), 0.0, theta_v.cos()])
}

pub fn directional_albedo_at_with(params: &Params, shading: &Shading, v: [f64; 3]) -> [f64; 3] {
    let lobes = make_lobes_with(params, shading);
    let a = mix(0.1, 0.001, params.clearcoat_gloss as f64);
    let density =
        Density { alpha_ggx: ((lobes.ax as f64) * (lobes.ay as f64)).sqrt(), alpha2_gtr1: (a * a).min(0.999_999) };
    let (n_u, n_phi) = (384usize, 384usize);
    let vf = Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32);
    let view = make_view(&lobes, vf);
    let mut sum = [0.0f64; 3];
    for technique in 0..3 {
        for i in 0..n_u {
            let s = (i as f64 + 0.5) / n_u as f64;
            for j in 0..n_phi {
                let phi = 2.0 * PI * (j as f64 + 0.5) / n_phi as f64;
                let l = match technique {
                    0 => spherical(s.sqrt(), phi),
                    1 => {
                        // GGX: tan²θh = α²·s/(1−s).
                        let t2 = density.alpha_ggx.powi(2) * s / (1.0 - s);
                        reflect_about(v, spherical(1.0 / (1.0 + t2).sqrt(), phi))
                    }
                    _ => {
                        let a2 = density.alpha2_gtr1;
                        let cos2 = (1.0 - a2.powf(1.0 - s)) / (1.0 - a2);
                        reflect_about(v, spherical(cos2.sqrt(), phi))
                    }
                };
                if l[2] <= 0.0 {
                    continue;
                }
                let pdfs = density.pdfs(l, v);
                let own = pdfs[technique];
                let total: f64 = pdfs.iter().sum();
                if own <= 0.0 || total <= 0.0 {
                    continue;
                }
                let lf = Vec3::new(l[0] as f32, l[1] as f32, l[2] as f32).normalize();
                let f = disney_brdf(&lobes, &view, lf, &make_half_vector(&lobes, lf, vf));
                // Balance heuristic: f·cos·(own/total)/own = f·cos/total.
                let weight = l[2] / total / (n_u * n_phi) as f64;
                for c in 0..3 {
                    sum[c] += f[c] as f64 * weight;
                }
            }
        }
    }
    sum
}

fn mix(a: f64, b: f64, t: f64) -> f64 {
    a + (b - a) * t
}
