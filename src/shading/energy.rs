//! Building the energy-compensation table ([`EnergyTable`], which sits with the BRDF that reads
//! it): the GPU computes E (`glsl/energy_table.comp`, driven by `render::energy`);
//! [`table_from_albedo`] adds the averages. [`build_albedo`] is the kernel's CPU mirror, for
//! tests.

use super::brdf::{
    energy_albedo, make_half_vector, make_lobes_with, make_view, specular_shadowing, EnergyTable, Shading,
    ENERGY_TABLE_SIZE as SIZE,
};
use super::material::Material;
use super::model::Model;
use super::sampling::{azimuth, pdf_specular_reflection, reflect, sample_specular_normal};
use glam::Vec3;

/// Quadrature points per axis of the sampler's unit square (`QUADRATURE` in energy_table.comp).
pub const QUADRATURE: usize = 64;

/// The table's μ at node `i` (never exactly 0, where the view is degenerate).
pub fn node_mu(i: usize) -> f32 {
    let t = i as f32 / (SIZE - 1) as f32;
    (t * t).max(1e-4)
}

/// The table's roughness at node `j`.
pub fn node_roughness(j: usize) -> f32 {
    j as f32 / (SIZE - 1) as f32
}

/// Completes a table from E (SIZE × SIZE, μ fastest) with E_avg = 2∫E(μ)·μ dμ of the same
/// interpolant the shaders use (linear in √μ), so that compensation restores exactly the energy
/// the interpolated E says is missing.
pub fn table_from_albedo(albedo: Vec<f32>) -> EnergyTable {
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
                    let e = energy_albedo(&values, (t * t) as f32, r) as f64;
                    4.0 * e * t * t * t
                })
                .sum();
            (sum / steps as f64) as f32
        })
        .collect();
    values.extend(averages);
    EnergyTable { values }
}

/// E on the grid for a model, by the same quadrature as energy_table.comp, on the CPU.
pub fn build_albedo(model: &Model) -> Vec<f32> {
    let shading = Shading { model: Model { energy_compensation: false, ..*model }, energy: None };
    let mut out = Vec::with_capacity(SIZE * SIZE);
    for j in 0..SIZE {
        for i in 0..SIZE {
            let mu = node_mu(i);
            // A white metal: only the specular lobe, with F = 1, enters E.
            let white_metal = Material {
                base_color: Vec3::ONE,
                metallic: 1.0,
                subsurface: 0.0,
                specular: 0.5,
                specular_tint: 0.0,
                roughness: node_roughness(j),
                anisotropic: 0.0,
                sheen: 0.0,
                sheen_tint: 0.0,
                clearcoat: 0.0,
                clearcoat_gloss: 1.0,
                ior_edge: Vec3::ZERO,
            };
            let s = make_lobes_with(white_metal, &shading);
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
