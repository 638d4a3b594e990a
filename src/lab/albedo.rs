//! The directional albedo of any material under a model, from tables of the model's own lobes:
//! what the `albedo` AOV holds, as denoisers expect it.
//!
//! Each lobe's albedo is integrated once per model ([`super::directional_integral`]) over a grid
//! of view angles and roughness (clearcoat gloss for the coat), for unit colours:
//!
//! - diffuse, without and with subsurface, per unit `base_color`;
//! - specular at F0 = 0 and F0 = 1, between which Schlick's Fresnel is linear in F0;
//! - sheen per unit sheen colour, and clearcoat per unit `clearcoat`.
//!
//! A material's albedo is then those tables weighted as the BRDF weighs its lobes. Anisotropy
//! is left out (the tables are isotropic), and with the dielectric or conductor Fresnel the
//! specular term is interpolated linearly in F0 like Schlick's.

use super::{directional_integral, Subject};
use crate::material::Params;
use crate::shading::brdf::{tint_luminance, Shading};
use glam::Vec3;

/// Points per axis of the grid: view angle (by cos θv) and roughness (or gloss).
const GRID: usize = 16;
/// Quadrature points per axis of each sampler's unit square, per table entry.
const QUADRATURE: usize = 24;

/// The tables of one model.
pub struct AlbedoTables {
    /// [lobe][roughness][mu], lobes in [`Table`] order.
    tables: Vec<[[f32; GRID]; GRID]>,
}

/// The tables, as indices into [`AlbedoTables::tables`].
#[derive(Clone, Copy)]
enum Table {
    Diffuse,
    Subsurface,
    SpecularF0Zero,
    SpecularF0One,
    Sheen,
    Clearcoat,
}

const TABLES: [Table; 6] =
    [Table::Diffuse, Table::Subsurface, Table::SpecularF0Zero, Table::SpecularF0One, Table::Sheen, Table::Clearcoat];

/// The grid's cos θv values: cell centres, so that a view at grazing reads a sampled value.
fn mu_at(i: usize) -> f32 {
    (i as f32 + 0.5) / GRID as f32
}

/// The grid's roughness (or gloss) values, both ends included.
fn r_at(j: usize) -> f32 {
    j as f32 / (GRID - 1) as f32
}

impl AlbedoTables {
    /// Integrates the tables for a model (a few hundred milliseconds).
    pub fn build(shading: &Shading) -> AlbedoTables {
        let tables = TABLES
            .iter()
            .map(|&table| {
                let mut grid = [[0.0f32; GRID]; GRID];
                for (j, row) in grid.iter_mut().enumerate() {
                    let r = r_at(j);
                    let (params, pick): (Params, fn(&crate::shading::brdf::BrdfLobes) -> f32) = match table {
                        Table::Diffuse => (unit(Params { roughness: r, ..black() }), |b| b.diffuse.x),
                        Table::Subsurface => {
                            (unit(Params { roughness: r, subsurface: 1.0, ..black() }), |b| b.diffuse.x)
                        }
                        Table::SpecularF0Zero => {
                            (Params { roughness: r, metallic: 1.0, base_color: [0.0; 3], ..black() }, |b| b.specular.x)
                        }
                        Table::SpecularF0One => {
                            (Params { roughness: r, metallic: 1.0, base_color: [1.0; 3], ..black() }, |b| b.specular.x)
                        }
                        Table::Sheen => (Params { sheen: 1.0, sheen_tint: 0.0, ..black() }, |b| b.sheen.x),
                        Table::Clearcoat => (Params { clearcoat: 1.0, clearcoat_gloss: r, ..black() }, |b| b.clearcoat),
                    };
                    let subject = Subject { label: String::new(), params, shading: shading.clone() };
                    for (i, value) in row.iter_mut().enumerate() {
                        let theta = mu_at(i).acos();
                        *value = directional_integral(&subject, theta, QUADRATURE, |_, b| Vec3::splat(pick(b))).x;
                    }
                }
                grid
            })
            .collect();
        AlbedoTables { tables }
    }

    /// One table at (cos θv, roughness), bilinear, clamped to the grid.
    fn lookup(&self, table: Table, mu: f32, r: f32) -> f32 {
        let grid = &self.tables[table as usize];
        let x = (mu * GRID as f32 - 0.5).clamp(0.0, (GRID - 1) as f32);
        let y = (r * (GRID - 1) as f32).clamp(0.0, (GRID - 1) as f32);
        let (x0, y0) = (x.floor() as usize, y.floor() as usize);
        let (x1, y1) = ((x0 + 1).min(GRID - 1), (y0 + 1).min(GRID - 1));
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let row = |y: usize| grid[y][x0] * (1.0 - fx) + grid[y][x1] * fx;
        row(y0) * (1.0 - fy) + row(y1) * fy
    }

    /// The directional albedo of `m` seen at cos θv = `mu`, per channel.
    pub fn albedo(&self, m: &Params, mu: f32) -> Vec3 {
        let base = Vec3::from(m.base_color);
        let lum = tint_luminance(base);
        let tint = if lum > 0.0 { base / lum } else { Vec3::ONE };
        let diffuse = self.lookup(Table::Diffuse, mu, m.roughness);
        let subsurface = self.lookup(Table::Subsurface, mu, m.roughness);
        let diffuse = base * (diffuse + (subsurface - diffuse) * m.subsurface);
        let sheen = Vec3::ONE.lerp(tint, m.sheen_tint) * (m.sheen * self.lookup(Table::Sheen, mu, 0.0));
        let f0 = Vec3::splat(0.08 * m.specular).lerp(0.08 * m.specular * tint, m.specular_tint).lerp(base, m.metallic);
        let zero = self.lookup(Table::SpecularF0Zero, mu, m.roughness);
        let one = self.lookup(Table::SpecularF0One, mu, m.roughness);
        let specular = Vec3::splat(zero) + f0 * (one - zero);
        let coat = m.clearcoat * self.lookup(Table::Clearcoat, mu, m.clearcoat_gloss);
        (diffuse + sheen) * (1.0 - m.metallic) + specular + Vec3::splat(coat)
    }
}

/// A material with no lobe at all, to turn one on at a time.
fn black() -> Params {
    Params { base_color: [0.0; 3], specular: 0.0, sheen: 0.0, clearcoat: 0.0, ..Params::default() }
}

/// A white diffuse: base colour 1, no specular.
fn unit(p: Params) -> Params {
    Params { base_color: [1.0; 3], ..p }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lab::directional_albedo;

    #[test]
    fn table_albedos_match_the_integrator() {
        let shading = Shading::default();
        let tables = AlbedoTables::build(&shading);
        let materials = [
            Params::default(),
            Params { base_color: [0.9, 0.4, 0.1], metallic: 1.0, roughness: 0.3, ..Params::default() },
            Params {
                base_color: [0.2, 0.5, 0.8],
                roughness: 0.7,
                subsurface: 0.5,
                sheen: 1.0,
                clearcoat: 0.8,
                ..Params::default()
            },
            Params {
                specular_tint: 1.0,
                sheen_tint: 1.0,
                sheen: 0.5,
                clearcoat_gloss: 0.3,
                clearcoat: 1.0,
                ..Params::default()
            },
        ];
        for m in materials {
            let subject = Subject { label: String::new(), params: m, shading: shading.clone() };
            for theta in [0.1f32, 0.7, 1.2, 1.45] {
                let exact = directional_albedo(&subject, theta);
                let table = tables.albedo(&m, theta.cos());
                let error = (table - exact).abs().max_element() / exact.max_element().max(0.05);
                assert!(error < 0.03, "{m:?} at θv {theta}: table {table}, integrator {exact}");
            }
        }
    }
}
