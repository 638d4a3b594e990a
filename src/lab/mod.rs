//! The BRDF lab (docs/shading.md#brdf-models, `lookdev brdf`): what the plots show, computed from the Rust
//! reference of the shaders, so a plot shows exactly what the renderer evaluates.
//!
//! - [`directional_albedo`]: E(θv) = ∫ f(l, v)·cosθl dl, by a deterministic quadrature that
//!   combines the model's own samplers with the balance heuristic;
//! - [`slice_directions`]: BRDF Explorer's (θh, θd, φd) parameterisation (Rusinkiewicz 1998);
//! - [`in_plane`]: the lobe in the plane of incidence.

pub mod albedo;
pub mod furnace;
pub mod plot;

use crate::material::Params;
use crate::shading::brdf::{
    disney_brdf, disney_lobes, lobes_total, make_half_vector, make_lobes_with, make_view, BrdfLobes, Lobes, Shading,
    View,
};
use crate::shading::sampling::{
    azimuth, pdf_gtr1_reflection, pdf_specular_reflection, reflect, sample_gtr1_normal, sample_specular_normal,
};
use glam::Vec3;

/// A material under a model: what one curve or one panel of a plot shows.
#[derive(Clone, Debug)]
pub struct Subject {
    /// The legend: the material's name and the model's label.
    pub label: String,
    pub params: Params,
    pub shading: Shading,
}

impl Subject {
    pub fn lobes(&self) -> Lobes {
        make_lobes_with(&self.params, &self.shading)
    }

    /// f(l, v) in the shading frame.
    pub fn brdf(&self, l: Vec3, v: Vec3) -> Vec3 {
        let s = self.lobes();
        disney_brdf(&s, &make_view(&s, v), l, &make_half_vector(&s, l, v))
    }
}

/// Quadrature points per axis of each sampler's unit square in [`directional_albedo`].
pub const ALBEDO_QUADRATURE: usize = 160;

/// The view direction at polar angle θv (radians), in the x–z plane.
pub fn view_at(theta_v: f32) -> Vec3 {
    Vec3::new(theta_v.sin(), 0.0, theta_v.cos())
}

/// E(θv) per channel: a midpoint grid over the unit square of each of three samplers, combined
/// with the balance heuristic: the model's specular sampler, GTR1 when there is a clearcoat, and
/// for the diffuse lobes one uniform in φ and in √cosθ (pdf 1/(4π√cosθ)). That last one puts
/// more points near the horizon than cosine sampling would, where the energy-compensation lobe of
/// a smooth surface lives. The grid makes the result deterministic.
pub fn directional_albedo(subject: &Subject, theta_v: f32) -> Vec3 {
    directional_albedo_with(subject, theta_v, ALBEDO_QUADRATURE)
}

pub fn directional_albedo_with(subject: &Subject, theta_v: f32, n: usize) -> Vec3 {
    directional_integral(subject, theta_v, n, lobes_total)
}

/// Each lobe's share of E(θv), as the lobe AOVs count them: diffuse (with subsurface) and
/// sheen weighted by 1 − metallic, specular, clearcoat ([`crate::render::renderer::LOBES`] order:
/// diffuse, specular, clearcoat, sheen). They sum to [`directional_albedo`].
pub fn lobe_albedos(subject: &Subject, theta_v: f32, n: usize) -> [Vec3; 4] {
    let weight = 1.0 - subject.params.metallic;
    [
        directional_integral(subject, theta_v, n, |_, b| b.diffuse * weight),
        directional_integral(subject, theta_v, n, |_, b| b.specular),
        directional_integral(subject, theta_v, n, |_, b| Vec3::splat(b.clearcoat)),
        directional_integral(subject, theta_v, n, |_, b| b.sheen * weight),
    ]
}

/// ∫ g(l)·cosθl dl over the hemisphere, g a function of the BRDF's lobes at l, with the
/// quadrature of [`directional_albedo`].
pub fn directional_integral(subject: &Subject, theta_v: f32, n: usize, g: impl Fn(&Lobes, &BrdfLobes) -> Vec3) -> Vec3 {
    let s = subject.lobes();
    let v = view_at(theta_v);
    let view = make_view(&s, v);
    let coat = s.clearcoat > 0.0;
    let techniques = if coat { 3 } else { 2 };
    let pdfs = |view: &View, l: Vec3| -> (f64, crate::shading::brdf::HalfVector) {
        let hv = make_half_vector(&s, l, v);
        let mut p = pdf_grazing(l) + pdf_specular_reflection(view, &hv) as f64;
        if coat {
            p += pdf_gtr1_reflection(view, &hv) as f64;
        }
        (p, hv)
    };
    let mut sum = [0.0f64; 3];
    for technique in 0..techniques {
        for i in 0..n {
            let phi = azimuth((i as f32 + 0.5) / n as f32);
            for j in 0..n {
                let u = (j as f32 + 0.5) / n as f32;
                let l = match technique {
                    0 => sample_grazing(phi, u),
                    1 => reflect(-v, sample_specular_normal(&s, &view, phi, u)),
                    _ => reflect(-v, sample_gtr1_normal(s.cc_alpha2, s.cc_log2_alpha2, phi, u)),
                };
                if l.z <= 0.0 {
                    continue;
                }
                let (p, hv) = pdfs(&view, l);
                if p <= 0.0 {
                    continue;
                }
                let f = g(&s, &disney_lobes(&s, &view, l, &hv));
                let w = l.z as f64 / p;
                sum[0] += f.x as f64 * w;
                sum[1] += f.y as f64 * w;
                sum[2] += f.z as f64 * w;
            }
        }
    }
    let scale = 1.0 / (n * n) as f64;
    Vec3::new((sum[0] * scale) as f32, (sum[1] * scale) as f32, (sum[2] * scale) as f32)
}

/// The hemisphere with cosθ = u²: denser toward the horizon than the cosine sampler.
fn sample_grazing(azimuth: glam::Vec2, u: f32) -> Vec3 {
    let cos_t = u * u;
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    Vec3::new(sin_t * azimuth.x, sin_t * azimuth.y, cos_t)
}

/// pdf over solid angle of [`sample_grazing`]: (du/dcosθ)/2π = 1/(4π√cosθ).
fn pdf_grazing(l: Vec3) -> f64 {
    if l.z > 0.0 {
        1.0 / (4.0 * std::f64::consts::PI * (l.z as f64).sqrt())
    } else {
        0.0
    }
}

/// (l, v) of BRDF Explorer's slice coordinates: the half vector at (θh, φh = 0) and the
/// difference vector at (θd, φd) about it (angles in radians).
pub fn slice_directions(theta_h: f32, theta_d: f32, phi_d: f32) -> (Vec3, Vec3) {
    let d = Vec3::new(theta_d.sin() * phi_d.cos(), theta_d.sin() * phi_d.sin(), theta_d.cos());
    let e = Vec3::new(-d.x, -d.y, d.z);
    // Rotate the half-vector frame by θh about +Y: its +Z goes to h.
    let rotate = |w: Vec3| {
        let (s, c) = theta_h.sin_cos();
        Vec3::new(c * w.x + s * w.z, w.y, -s * w.x + c * w.z)
    };
    (rotate(d), rotate(e))
}

/// The direction at signed angle θ (radians) from the normal in the x–z plane: negative angles
/// are on the −x side, where the plane of incidence puts the light.
pub fn in_plane(theta: f32) -> Vec3 {
    Vec3::new(theta.sin(), 0.0, theta.cos())
}

/// Rec.709 luminance, the one number a curve shows of an RGB value.
pub fn luminance(c: Vec3) -> f32 {
    crate::shading::common::luminance(c)
}
