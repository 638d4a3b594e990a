//! The built-in sphere: a unit sphere under an orthographic camera, the scene other renderers
//! can reproduce exactly (benches/compare_mitsuba.py renders it in Mitsuba 3).
//!
//! Each pixel is sampled on the regular 4×4 grid the shader ball uses. Coverage is the fraction
//! of subsamples inside the sphere's outline; the normal is the sphere's at the centroid of
//! those subsamples, which is the pixel centre wherever the pixel is wholly covered, so such a
//! pixel's normal is the analytic one exactly (not an average of sixteen, renormalised).

use std::collections::BTreeMap;

use glam::Vec3;

use super::frame::tangent_or_stable;
use super::scene::around_axis;
use super::GBuffer;

/// The sphere's object ID and name.
pub const SPHERE_ID: u32 = 1;
const SPHERE_NAME: &str = "sphere";
/// The image's shorter side spans this many world units either side of the centre: the unit
/// sphere's outline fills 91% of it, and leaves a margin of background all around.
pub const SPHERE_FRAME_HALF_EXTENT: f32 = 1.1;
/// Subsamples per pixel along each axis.
const GRID: usize = 4;

impl GBuffer {
    /// The built-in sphere at `width` × `height`.
    ///
    /// - Camera: orthographic, looking toward −Z with +Y up; the shorter side spans
    ///   ±[`SPHERE_FRAME_HALF_EXTENT`] world units, pixels are square. V = (0, 0, 1) at every
    ///   pixel, background included (whose environment is then the one colour seen toward −Z).
    /// - Object 1 "sphere": the unit sphere at the origin. Tangents run around +Y, as on the
    ///   shader ball's ball (the stable frame at the poles).
    /// - Coverage from a regular 4×4 grid of rays per pixel; no masks or maps.
    ///
    /// A zero width or height is raised to 1. The result is deterministic.
    pub fn sphere(width: u32, height: u32) -> GBuffer {
        let (width, height) = (width.max(1), height.max(1));
        let count = width as usize * height as usize;
        let mut g = GBuffer {
            width,
            height,
            normal: Vec::with_capacity(count),
            view: vec![[0.0, 0.0, 1.0]; count],
            tangent: Vec::with_capacity(count),
            coverage: Vec::with_capacity(count),
            object_id: Vec::with_capacity(count),
            masks: BTreeMap::new(),
            maps: BTreeMap::new(),
            object_names: BTreeMap::from([(SPHERE_ID, SPHERE_NAME.to_string())]),
            mask_names: BTreeMap::new(),
            visibility: None,
            has_view: true,
            has_tangent: true,
            supersample: 1,
        };
        // World units per pixel, and the world position of pixel (0, 0)'s top-left corner.
        let pixel = 2.0 * SPHERE_FRAME_HALF_EXTENT / width.min(height) as f32;
        let left = -0.5 * width as f32 * pixel;
        let top = 0.5 * height as f32 * pixel;
        for y in 0..height {
            for x in 0..width {
                let (hits, centroid) = covered_subsamples(x, y, |px, py| (left + px * pixel, top - py * pixel));
                let (normal, tangent) = match centroid {
                    Some((cx, cy)) => {
                        let normal = Vec3::new(cx, cy, (1.0 - cx * cx - cy * cy).max(0.0).sqrt()).normalize();
                        (normal, tangent_or_stable(normal, around_axis(normal)))
                    }
                    None => (Vec3::Z, Vec3::X),
                };
                g.normal.push(normal.to_array());
                g.tangent.push(tangent.to_array());
                g.coverage.push(hits as f32 / (GRID * GRID) as f32);
                g.object_id.push(if hits > 0 { SPHERE_ID } else { 0 });
            }
        }
        g
    }
}

/// How many of pixel (x, y)'s subsamples fall inside the unit circle, and their centroid in
/// world X and Y (`None` when none does). `world` maps a position in pixels to world X and Y.
fn covered_subsamples(x: u32, y: u32, world: impl Fn(f32, f32) -> (f32, f32)) -> (usize, Option<(f32, f32)>) {
    let mut hits = 0;
    // Offsets within the pixel, summed in pixel units: for a whole pixel they sum to exactly
    // 8 per axis (the grid is symmetric and its offsets are binary fractions), so the centroid
    // is exactly the pixel centre.
    let (mut sum_x, mut sum_y) = (0.0f32, 0.0f32);
    for s in 0..GRID * GRID {
        let offset = |i: usize| (i as f32 + 0.5) / GRID as f32;
        let (ox, oy) = (offset(s % GRID), offset(s / GRID));
        let (wx, wy) = world(x as f32 + ox, y as f32 + oy);
        if wx * wx + wy * wy < 1.0 {
            hits += 1;
            sum_x += ox;
            sum_y += oy;
        }
    }
    let centroid = (hits > 0).then(|| world(x as f32 + sum_x / hits as f32, y as f32 + sum_y / hits as f32));
    (hits, centroid)
}
