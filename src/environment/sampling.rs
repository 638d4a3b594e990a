//! Mirror of `glsl/include/environment.glsl`: the lat-long mapping, bilinear radiance, and
//! sampling the piecewise-constant distribution.

use super::{Distribution, Environment};
use crate::shading::common::{INV_PI, INV_TWO_PI, ONE_MINUS_EPSILON, PI, TWO_PI};
use glam::{Vec2, Vec3};

pub fn direction_to_uv(d: Vec3) -> Vec2 {
    let mut u = 0.5 + d.x.atan2(-d.z) * INV_TWO_PI;
    u -= u.floor();
    // acos(d.y), as atan2 for accuracy near the poles (see environment.glsl).
    let v = (d.x * d.x + d.z * d.z).sqrt().atan2(d.y) * INV_PI;
    Vec2::new(u, v)
}

pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    let phi = TWO_PI * (uv.x - 0.5);
    let theta = PI * uv.y;
    let sin_theta = theta.sin();
    Vec3::new(sin_theta * phi.sin(), theta.cos(), -sin_theta * phi.cos())
}

/// Bilinear radiance between texel centres, wrapping in u and clamping in v.
pub fn radiance(env: &Environment, uv: Vec2) -> Vec3 {
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
    fn cell_index(&self, uv: Vec2) -> usize {
        let column = ((uv.x * self.columns as f32) as u32).min(self.columns - 1);
        let row = ((uv.y * self.rows as f32) as u32).min(self.rows - 1);
        (row * self.columns + column) as usize
    }

    /// pdf over solid angle of [`Distribution::sample`] producing direction `d` at `uv`.
    pub fn pdf(&self, uv: Vec2, d: Vec3) -> f32 {
        let sin_theta = (1.0 - d.y * d.y).max(0.0).sqrt();
        if sin_theta <= 0.0 {
            return 0.0;
        }
        self.cell_pdf[self.cell_index(uv)] / (2.0 * PI * PI * sin_theta)
    }

    fn search(cdf: &[f32], u: f32) -> usize {
        // Largest i < n with cdf[i] <= u, as the GPU's binary search finds it.
        let (mut lo, mut hi) = (0usize, cdf.len() - 1);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if cdf[mid] <= u {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// Samples a direction; returns it with its uv and pdf over solid angle.
    pub fn sample(&self, u: Vec2) -> (Vec3, Vec2, f32) {
        let row = Distribution::search(&self.marginal_cdf, u.y);
        let (r0, r1) = (self.marginal_cdf[row], self.marginal_cdf[row + 1]);
        let dv = if r1 > r0 { (u.y - r0) / (r1 - r0) } else { 0.5 };
        let stride = self.columns as usize + 1;
        let conditional = &self.conditional_cdf[row * stride..(row + 1) * stride];
        let column = Distribution::search(conditional, u.x);
        let (c0, c1) = (conditional[column], conditional[column + 1]);
        let du = if c1 > c0 { (u.x - c0) / (c1 - c0) } else { 0.5 };
        let uv = Vec2::new(
            (column as f32 + du.min(ONE_MINUS_EPSILON)) / self.columns as f32,
            (row as f32 + dv.min(ONE_MINUS_EPSILON)) / self.rows as f32,
        );
        let sin_theta = (PI * uv.y).sin();
        let pdf = if sin_theta > 0.0 {
            self.cell_pdf[row * self.columns as usize + column] / (2.0 * PI * PI * sin_theta)
        } else {
            0.0
        };
        (uv_to_direction(uv), uv, pdf)
    }
}
