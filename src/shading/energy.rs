//! The energy-compensation table of a model (Kulla and Conty 2017): the directional albedo
//! E(μ, roughness) of the single-scattering specular lobe with F = 1, and its cosine-weighted
//! average E_avg(roughness). The GPU builds E (`glsl/energy_table.comp`, driven by
//! `render::energy`); [`EnergyTable::from_albedo`] adds the averages. [`build_albedo`] is the
//! kernel's CPU mirror, for tests.

use super::brdf::{make_half_vector, make_lobes_with, make_view, specular_shadowing, Shading};
use super::model::Model;
use super::sampling::{azimuth, pdf_specular_reflection, reflect, sample_specular_normal};
use crate::material::Params;
use glam::Vec3;

/// Nodes per axis: √μ and roughness, each from 0 to 1 (`ENERGY_TABLE_SIZE` in brdf.glsl).
pub const SIZE: usize = 32;
/// Quadrature points per axis of the sampler's unit square (`QUADRATURE` in energy_table.comp).
pub const QUADRATURE: usize = 64;

/// E on the grid, then E_avg per roughness node: the layout of brdf.glsl's `energy_table`.
#[derive(Clone, Debug, PartialEq)]
pub struct EnergyTable {
    pub values: Vec<f32>,
}

/// The table's μ at node `i` (never exactly 0, where the view is degenerate).
pub fn node_mu(i: usize) -> f32 {
    let t = i as f32 / (SIZE - 1) as f32;
    (t * t).max(1e-4)
}

/// The table's roughness at node `j`.
pub fn node_roughness(j: usize) -> f32 {
    j as f32 / (SIZE - 1) as f32
}

impl EnergyTable {
    /// Completes a table from E (SIZE × SIZE, μ fastest) with E_avg = 2∫E(μ)·μ dμ of the same
    /// interpolant the shaders use (linear in √μ), so that compensation restores exactly the
    /// energy the interpolated E says is missing.
    pub fn from_albedo(albedo: Vec<f32>) -> EnergyTable {
        assert_eq!(albedo.len(), SIZE * SIZE);
        let mut values = albedo;
        let steps = 4096;
        let averages: Vec<f32> = (0..SIZE)
            .map(|j| {
                let r = node_roughness(j);
                // Midpoint rule in t = √μ: 2∫E·μ dμ = 4∫E(t²)·t³ dt.
                let sum: f64 = (0..steps)
                    .map(|k| {
                        let t = (k as f64 + 0.5) / steps as f64;
                        let e = lookup(&values, (t * t) as f32, r) as f64;
                        4.0 * e * t * t * t
                    })
                    .sum();
                (sum / steps as f64) as f32
            })
            .collect();
        values.extend(averages);
        EnergyTable { values }
    }

    /// A table of zeros, bound where compensation is off (the shaders never read it then).
    pub fn placeholder() -> EnergyTable {
        EnergyTable { values: vec![0.0; SIZE * SIZE + SIZE] }
    }
}

/// Bilinear E(μ, roughness), as brdf.glsl's `energy_albedo`, on the E part of `values`.
pub fn lookup(values: &[f32], mu: f32, roughness: f32) -> f32 {
    let n = SIZE as i32;
    let x = mu.clamp(0.0, 1.0).sqrt() * (n - 1) as f32;
    let y = roughness.clamp(0.0, 1.0) * (n - 1) as f32;
    let x0 = (x as i32).min(n - 2);
    let y0 = (y as i32).min(n - 2);
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let i = (y0 * n + x0) as usize;
    let mix = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let bottom = mix(values[i], values[i + 1], fx);
    let top = mix(values[i + SIZE], values[i + SIZE + 1], fx);
    mix(bottom, top, fy)
}

/// E on the grid for a model, by the same quadrature as energy_table.comp, on the CPU.
pub fn build_albedo(model: &Model) -> Vec<f32> {
    let shading = Shading { model: Model { energy_compensation: false, ..*model }, energy: None };
    let mut out = Vec::with_capacity(SIZE * SIZE);
    for j in 0..SIZE {
        for i in 0..SIZE {
            let mu = node_mu(i);
            let params = Params {
                base_color: [1.0; 3],
                metallic: 1.0,
                roughness: node_roughness(j),
                sheen_tint: 0.0,
                ..Params::default()
            };
            let s = make_lobes_with(&params, &shading);
            let v = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            let view = make_view(&s, v);
            let q = QUADRATURE as f32;
            let mut sum = 0.0f32;
            for a in 0..QUADRATURE {
                let phi = azimuth((a as f32 + 0.5) / q);
                for b in 0..QUADRATURE {
                    let l = reflect(-v, sample_specular_normal(&s, &view, phi, (b as f32 + 0.5) / q));
                    if l.z <= 0.0 {
                        continue;
                    }
                    let hv = make_half_vector(&s, l, v);
                    let pdf = pdf_specular_reflection(&view, &hv);
                    if pdf > 0.0 {
                        sum += specular_shadowing(&s, &view, l) * hv.d_spec * l.z / pdf;
                    }
                }
            }
            out.push(sum / (q * q));
        }
    }
    out
}
