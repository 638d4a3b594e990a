//! The built-in orthographic sphere (`lookdev gbuffer --builtin sphere`): analytic normals,
//! coverage of the unit disk, constant view vectors, tangents around +Y, and the file the
//! command writes reads back as the same g-buffer.

mod common;

use common::cli::{assert_success, lookdev};
use glam::Vec3;
use lookdev::gbuffer::{GBuffer, SPHERE_FRAME_HALF_EXTENT, SPHERE_ID};

/// The world X and Y of a position in pixels, for a `width` × `height` sphere image.
fn world(width: u32, height: u32, px: f32, py: f32) -> (f32, f32) {
    let pixel = 2.0 * SPHERE_FRAME_HALF_EXTENT / width.min(height) as f32;
    ((px - 0.5 * width as f32) * pixel, (0.5 * height as f32 - py) * pixel)
}

#[test]
fn normals_are_the_analytic_spheres_and_coverage_is_the_unit_disk() {
    let (width, height) = (96, 64);
    let g = GBuffer::sphere(width, height);
    assert_eq!((g.width, g.height), (width, height));
    let mut covered_area = 0.0;
    let mut whole = 0;
    for y in 0..height {
        for x in 0..width {
            let p = (y * width + x) as usize;
            let n = Vec3::from(g.normal[p]);
            assert!((n.length() - 1.0).abs() < 1e-5, "pixel ({x},{y}): |N| = {}", n.length());
            assert_eq!(g.view[p], [0.0, 0.0, 1.0], "pixel ({x},{y}): V is constant");
            let t = Vec3::from(g.tangent[p]);
            assert!((t.length() - 1.0).abs() < 1e-5 && t.dot(n).abs() < 1e-5, "pixel ({x},{y}): T {t} for N {n}");
            // The pixel's corners: all inside the circle means wholly covered, all outside
            // (and the circle not crossing the pixel) means background.
            let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                .map(|(dx, dy)| world(width, height, x as f32 + dx, y as f32 + dy));
            let inside = corners.iter().filter(|(wx, wy)| wx * wx + wy * wy < 1.0).count();
            let (cx, cy) = world(width, height, x as f32 + 0.5, y as f32 + 0.5);
            let coverage = g.coverage[p];
            covered_area += coverage;
            if inside == 4 {
                whole += 1;
                assert_eq!(coverage, 1.0, "pixel ({x},{y}) lies inside the sphere");
                let analytic = Vec3::new(cx, cy, (1.0 - cx * cx - cy * cy).sqrt());
                assert!((n - analytic).length() < 1e-5, "pixel ({x},{y}): N {n}, the sphere's {analytic}");
                // Around +Y, eastward: +X at the front, turned with the sphere elsewhere.
                let around = Vec3::Y.cross(analytic).normalize();
                assert!((t - around).length() < 1e-4, "pixel ({x},{y}): T {t}, around +Y {around}");
            }
            if inside == 0 && cx.hypot(cy) > 1.0 + SPHERE_FRAME_HALF_EXTENT * 2.0 / height as f32 {
                assert_eq!(coverage, 0.0, "pixel ({x},{y}) lies outside the sphere");
            }
            assert_eq!(g.object_id[p], if coverage > 0.0 { SPHERE_ID } else { 0 }, "pixel ({x},{y})");
            if coverage > 0.0 {
                assert!(n.z > 0.0, "pixel ({x},{y}): a covered normal faces the camera");
            }
        }
    }
    // The disk's area in pixels: π / (world units per pixel)².
    let pixel = 2.0 * SPHERE_FRAME_HALF_EXTENT / height as f32;
    let disk = std::f32::consts::PI / (pixel * pixel);
    assert!((covered_area / disk - 1.0).abs() < 0.01, "coverage {covered_area} pixels, the disk {disk}");
    assert!(whole as f32 > 0.9 * disk, "{whole} wholly covered pixels of {disk}");
    assert_eq!(g.object_names.get(&SPHERE_ID).map(String::as_str), Some("sphere"));
    assert!(g.masks.is_empty() && g.maps.is_empty());
}

#[test]
fn the_sphere_is_centred_and_fills_the_shorter_side() {
    for (width, height) in [(64, 64), (40, 80), (81, 33)] {
        let g = GBuffer::sphere(width, height);
        // Symmetric left to right and top to bottom.
        for y in 0..height {
            for x in 0..width {
                let p = (y * width + x) as usize;
                let mirrored = (y * width + (width - 1 - x)) as usize;
                let flipped = ((height - 1 - y) * width + x) as usize;
                assert_eq!(g.coverage[p], g.coverage[mirrored], "({x},{y}) {width}×{height}");
                assert_eq!(g.coverage[p], g.coverage[flipped], "({x},{y}) {width}×{height}");
            }
        }
        // Across the shorter side the outline spans 1/1.1 of the image.
        let short = width.min(height);
        let across = if width <= height {
            (0..width).map(|x| g.coverage[((height / 2) * width + x) as usize]).sum::<f32>()
        } else {
            (0..height).map(|y| g.coverage[(y * width + width / 2) as usize]).sum::<f32>()
        };
        let expected = short as f32 / SPHERE_FRAME_HALF_EXTENT;
        assert!((across - expected).abs() < 1.5, "{width}×{height}: {across} pixels across, expected {expected}");
    }
}

#[test]
fn the_command_writes_the_sphere() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sphere.exr");
    assert_success(&lookdev(&["gbuffer", "--builtin", "sphere", "--size", "48", "40", "--out", out.to_str().unwrap()]));
    let read = GBuffer::read(&out).unwrap();
    let built = GBuffer::sphere(48, 40);
    assert_eq!((read.width, read.height), (48, 40));
    // Directions are stored as float and renormalised on reading: equal to rounding.
    let largest_difference = |a: &[[f32; 3]], b: &[[f32; 3]]| {
        a.iter().zip(b).flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs())).fold(0.0f32, f32::max)
    };
    assert!(largest_difference(&read.normal, &built.normal) < 1e-6);
    assert!(largest_difference(&read.view, &built.view) < 1e-6);
    assert!(largest_difference(&read.tangent, &built.tangent) < 1e-6);
    assert!(read.has_view && read.has_tangent);
    assert_eq!(read.object_id, built.object_id);
    assert_eq!(read.object_names, built.object_names);
    // Coverage is stored as half: the sixteenths are exact.
    assert_eq!(read.coverage, built.coverage);
}
