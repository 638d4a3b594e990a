//! Mirror of `glsl/include/environment.glsl`: the lat-long mapping, texel and background
//! lookups, and sampling the piecewise-constant distribution.

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

pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    let phi = TWO_PI * (uv.x - 0.5);
    let theta = PI * uv.y;
    let sin_theta = theta.sin();
    Vec3::new(sin_theta * phi.sin(), theta.cos(), -sin_theta * phi.cos())
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

/// pdf over solid angle from pdf_uv, at a unit direction `d`.
pub fn solid_angle_pdf(pdf_uv: f32, d: Vec3) -> f32 {
    let sin_theta = (1.0 - d.y * d.y).max(0.0).sqrt();
    if sin_theta > 0.0 {
        pdf_uv / (2.0 * PI * PI * sin_theta)
    } else {
        0.0
    }
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
    /// pdf_uv of the cell holding `uv`.
    pub fn uv_pdf(&self, uv: Vec2) -> f32 {
        let t = texel_of(self.width, self.height, uv) / self.block;
        self.cell_pdf[(t.y * self.columns + t.x) as usize]
    }

    /// pdf over solid angle of [`Distribution::sample`] producing direction `d` at `uv`.
    pub fn pdf(&self, uv: Vec2, d: Vec3) -> f32 {
        solid_angle_pdf(self.uv_pdf(uv), d)
    }

    /// Last interval r with `cdf[r] ≤ u`, searched between the guides around u's bucket.
    fn search(cdf: &[f32], guide: &[u32], u: f32) -> usize {
        let n = cdf.len() - 1;
        let k = (u * n as f32) as i64;
        let mut lo = guide[(k - 1).max(0) as usize] as usize;
        let mut hi = (guide[(k + 2).min(n as i64) as usize] as usize + 1).min(n);
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

    /// Samples a direction; returns it with its uv and the texel the sample lies in.
    pub fn sample(&self, u: Vec2) -> (Vec3, Vec2, UVec2) {
        let row = Distribution::search(&self.marginal_cdf, &self.marginal_guide, u.y);
        let (r0, r1) = (self.marginal_cdf[row], self.marginal_cdf[row + 1]);
        let dv = if r1 > r0 { (u.y - r0) / (r1 - r0) } else { 0.5 };
        let stride = self.columns as usize + 1;
        let cdf = &self.conditional_cdf[row * stride..(row + 1) * stride];
        let guide = &self.conditional_guide[row * stride..(row + 1) * stride];
        let column = Distribution::search(cdf, guide, u.x);
        let (c0, c1) = (cdf[column], cdf[column + 1]);
        let du = if c1 > c0 { (u.x - c0) / (c1 - c0) } else { 0.5 };

        let start = UVec2::new(column as u32, row as u32) * self.block;
        let end = (start + self.block).min(UVec2::new(self.width, self.height));
        let position = start.as_vec2() + Vec2::new(du, dv).min(Vec2::splat(ONE_MINUS_EPSILON)) * (end - start).as_vec2();
        let uv = position / Vec2::new(self.width as f32, self.height as f32);
        let texel = position.as_uvec2().min(end - 1);
        (uv_to_direction(uv), uv, texel)
    }

    /// pdf over solid angle of a sample returned by [`Distribution::sample`].
    pub fn sample_pdf(&self, d: Vec3, texel: UVec2) -> f32 {
        let cell = texel / self.block;
        solid_angle_pdf(self.cell_pdf[(cell.y * self.columns + cell.x) as usize], d)
    }
}
