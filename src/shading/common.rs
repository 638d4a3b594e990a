//! Mirror of `glsl/include/common.glsl`.

use glam::Vec3;

pub use std::f32::consts::PI;
pub const TWO_PI: f32 = 2.0 * PI;
pub const INV_PI: f32 = 1.0 / PI;
pub const INV_TWO_PI: f32 = 0.5 / PI;
/// The largest float below 1: uniform samples must stay in [0, 1).
pub const ONE_MINUS_EPSILON: f32 = 0.99999994;

/// Rec.709 relative luminance, for importance weights.
pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// GLSL's `mix` for scalars.
pub fn mix(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}
