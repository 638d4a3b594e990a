//! Mirror of `glsl/include/environment.glsl`: the lat-long mapping, texel and background
//! lookups, and sampling the distribution.

use super::distribution::row_cos;
use super::{Distribution, Environment};
use crate::shading::common::{INV_PI, INV_TWO_PI, ONE_MINUS_EPSILON, PI, TWO_PI};
use glam::{UVec2, Vec2, Vec3};

pub fn direction_to_uv(d: Vec3) -> Vec2 {
    let mut u = 0.5 + d.x.atan2(-d.z) * INV_TWO_PI;
    u -= u.floor();
    // acos(d.y), as atan2 for accuracy near the poles (see environment.glsl).
    let v = (d.x * d.x + d.z * d.z).sqrt().atan2(d.y) * INV_PI;
    Vec2::new(u, v)
}

/// The direction with azimuth `u` and polar angle θ given by its cosine and sine.
pub fn direction(u: f32, cos_theta: f32, sin_theta: f32) -> Vec3 {
    let phi = TWO_PI * (u - 0.5);
    Vec3::new(sin_theta * phi.sin(), cos_theta, -sin_theta * phi.cos())
}

pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    let theta = PI * uv.y;
    direction(uv.x, theta.cos(), theta.sin())
}

/// The texel holding `uv`.
pub fn texel_of(width: u32, height: u32, uv: Vec2) -> UVec2 {
    let p = uv * Vec2::new(width as f32, height as f32);
    UVec2::new((p.x.max(0.0) as u32).min(width - 1), (p.y.max(0.0) as u32).min(height - 1))
}

/// The radiance lighting sees: the texel holding `uv` (piecewise constant).
pub fn radiance(env: &Environment, uv: Vec2) -> Vec3 {
    let t = texel_of(env.width, env.height, uv);
    Vec3::from(env.texel(t.x, t.y))
}

/// Bilinear radiance between texel centres, wrapping in u and clamping in v: for the background.
pub fn background(env: &Environment, uv: Vec2) -> Vec3 {
    let (w, h) = (env.width as i32, env.height as i32);
    let p = uv * Vec2::new(w as f32, h as f32) - 0.5;
    let f = p.floor();
    let t = p - f;
    let mut x0 = f.x as i32;
    let mut y0 = f.y as i32;
    x0 = if x0 < 0 { w - 1 } else { x0.min(w - 1) };
    let x1 = if x0 + 1 == w { 0 } else { x0 + 1 };
    let y1 = (y0 + 1).clamp(0, h - 1);
    y0 = y0.clamp(0, h - 1);
    let texel = |x: i32, y: i32| Vec3::from(env.texel(x as u32, y as u32));
    let top = texel(x0, y0).lerp(texel(x1, y0), t.x);
    let bottom = texel(x0, y1).lerp(texel(x1, y1), t.x);
    top.lerp(bottom, t.y)
}

impl Distribution {
    /// pdf over solid angle of the cell holding texel `t`.
    pub fn texel_cell_pdf(&self, t: UVec2) -> f32 {
        self.cell_pdf[((t.y / self.block_y) * self.columns + t.x / self.block_x) as usize]
    }

    /// pdf over solid angle of [`Distribution::sample`] producing a direction at `uv`.
    pub fn pdf(&self, uv: Vec2) -> f32 {
        self.texel_cell_pdf(texel_of(self.width, self.height, uv))
    }

    /// Samples a direction: a cell by the tables, then uniformly in solid angle within it.
    /// Returns the direction and the texel it lies in.
    pub fn sample(&self, u: Vec2) -> (Vec3, UVec2) {
        let row = self.marginal.search(u.y);
        let (r0, r1) = (self.marginal.cdf[row], self.marginal.cdf[row + 1]);
        let dv = if r1 > r0 { (u.y - r0) / (r1 - r0) } else { 0.5 };
        let table = &self.conditional[row];
        let column = table.search(u.x);
        let (c0, c1) = (table.cdf[column], table.cdf[column + 1]);
        let du = if c1 > c0 { (u.x - c0) / (c1 - c0) } else { 0.5 };
        self.point_in_cell(row as u32, column as u32, du.min(ONE_MINUS_EPSILON), dv.min(ONE_MINUS_EPSILON))
    }

    /// The point at (du, dv) ∈ [0, 1)² of cell (row, column), uniform in azimuth and in cos θ,
    /// and its texel, as `env_point_in_cell` computes them.
    pub fn point_in_cell(&self, row: u32, column: u32, du: f32, dv: f32) -> (Vec3, UVec2) {
        let start = UVec2::new(column * self.block_x, row * self.block_y);
        let end = (start + UVec2::new(self.block_x, self.block_y)).min(UVec2::new(self.width, self.height));
        let x = start.x as f32 + du * (end.x - start.x) as f32;
        let (z0, z1) = (row_cos(start.y, self.height) as f32, row_cos(end.y, self.height) as f32);
        let z = z0 + (z1 - z0) * dv;
        let sin_theta = (1.0 - z * z).max(0.0).sqrt();
        let y = if self.block_y == 1 {
            start.y
        } else {
            ((sin_theta.atan2(z) * INV_PI * self.height as f32) as u32).clamp(start.y, end.y - 1)
        };
        (direction(x / self.width as f32, z, sin_theta), UVec2::new((x as u32).min(end.x - 1), y))
    }
}
