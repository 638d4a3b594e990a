//! Baking glTF assets into g-buffers and importing their materials, checked against analytic
//! geometry, the material mapping's formulas and the built-in analytic sphere. Every bake runs
//! with Vulkan validation on and fails on any error.

mod common;

use common::cli::{assert_bad_input, assert_success, lookdev, stderr};
use common::gltf::{camera_looking_down_z, cube, plane, srgb_to_linear, uv_sphere, Gltf, Mesh};
use glam::{Mat3, Quat, Vec3};
use lookdev::asset::bake::{bake, BakeOptions};
use lookdev::asset::camera::CameraChoice;
use lookdev::asset::import::Import;
use lookdev::asset::Asset;
use lookdev::gbuffer::GBuffer;
use serde_json::json;
use std::path::{Path, PathBuf};

fn bake_file(path: &Path, size: u32, samples: u32) -> GBuffer {
    let ctx = common::gpu::graphics_context();
    let asset = Asset::load(path).unwrap_or_else(|e| panic!("{e}"));
    let options = BakeOptions { width: size, height: size, samples, camera: CameraChoice::Default, visibility: None };
    let gbuffer = bake(&ctx, &asset, &options, |_, _, _| {}).unwrap_or_else(|e| panic!("{e}"));
    common::gpu::finish(ctx);
    gbuffer
}

/// The ray through the centre of pixel (x, y) (plus a sub-pixel offset) of a camera at `eye`
/// looking down −Z with +Y up and a square frame.
fn ray(eye: Vec3, fov_degrees: f32, size: u32, x: f32, y: f32) -> (Vec3, Vec3) {
    let half = (fov_degrees.to_radians() / 2.0).tan();
    let ndc = |c: f32| 2.0 * c / size as f32 - 1.0;
    (eye, Vec3::new(ndc(x) * half, -ndc(y) * half, -1.0).normalize())
}

fn angle_degrees(a: Vec3, b: Vec3) -> f32 {
    a.normalize().dot(b.normalize()).clamp(-1.0, 1.0).acos().to_degrees()
}

/// The scene of the first test: a sphere on the left, and on the right a cube turned 30° about
/// Y and 20° about X, scaled by 1.5 and mirrored in x (a negative scale, which turns its
/// triangles' winding around).
struct TwoObjects {
    sphere_centre: Vec3,
    cube_centre: Vec3,
    /// Cube space to world: rotation times the mirroring scale (half-size 0.5 before scaling).
    cube_linear: Mat3,
    eye: Vec3,
    fov: f32,
}

const SPHERE_RADIUS: f32 = 1.0;

impl TwoObjects {
    fn new() -> TwoObjects {
        let rotation = Quat::from_rotation_y(30f32.to_radians()) * Quat::from_rotation_x(20f32.to_radians());
        TwoObjects {
            sphere_centre: Vec3::new(-1.3, 0.0, 0.0),
            cube_centre: Vec3::new(1.3, 0.1, 0.0),
            cube_linear: Mat3::from_quat(rotation) * Mat3::from_diagonal(Vec3::new(-1.5, 1.5, 1.5)),
            eye: Vec3::new(0.0, 0.0, 9.0),
            fov: 30.0,
        }
    }

    fn write(&self, dir: &Path) -> PathBuf {
        let mut gltf = Gltf::new();
        let paint = gltf.material(json!({
            "name": "red paint",
            "pbrMetallicRoughness": { "baseColorFactor": [0.8, 0.1, 0.1, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.4 }
        }));
        let steel = gltf.material(json!({
            "name": "steel",
            "pbrMetallicRoughness": { "baseColorFactor": [0.6, 0.6, 0.6, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.3 }
        }));
        let sphere = gltf.mesh("sphere", &[(&uv_sphere(SPHERE_RADIUS, 96, 48), Some(paint))]);
        let cube_mesh = gltf.mesh("cube", &[(&cube(0.5), Some(steel))]);
        gltf.node(json!({ "name": "ball", "mesh": sphere, "translation": self.sphere_centre.to_array() }));
        let rotation = Quat::from_mat3(&(self.cube_linear * Mat3::from_diagonal(Vec3::new(-1.0, 1.0, 1.0) / 1.5)));
        // The cube sits under a parent node, so that the hierarchy's transforms compose.
        let child = gltf.node(json!({
            "name": "box",
            "mesh": cube_mesh,
            "rotation": rotation.to_array(),
            "scale": [-1.5, 1.5, 1.5],
        }));
        gltf.node(json!({ "name": "holder", "translation": self.cube_centre.to_array(), "children": [child] }));
        camera_looking_down_z(&mut gltf, "front", self.eye.to_array(), self.fov, 1.0);
        gltf.write_gltf(dir, "two-objects")
    }

    /// The nearest analytic hit: (distance, object id, outward normal).
    fn trace(&self, origin: Vec3, direction: Vec3) -> Option<(f32, u32, Vec3)> {
        let mut best: Option<(f32, u32, Vec3)> = None;
        // The sphere.
        let oc = origin - self.sphere_centre;
        let b = oc.dot(direction);
        let disc = b * b - (oc.length_squared() - SPHERE_RADIUS * SPHERE_RADIUS);
        if disc > 0.0 {
            let t = -b - disc.sqrt();
            let normal = (origin + direction * t - self.sphere_centre).normalize();
            best = Some((t, 1, normal));
        }
        // The cube, as a slab test in its own space.
        let inverse = self.cube_linear.inverse();
        let (o, d) = (inverse * (origin - self.cube_centre), inverse * direction);
        let (mut near, mut far, mut axis) = (f32::MIN, f32::MAX, 0);
        for k in 0..3 {
            let (t0, t1) = ((-0.5 - o[k]) / d[k], (0.5 - o[k]) / d[k]);
            let (lo, hi) = (t0.min(t1), t0.max(t1));
            if lo > near {
                near = lo;
                axis = k;
            }
            far = far.min(hi);
        }
        if near < far && near > 0.0 && best.is_none_or(|(t, _, _)| near < t) {
            let mut local = Vec3::ZERO;
            local[axis] = if d[axis] > 0.0 { -1.0 } else { 1.0 };
            let normal = (inverse.transpose() * local).normalize();
            best = Some((near, 2, normal));
        }
        best
    }
}

fn names(gbuffer: &GBuffer) -> Vec<(u32, String)> {
    gbuffer.object_names.iter().map(|(id, name)| (*id, name.clone())).collect()
}

#[test]
fn a_sphere_and_a_mirrored_cube_bake_to_their_analytic_normals_ids_masks_and_coverage() {
    let dir = tempfile::tempdir().unwrap();
    let scene = TwoObjects::new();
    let path = scene.write(dir.path());
    let size = 160;
    let g = bake_file(&path, size, 16);
    assert_eq!(names(&g), [(1, "ball/sphere".to_string()), (2, "box/cube".to_string())]);
    let keys: Vec<&str> = g.masks.keys().map(String::as_str).collect();
    assert_eq!(keys, ["red_paint", "steel"]);

    let (mut checked, mut edges, mut coverage_error) = ([0usize; 3], 0, 0.0f64);
    for y in 0..size {
        for x in 0..size {
            let p = (y * size + x) as usize;
            // The analytic coverage and object at 8×8 points in the pixel.
            let mut hits = [0u32; 3];
            for sy in 0..8 {
                for sx in 0..8 {
                    let (o, d) = ray(
                        scene.eye,
                        scene.fov,
                        size,
                        x as f32 + (sx as f32 + 0.5) / 8.0,
                        y as f32 + (sy as f32 + 0.5) / 8.0,
                    );
                    hits[scene.trace(o, d).map_or(0, |h| h.1) as usize] += 1;
                }
            }
            let analytic = (64 - hits[0]) as f32 / 64.0;
            coverage_error += (g.coverage[p] - analytic).abs() as f64;
            assert!(
                (g.coverage[p] - analytic).abs() < 0.2,
                "pixel ({x}, {y}): coverage {} vs {analytic}",
                g.coverage[p]
            );
            if g.coverage[p] > 0.0 && g.coverage[p] < 1.0 {
                edges += 1;
            }
            // Normals, ids and masks where the whole pixel sees one object.
            let Some(object) = (1..3).find(|&k| hits[k] == 64) else { continue };
            let (o, d) = ray(scene.eye, scene.fov, size, x as f32 + 0.5, y as f32 + 0.5);
            let (_, _, expected) = scene.trace(o, d).unwrap();
            let baked = Vec3::from(g.normal[p]);
            // The sphere's 96×48 facets bend smooth normals by well under a degree; the cube's
            // pixels may straddle an edge, where the average of two faces is right.
            let limit = if object == 1 { 1.0 } else { 0.5 };
            let straddles = object == 2 && {
                let corner = |cx: f32, cy: f32| {
                    let (o, d) = ray(scene.eye, scene.fov, size, x as f32 + cx, y as f32 + cy);
                    scene.trace(o, d).map(|h| (h.2 * 100.0).round())
                };
                let first = corner(0.0, 0.0);
                [(1.0, 0.0), (0.0, 1.0), (1.0, 1.0)].iter().any(|&(cx, cy)| corner(cx, cy) != first)
            };
            if !straddles {
                let angle = angle_degrees(baked, expected);
                assert!(
                    angle < limit,
                    "pixel ({x}, {y}) on object {object}: normal {baked} is {angle}° from {expected}"
                );
                checked[object] += 1;
            }
            assert_eq!(g.object_id[p] as usize, object, "pixel ({x}, {y})");
            let (own, other) = if object == 1 { ("red_paint", "steel") } else { ("steel", "red_paint") };
            assert_eq!((g.masks[own][p], g.masks[other][p]), (1.0, 0.0), "pixel ({x}, {y})");
            let v = Vec3::from(g.view[p]);
            assert!(angle_degrees(v, -d) < 1.0, "pixel ({x}, {y}): view {v} vs {}", -d);
            let t = Vec3::from(g.tangent[p]);
            assert!((t.length() - 1.0).abs() < 1e-3 && t.dot(baked).abs() < 1e-3, "pixel ({x}, {y}): tangent {t}");
        }
    }
    assert!(checked[1] > 2000 && checked[2] > 1000, "too few interior pixels checked: {checked:?}");
    assert!(edges > 200, "silhouettes are antialiased: only {edges} partly covered pixels");
    let mean_error = coverage_error / (size * size) as f64;
    assert!(mean_error < 0.005, "mean coverage error {mean_error}");
}

#[test]
fn double_sided_back_faces_face_the_eye_and_single_sided_ones_are_culled() {
    let dir = tempfile::tempdir().unwrap();
    for double_sided in [true, false] {
        let mut gltf = Gltf::new();
        let material = gltf.material(json!({ "name": "card", "doubleSided": double_sided }));
        let mesh = gltf.mesh("card", &[(&plane(1.0), Some(material))]);
        // Turned to face −Z: the camera on +Z sees its back.
        let turned = Quat::from_rotation_y(std::f32::consts::PI);
        gltf.node(json!({ "name": "card", "mesh": mesh, "rotation": turned.to_array() }));
        camera_looking_down_z(&mut gltf, "front", [0.0, 0.0, 4.0], 40.0, 1.0);
        let g = bake_file(&gltf.write_glb(dir.path(), &format!("card-{double_sided}")), 32, 4);
        let centre = (16 * 32 + 16) as usize;
        if double_sided {
            assert_eq!(g.coverage[centre], 1.0);
            let n = Vec3::from(g.normal[centre]);
            assert!(angle_degrees(n, Vec3::Z) < 0.01, "the back face's normal faces the eye: {n}");
        } else {
            assert_eq!(g.coverage.iter().sum::<f32>(), 0.0, "a single-sided back face is not drawn");
        }
    }
}

/// A 2×2 normal map, one tilt per quadrant, encoded as glTF stores tangent-space normals.
fn quadrant_normal_map() -> (image::RgbaImage, [[f32; 3]; 4]) {
    let tilts = [[0.4, 0.3], [-0.5, 0.2], [0.2, -0.6], [-0.3, -0.3]];
    let mut image = image::RgbaImage::new(2, 2);
    let mut normals = [[0.0; 3]; 4];
    for (k, [x, y]) in tilts.into_iter().enumerate() {
        let n = Vec3::new(x, y, (1.0f32 - x * x - y * y).sqrt());
        let encode = |c: f32| ((c * 0.5 + 0.5) * 255.0).round() as u8;
        image.put_pixel(k as u32 % 2, k as u32 / 2, image::Rgba([encode(n.x), encode(n.y), encode(n.z), 255]));
        // What the stored bytes decode to.
        let decoded = Vec3::new(encode(n.x) as f32, encode(n.y) as f32, encode(n.z) as f32) / 255.0 * 2.0 - 1.0;
        normals[k] = decoded.to_array();
    }
    (image, normals)
}

#[test]
fn a_normal_mapped_plane_bakes_to_the_perturbed_normals_with_given_or_generated_tangents() {
    let dir = tempfile::tempdir().unwrap();
    let (image, normals) = quadrant_normal_map();
    for given_tangents in [false, true] {
        let mut gltf = Gltf::new();
        let texture = gltf.texture(&image);
        gltf.json["samplers"] = json!([{ "magFilter": 9728, "minFilter": 9728 }]);
        gltf.json["textures"][texture]["sampler"] = json!(0);
        let material = gltf.material(json!({ "name": "bumpy", "normalTexture": { "index": texture, "scale": 0.5 } }));
        let mut mesh: Mesh = plane(1.0);
        if given_tangents {
            mesh.tangents = Some(vec![[1.0, 0.0, 0.0, 1.0]; 4]);
        }
        let mesh = gltf.mesh("plane", &[(&mesh, Some(material))]);
        gltf.node(json!({ "name": "plane", "mesh": mesh }));
        // The plane fills the frame: half-size 1 at distance 1/tan(20°).
        let distance = 1.0 / 20f32.to_radians().tan();
        camera_looking_down_z(&mut gltf, "front", [0.0, 0.0, distance], 40.0, 1.0);
        let g = bake_file(&gltf.write_gltf(dir.path(), &format!("bumpy-{given_tangents}")), 64, 1);
        for (k, stored) in normals.iter().enumerate() {
            // The quadrant's centre: top-left of the image is u, v = 0, at world (−1, +1).
            let (x, y) = (16 + 32 * (k % 2), 16 + 32 * (k / 2));
            let m = Vec3::from(*stored);
            // The normal scale multiplies the tangent-space x and y; T = +X and B = +Y.
            let expected = Vec3::new(m.x * 0.5, m.y * 0.5, m.z).normalize();
            let baked = Vec3::from(g.normal[y * 64 + x]);
            let angle = angle_degrees(baked, expected);
            assert!(angle < 0.2, "tangents given: {given_tangents}, quadrant {k}: {baked} is {angle}° from {expected}");
            let tangent = Vec3::from(g.tangent[y * 64 + x]);
            assert!(tangent.dot(Vec3::X) > 0.9, "the tangent follows +u: {tangent}");
        }
    }
}

#[test]
fn vertex_colours_and_textures_become_masks_and_maps_that_the_look_binds() {
    let dir = tempfile::tempdir().unwrap();
    let mut gltf = Gltf::new();
    // Left half metallic 1 and roughness 0.2, right half metallic 0 and roughness 1 (B and G);
    // a base colour texture of a rust colour on the left and a pale one on the right.
    let metal_rough = gltf.texture(&image::RgbaImage::from_fn(2, 1, |x, _| {
        if x == 0 {
            image::Rgba([0, 51, 255, 255])
        } else {
            image::Rgba([0, 255, 0, 255])
        }
    }));
    let colors = [[150u8, 60, 20], [230, 200, 170]];
    let albedo = gltf.texture(&image::RgbaImage::from_fn(2, 1, |x, _| {
        let [r, g, b] = colors[x as usize];
        image::Rgba([r, g, b, 255])
    }));
    gltf.json["samplers"] = json!([{ "magFilter": 9728, "minFilter": 9728 }]);
    for texture in [metal_rough, albedo] {
        gltf.json["textures"][texture]["sampler"] = json!(0);
    }
    let factor = [0.9, 0.8, 1.0];
    let material = gltf.material(json!({
        "name": "worn",
        "pbrMetallicRoughness": {
            "metallicRoughnessTexture": { "index": metal_rough },
            "roughnessFactor": 0.9,
            "baseColorTexture": { "index": albedo },
            "baseColorFactor": [factor[0], factor[1], factor[2], 1.0]
        }
    }));
    let mut mesh = plane(1.0);
    mesh.colors = Some(vec![[1.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 0.5], [0.0, 0.0, 1.0, 0.5]]);
    let mesh = gltf.mesh("plane", &[(&mesh, Some(material))]);
    gltf.node(json!({ "name": "plane", "mesh": mesh }));
    camera_looking_down_z(&mut gltf, "front", [0.0, 0.0, 1.0 / 20f32.to_radians().tan()], 40.0, 1.0);
    let path = gltf.write_gltf(dir.path(), "worn");
    let g = bake_file(&path, 64, 4);
    let at = |name: &str, x: usize, y: usize| g.masks[name][y * 64 + x];
    // Vertex colours: red along the top edge, blue (alpha 0.5) along the bottom.
    assert!((at("color0.r", 32, 1) - 1.0).abs() < 0.05 && at("color0.b", 32, 1) < 0.05);
    assert!((at("color0.b", 32, 62) - 1.0).abs() < 0.05 && (at("color0.a", 32, 62) - 0.5).abs() < 0.05);
    assert!((at("color0.r", 32, 32) - 0.5).abs() < 0.05, "colours interpolate");

    // The maps hold the texels (the base colour's times COLOR_0), and the imported look's
    // preset holds the factors: resolved, each pixel has factor × texture.
    let asset = Asset::load(&path).unwrap();
    let import = Import::new(&asset).unwrap();
    let look = import.look(&dir.path().join("worn.toml"), str::to_string);
    assert_eq!(look.objects[0].layers.len(), 1, "one material, one layer");
    let maps: Vec<&str> = g.maps.keys().map(String::as_str).collect();
    assert_eq!(maps, ["base_color.B", "base_color.G", "base_color.R", "metallic", "roughness"]);
    let ids = lookdev::render::scene::covered_object_ids(&g);
    let stacks = lookdev::material::stack::PackedStacks::pack(&look, ids, &g, Path::new("worn.exr")).unwrap();
    for (x, texel) in [(16usize, 0usize), (48, 1)] {
        let (m, r) = if texel == 0 { (1.0, 0.2) } else { (0.0, 1.0) };
        let i = 32 * 64 + x;
        assert!((g.maps["metallic"][i] - m).abs() < 0.01, "metallic at x = {x}");
        assert!((g.maps["roughness"][i] - r).abs() < 0.01, "roughness at x = {x}");
        let blended = stacks.resolve_gbuffer_pixel(&g, i);
        assert!((blended.metallic - m).abs() < 0.01, "metallic at x = {x}: {}", blended.metallic);
        assert!((blended.roughness - 0.9 * r).abs() < 0.01, "roughness at x = {x}: {}", blended.roughness);
        // Half way down, COLOR_0 is (0.5, 0, 0.5).
        let color0 = [0.5, 0.0, 0.5];
        let expected = [0, 1, 2].map(|k| factor[k] * srgb_to_linear(colors[texel][k]) * color0[k]);
        for k in 0..3 {
            assert!(
                (blended.base_color[k] - expected[k]).abs() < 0.01,
                "base colour at x = {x}: {:?} vs {expected:?}",
                blended.base_color
            );
        }
    }
}

/// A 2×1 texture: `left` on the left half of the image, `right` on the right.
fn halves(left: [u8; 4], right: [u8; 4]) -> image::RgbaImage {
    image::RgbaImage::from_fn(2, 1, |x, _| image::Rgba(if x == 0 { left } else { right }))
}

#[test]
fn the_extensions_textures_become_maps_in_disney_units_that_the_look_binds() {
    let dir = tempfile::tempdir().unwrap();
    let mut gltf = Gltf::new();
    for name in ["KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_specular"] {
        gltf.uses_extension(name);
    }
    let coat = gltf.texture(&halves([153, 0, 0, 255], [51, 0, 0, 255]));
    let coat_roughness = gltf.texture(&halves([0, 255, 0, 255], [0, 102, 0, 255]));
    // Sheen and specular colours are sRGB; the specular texture's weight is its alpha.
    let sheen = gltf.texture(&halves([255, 255, 255, 255], [255, 128, 0, 255]));
    let specular = gltf.texture(&halves([0, 0, 0, 255], [0, 0, 0, 64]));
    let specular_color = gltf.texture(&halves([255, 255, 255, 255], [0, 255, 0, 255]));
    let base = gltf.texture(&halves([200, 200, 200, 255], [90, 180, 250, 255]));
    gltf.json["samplers"] = json!([{ "magFilter": 9728, "minFilter": 9728 }]);
    for texture in [coat, coat_roughness, sheen, specular, specular_color, base] {
        gltf.json["textures"][texture]["sampler"] = json!(0);
    }
    let material = gltf.material(json!({
        "name": "coated",
        "pbrMetallicRoughness": { "baseColorTexture": { "index": base } },
        "extensions": {
            "KHR_materials_clearcoat": {
                "clearcoatFactor": 0.5, "clearcoatTexture": { "index": coat },
                "clearcoatRoughnessFactor": 0.5, "clearcoatRoughnessTexture": { "index": coat_roughness }
            },
            "KHR_materials_sheen": { "sheenColorFactor": [0.8, 0.4, 0.2], "sheenColorTexture": { "index": sheen } },
            "KHR_materials_specular": {
                "specularFactor": 1.0, "specularTexture": { "index": specular },
                "specularColorFactor": [1.0, 0.5, 0.5], "specularColorTexture": { "index": specular_color }
            }
        }
    }));
    let mesh = gltf.mesh("plane", &[(&plane(1.0), Some(material))]);
    gltf.node(json!({ "name": "plane", "mesh": mesh }));
    camera_looking_down_z(&mut gltf, "front", [0.0, 0.0, 1.0 / 20f32.to_radians().tan()], 40.0, 1.0);
    let path = gltf.write_gltf(dir.path(), "coated");
    let g = bake_file(&path, 32, 4);
    let maps: Vec<&str> = g.maps.keys().map(String::as_str).collect();
    assert_eq!(
        maps,
        [
            "base_color.B",
            "base_color.G",
            "base_color.R",
            "clearcoat",
            "clearcoat_gloss",
            "sheen",
            "sheen_tint",
            "specular"
        ]
    );
    let luminance = |c: [f32; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    let gloss = |r: f32| ((0.1 - r * r) / 0.099f32).clamp(0.0, 1.0);
    let srgb = |c: u8| srgb_to_linear(c);
    for (x, left) in [(8usize, true), (24, false)] {
        let at = |name: &str| g.maps[name][16 * 32 + x];
        let close = |name: &str, want: f32| {
            assert!((at(name) - want).abs() < 0.01, "{name} at x = {x}: {} vs {want}", at(name))
        };
        close("clearcoat", if left { 0.6 } else { 0.2 });
        close("clearcoat_gloss", gloss(0.5 * if left { 1.0 } else { 0.4 }));
        let sheen_colour = if left { [1.0, 1.0, 1.0] } else { [1.0, srgb(128), 0.0] };
        let factor = [0.8, 0.4, 0.2];
        let sheen = [0, 1, 2].map(|k| factor[k] * sheen_colour[k]);
        close("sheen", luminance(sheen) / luminance(factor));
        let base = if left { [srgb(200); 3] } else { [srgb(90), srgb(180), srgb(250)] };
        close("sheen_tint", lookdev::asset::materials::sheen_tint(sheen, base));
        let weight = if left { 1.0 } else { 64.0 / 255.0 };
        let colour_factor = [1.0, 0.5, 0.5];
        let colour = if left { 1.0 } else { luminance([0.0, 0.5, 0.0]) / luminance(colour_factor) };
        close("specular", weight * colour);
    }
    // The preset holds the factors (and 1 where the map holds the value itself); the look binds.
    let asset = Asset::load(&path).unwrap();
    let import = Import::new(&asset).unwrap();
    let p = import.materials[0].preset.params;
    assert_eq!((p.clearcoat, p.clearcoat_gloss, p.sheen_tint), (2.0, 1.0, 1.0));
    assert!((p.sheen - luminance([0.8, 0.4, 0.2])).abs() < 1e-6);
    let look = import.look(&dir.path().join("coated.toml"), str::to_string);
    let bound: Vec<&str> = look.objects[0].layers[0].maps.values().map(String::as_str).collect();
    assert_eq!(bound, ["base_color", "specular", "sheen", "sheen_tint", "clearcoat", "clearcoat_gloss"]);
}

#[test]
fn undecodable_textures_are_refused_naming_the_image_its_uri_and_the_extension() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("g.exr").to_string_lossy().into_owned();
    let presets = dir.path().join("presets").to_string_lossy().into_owned();
    let look = dir.path().join("look.toml").to_string_lossy().into_owned();
    // A Basis texture with no fallback: bake and import both refuse it.
    let basis = broken_asset(dir.path(), "basis", |g| {
        g.uses_extension("KHR_texture_basisu");
        g.json["extensionsRequired"] = json!(["KHR_texture_basisu"]);
        g.json["images"] = json!([{ "uri": "albedo.ktx2", "name": "albedo" }]);
        g.json["textures"] = json!([{ "extensions": { "KHR_texture_basisu": { "source": 0 } } }]);
        g.json["materials"] = json!([{ "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 } } }]);
        g.json["meshes"][0]["primitives"][0]["material"] = json!(0);
    });
    let fragments = ["basis.gltf", "texture 0", "image 0 'albedo' (albedo.ktx2)", "KTX2", "KHR_texture_basisu"];
    assert_bad_input(&lookdev(&["bake", &basis, "--out", &out, "--size", "16", "16"]), &fragments);
    assert_bad_input(&lookdev(&["import", &basis, "--presets", &presets, "--look", &look]), &fragments);
    // A KTX2 image given as the plain source is refused the same way.
    let plain = broken_asset(dir.path(), "plain", |g| {
        g.json["images"] = json!([{ "uri": "albedo.ktx2" }]);
        g.json["textures"] = json!([{ "source": 0 }]);
        g.json["materials"] = json!([{ "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 } } }]);
        g.json["meshes"][0]["primitives"][0]["material"] = json!(0);
    });
    assert_bad_input(
        &lookdev(&["bake", &plain, "--out", &out, "--size", "16", "16"]),
        &["plain.gltf", "albedo.ktx2", "KTX2"],
    );
    assert!(!Path::new(&out).exists(), "no g-buffer is written for bad input");

    // With a PNG fallback as its source, the texture bakes from that; a texture on a texcoord
    // set beyond TEXCOORD_1 is sampled with TEXCOORD_0 and reported.
    let mut gltf = Gltf::new();
    gltf.uses_extension("KHR_texture_basisu");
    let texture = gltf.texture(&halves([255, 0, 0, 255], [0, 0, 255, 255]));
    gltf.json["textures"][texture]["extensions"] = json!({ "KHR_texture_basisu": { "source": 7 } });
    let material = gltf.material(json!({
        "pbrMetallicRoughness": { "baseColorTexture": { "index": texture } },
        "emissiveTexture": { "index": texture, "texCoord": 2 },
        "emissiveFactor": [1.0, 1.0, 1.0]
    }));
    let mesh = gltf.mesh("plane", &[(&plane(1.0), Some(material))]);
    gltf.node(json!({ "name": "plane", "mesh": mesh }));
    camera_looking_down_z(&mut gltf, "front", [0.0, 0.0, 1.0 / 20f32.to_radians().tan()], 40.0, 1.0);
    let fallback = gltf.write_gltf(dir.path(), "fallback").to_string_lossy().into_owned();
    let output = lookdev(&["bake", &fallback, "--out", &out, "--size", "16", "16", "--samples", "1"]);
    assert_success(&output);
    assert!(stderr(&output).contains("emissiveTexture uses TEXCOORD_2, which is not read"), "{}", stderr(&output));
    let g = GBuffer::read(Path::new(&out)).unwrap();
    assert!(g.maps["base_color.R"][8 * 16 + 4] > 0.9 && g.maps["base_color.B"][8 * 16 + 12] > 0.9);
}

#[test]
fn the_mapping_holds_for_every_listed_extension_and_unsupported_ones_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let mut gltf = Gltf::new();
    for name in [
        "KHR_materials_ior",
        "KHR_materials_specular",
        "KHR_materials_clearcoat",
        "KHR_materials_sheen",
        "KHR_materials_anisotropy",
        "KHR_materials_emissive_strength",
        "KHR_materials_transmission",
    ] {
        gltf.uses_extension(name);
    }
    let material = gltf.material(json!({
        "name": "Lacquer.01",
        "pbrMetallicRoughness": { "baseColorFactor": [0.5, 0.25, 0.1, 1.0], "metallicFactor": 0.2, "roughnessFactor": 0.6 },
        "emissiveFactor": [1.0, 0.5, 0.25],
        "extensions": {
            "KHR_materials_emissive_strength": { "emissiveStrength": 6.0 },
            "KHR_materials_ior": { "ior": 1.8 },
            "KHR_materials_specular": { "specularFactor": 0.5, "specularColorFactor": [1.0, 1.0, 1.0] },
            "KHR_materials_clearcoat": { "clearcoatFactor": 0.5, "clearcoatRoughnessFactor": 0.2 },
            "KHR_materials_sheen": { "sheenColorFactor": [0.3, 0.3, 0.3] },
            "KHR_materials_anisotropy": { "anisotropyStrength": 0.6 },
            "KHR_materials_transmission": { "transmissionFactor": 0.5 }
        }
    }));
    let mesh = gltf.mesh("ball", &[(&uv_sphere(1.0, 16, 8), Some(material))]);
    gltf.node(json!({ "name": "ball", "mesh": mesh }));
    let path = gltf.write_gltf(dir.path(), "lacquer");

    let asset = Asset::load(&path).unwrap();
    let import = Import::new(&asset).unwrap();
    assert_eq!(import.unsupported, ["KHR_materials_transmission"]);
    let [imported] = &import.materials[..] else { panic!("one material") };
    assert_eq!((imported.used.channel.as_str(), imported.preset.name.as_str()), ("Lacquer_01", "lacquer_01"));
    let p = imported.preset.params;
    let close = |a: f32, b: f32, what: &str| assert!((a - b).abs() < 1e-4, "{what}: {a} vs {b}");
    close(p.base_color[0], 0.5, "base_color.r");
    close(p.base_color[2], 0.1, "base_color.b");
    close(p.metallic, 0.2, "metallic");
    close(p.roughness, 0.6, "roughness");
    // F0 of IOR 1.8 is (0.8/2.8)², scaled by the specular factor, over Disney's 0.08.
    close(p.specular, (0.8f32 / 2.8).powi(2) * 0.5 / 0.08, "specular");
    close(p.specular_tint, 0.0, "specular_tint");
    // A full glTF coat is Disney clearcoat 4 (its lobe has a 0.25 weight).
    close(p.clearcoat, 2.0, "clearcoat");
    // GTR1's alpha mix(0.1, 0.001, gloss) equals the coat's alpha 0.2².
    close(0.1 + (0.001 - 0.1) * p.clearcoat_gloss, 0.04, "clearcoat alpha");
    close(p.sheen, 0.3, "sheen");
    close(p.sheen_tint, 0.0, "sheen_tint");
    // Disney's alpha ratio 1/(1 − 0.9·anisotropic) equals glTF's stretch mix(α, 1, s²)/α.
    let alpha = 0.6f32 * 0.6;
    close(1.0 / (1.0 - 0.9 * p.anisotropic), (alpha + 0.36 * (1.0 - alpha)) / alpha, "anisotropy ratio");
    // Emission: emissiveFactor × KHR_materials_emissive_strength.
    assert_eq!(p.emission, [6.0, 3.0, 1.5]);
    assert!(imported.mapped.maps.is_empty(), "no textures, no maps");
    assert!(
        imported.mapped.notes.iter().any(|n| n.contains("KHR_materials_transmission")),
        "{:?}",
        imported.mapped.notes
    );

    // The CLI writes the preset and the look, and warns of the extension it ignores.
    let (presets, look) = (dir.path().join("presets"), dir.path().join("lacquer.toml"));
    let import = || {
        lookdev(&[
            "import",
            path.to_str().unwrap(),
            "--presets",
            presets.to_str().unwrap(),
            "--look",
            look.to_str().unwrap(),
        ])
    };
    let output = import();
    assert_success(&output);
    assert!(
        stderr(&output).contains("warning") && stderr(&output).contains("KHR_materials_transmission"),
        "{}",
        stderr(&output)
    );
    let written = lookdev::material::Preset::load(&presets.join("lacquer_01.toml")).unwrap();
    assert_eq!(written.params, p, "the preset file holds the mapped values");
    let look_text = std::fs::read_to_string(&look).unwrap();
    assert!(look_text.contains("preset = \"presets/lacquer_01.toml\""), "{look_text}");
    // Importing again without --force refuses, and leaves the files as they were.
    let again = import();
    assert_eq!(again.status.code(), Some(2), "{}", stderr(&again));
    assert!(stderr(&again).contains("already exists"), "{}", stderr(&again));
    assert_eq!(std::fs::read_to_string(&look).unwrap(), look_text);
}

/// What import writes for people to read carries no float noise: glTF's IOR 1.5 is F0 0.04,
/// exactly Disney's specular 0.5, and a factor of 0.3 stays 0.3.
#[test]
fn imported_presets_hold_the_values_without_float_noise() {
    let dir = tempfile::tempdir().unwrap();
    let mut gltf = Gltf::new();
    gltf.uses_extension("KHR_materials_ior");
    let material = gltf.material(json!({
        "name": "plastic",
        "pbrMetallicRoughness": { "baseColorFactor": [0.3, 0.7, 0.1, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.3 },
        "extensions": { "KHR_materials_ior": { "ior": 1.5 } }
    }));
    let mesh = gltf.mesh("ball", &[(&uv_sphere(1.0, 16, 8), Some(material))]);
    gltf.node(json!({ "name": "ball", "mesh": mesh }));
    let path = gltf.write_gltf(dir.path(), "plastic");
    let (presets, look) = (dir.path().join("presets"), dir.path().join("plastic.toml"));
    assert_success(&lookdev(&[
        "import",
        path.to_str().unwrap(),
        "--presets",
        presets.to_str().unwrap(),
        "--look",
        look.to_str().unwrap(),
    ]));
    let text = std::fs::read_to_string(presets.join("plastic.toml")).unwrap();
    for line in ["specular = 0.5\n", "roughness = 0.3\n", "base_color = [0.3, 0.7, 0.1]\n"] {
        assert!(text.contains(line), "no '{}' in:\n{text}", line.trim());
    }
}

/// `import --gbuffer` records the bake in the look, relative to it: the look renders on its own,
/// from any folder, at the bake's size.
#[test]
fn an_imported_look_names_its_bake_and_renders_from_anywhere() {
    let dir = tempfile::tempdir().unwrap();
    let arg = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let mut gltf = Gltf::new();
    let red =
        gltf.material(json!({ "name": "red", "pbrMetallicRoughness": { "baseColorFactor": [0.8, 0.1, 0.1, 1.0] } }));
    let mesh = gltf.mesh("ball", &[(&uv_sphere(1.0, 16, 8), Some(red))]);
    gltf.node(json!({ "name": "ball", "mesh": mesh }));
    camera_looking_down_z(&mut gltf, "front", [0.0, 0.0, 5.5], 30.0, 1.0);
    let model = gltf.write_glb(dir.path(), "ball");
    std::fs::create_dir_all(dir.path().join("bakes")).unwrap();
    std::fs::create_dir_all(dir.path().join("looks/shot")).unwrap();
    let model = model.to_str().unwrap();
    assert_success(&lookdev(&["bake", model, "--out", &arg("bakes/ball.exr"), "--size", "48", "40"]));
    let look = arg("looks/shot/ball.toml");
    let imported =
        lookdev(&["import", model, "--presets", &arg("presets"), "--look", &look, "--gbuffer", &arg("bakes/ball.exr")]);
    assert_success(&imported);
    let text = std::fs::read_to_string(&look).unwrap();
    assert!(text.contains("[gbuffer]\nfile = \"../../bakes/ball.exr\"\n"), "{text}");
    let out = arg("ball.png");
    let rendered = std::process::Command::new(env!("CARGO_BIN_EXE_lookdev"))
        .args(["render", "--look", &look, "--spp", "2", "--quiet", "--out", &out])
        .current_dir(std::env::temp_dir())
        .output()
        .unwrap();
    assert_success(&rendered);
    assert_eq!(image::image_dimensions(&out).unwrap(), (48, 40));
}

fn read_exr(path: &Path) -> Vec<[f32; 4]> {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |resolution, _| (resolution.width(), vec![[0.0; 4]; resolution.area()]),
        |(w, pixels), position, (r, g, b, a): (f32, f32, f32, f32)| {
            pixels[position.y() * *w + position.x()] = [r, g, b, a]
        },
    )
    .unwrap();
    image.layer_data.channel_data.pixels.1
}

#[test]
fn baking_and_rendering_a_gltf_sphere_matches_the_built_in_analytic_sphere() {
    let dir = tempfile::tempdir().unwrap();
    let arg = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    // The built-in ball: a unit sphere at the origin, seen from (0, 0, 5.5) with a 30° field of view.
    let mut gltf = Gltf::new();
    let material = gltf.material(json!({
        "name": "terracotta",
        "pbrMetallicRoughness": { "baseColorFactor": [0.8, 0.3, 0.1, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.4 },
        "extensions": { "KHR_materials_clearcoat": { "clearcoatFactor": 0.25, "clearcoatRoughnessFactor": 0.1 } }
    }));
    gltf.uses_extension("KHR_materials_clearcoat");
    let mesh = gltf.mesh("sphere", &[(&uv_sphere(1.0, 128, 64), Some(material))]);
    gltf.node(json!({ "name": "ball", "mesh": mesh }));
    camera_looking_down_z(&mut gltf, "front", [0.0, 0.0, 5.5], 30.0, 1.0);
    let model = gltf.write_glb(dir.path(), "ball");
    let model = model.to_str().unwrap();

    let size = "96";
    assert_success(&lookdev(&[
        "bake",
        model,
        "--out",
        &arg("baked.exr"),
        "--size",
        size,
        size,
        "--samples",
        "16",
        "--quiet",
    ]));
    assert_success(&lookdev(&["import", model, "--presets", &arg("presets"), "--look", &arg("ball.toml")]));
    assert_success(&lookdev(&[
        "gbuffer",
        "--builtin",
        "shaderball",
        "--size",
        size,
        size,
        "--out",
        &arg("analytic.exr"),
    ]));
    std::fs::write(
        dir.path().join("analytic.toml"),
        "[[object]]\n[[object.layer]]\npreset = \"presets/terracotta.toml\"\n",
    )
    .unwrap();
    let render = |gbuffer: &str, look: &str, out: &str, flags: &[&str]| {
        let (gbuffer_path, look_path, out_path) = (arg(gbuffer), arg(look), arg(out));
        let mut args = vec![
            "render",
            "--gbuffer",
            &gbuffer_path,
            "--look",
            &look_path,
            "--spp",
            "64",
            "--seed",
            "3",
            "--no-background",
            "--out",
            &out_path,
            "--quiet",
        ];
        args.extend(flags);
        assert_success(&lookdev(&args));
        read_exr(&dir.path().join(out))
    };
    // The baked ball, alone, keeps its traced visibility (a convex ball shadows nothing of
    // itself); the built-in's pedestal, which the asset lacks, must not shade the reference.
    let baked = render("baked.exr", "ball.toml", "baked-render.exr", &[]);
    let analytic = render("analytic.exr", "analytic.toml", "analytic-render.exr", &["--no-visibility"]);

    let analytic_gbuffer = GBuffer::read(&dir.path().join("analytic.exr")).unwrap();
    let baked_gbuffer = GBuffer::read(&dir.path().join("baked.exr")).unwrap();
    let (mut sum_baked, mut sum_analytic, mut sum_difference, mut count) = (0.0f64, 0.0f64, 0.0f64, 0);
    for p in 0..baked.len() {
        let on_ball = analytic_gbuffer.object_id[p] == lookdev::gbuffer::BALL_ID && analytic_gbuffer.coverage[p] == 1.0;
        if !on_ball || baked_gbuffer.coverage[p] < 1.0 {
            continue;
        }
        let luminance = |c: [f32; 4]| (0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]) as f64;
        sum_baked += luminance(baked[p]);
        sum_analytic += luminance(analytic[p]);
        sum_difference += (luminance(baked[p]) - luminance(analytic[p])).abs();
        count += 1;
    }
    assert!(count > 2000, "{count} ball pixels");
    let mean_difference = sum_difference / sum_analytic;
    let bias = (sum_baked - sum_analytic) / sum_analytic;
    assert!(bias.abs() < 0.01, "the baked ball is {:.2}% brighter", bias * 100.0);
    assert!(mean_difference < 0.03, "per-pixel difference {:.2}%", mean_difference * 100.0);
}

/// A one-sphere asset, changed by `edit` before it is written as `<name>.gltf`.
fn broken_asset(dir: &Path, name: &str, edit: impl FnOnce(&mut Gltf)) -> String {
    let mut gltf = Gltf::new();
    let mesh = gltf.mesh("sphere", &[(&uv_sphere(1.0, 8, 4), None)]);
    gltf.node(json!({ "name": "ball", "mesh": mesh }));
    edit(&mut gltf);
    gltf.write_gltf(dir, name).to_string_lossy().into_owned()
}

#[test]
fn bad_assets_are_refused_with_the_file_and_the_problem_named() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("g.exr").to_string_lossy().into_owned();
    let bake = |model: &str, extra: &[&str]| {
        let mut args = vec!["bake", model, "--out", &out, "--size", "16", "16", "--samples", "1"];
        args.extend_from_slice(extra);
        lookdev(&args)
    };
    let missing_buffer = broken_asset(dir.path(), "no-bin", |_| {});
    std::fs::remove_file(dir.path().join("no-bin.bin")).unwrap();
    assert_bad_input(&bake(&missing_buffer, &[]), &["no-bin.gltf", "buffer 0", "no-bin.bin"]);

    let missing_image = broken_asset(dir.path(), "no-image", |g| {
        g.json["images"] = json!([{ "uri": "albedo.png" }]);
        g.json["textures"] = json!([{ "source": 0 }]);
        g.json["materials"] = json!([{ "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 } } }]);
        g.json["meshes"][0]["primitives"][0]["material"] = json!(0);
    });
    assert_bad_input(&bake(&missing_image, &[]), &["no-image.gltf", "image 0", "albedo.png"]);

    let lines = broken_asset(dir.path(), "lines", |g| g.json["meshes"][0]["primitives"][0]["mode"] = json!(1));
    assert_bad_input(&bake(&lines, &[]), &["lines.gltf", "LINES", "only triangles"]);

    let empty = broken_asset(dir.path(), "empty", |g| {
        g.json["nodes"] = json!([{ "name": "nothing" }]);
    });
    assert_bad_input(&bake(&empty, &[]), &["empty.gltf", "no meshes"]);

    let wide = broken_asset(dir.path(), "wide", |g| {
        camera_looking_down_z(g, "fisheye", [0.0, 0.0, 5.0], 200.0, 1.0);
    });
    assert_bad_input(&bake(&wide, &[]), &["wide.gltf", "fisheye", "yfov"]);
    assert_bad_input(&bake(&wide, &["--camera", "nope"]), &["wide.gltf", "no camera named 'nope'", "fisheye"]);
    assert_bad_input(&bake(&wide, &["--auto-camera", "--fov", "180"]), &["--fov 180"]);

    for (extension, what) in [("KHR_draco_mesh_compression", "Draco"), ("EXT_meshopt_compression", "meshopt")] {
        let compressed = broken_asset(dir.path(), "compressed", |g| {
            g.json["extensionsUsed"] = json!([extension]);
            g.json["extensionsRequired"] = json!([extension]);
        });
        assert_bad_input(&bake(&compressed, &[]), &["compressed.gltf", what, "not supported"]);
        let import = lookdev(&["import", &compressed, "--presets", &out, "--look", &out]);
        assert_bad_input(&import, &["compressed.gltf", what]);
    }

    std::fs::write(dir.path().join("text.gltf"), "{ not json").unwrap();
    let text = dir.path().join("text.gltf").to_string_lossy().into_owned();
    assert_bad_input(&bake(&text, &[]), &["text.gltf", "not a readable glTF file"]);
    let absent = dir.path().join("absent.glb").to_string_lossy().into_owned();
    assert_bad_input(&bake(&absent, &[]), &["absent.glb", "file not found"]);
    assert!(!Path::new(&out).exists(), "no g-buffer is written for bad input");
}

#[test]
fn alpha_masked_materials_cut_out_what_is_below_the_cutoff() {
    let dir = tempfile::tempdir().unwrap();
    // (factor alpha, cutoff, texture alpha left and right): what is drawn on the left and the
    // right. A zero cutoff keeps everything, even at alpha 0.
    for (factor, cutoff, expect_left, expect_right) in
        [(1.0, 0.5, false, true), (0.4, 0.5, false, false), (0.0, 0.0, true, true)]
    {
        let mut gltf = Gltf::new();
        let texture = gltf.texture(&image::RgbaImage::from_fn(2, 1, |x, _| {
            image::Rgba([200, 200, 200, if x == 0 { 0 } else { 255 }])
        }));
        // Behind the leaf, a green board: where the leaf is cut out, the maps show the board.
        let green = gltf.texture(&image::RgbaImage::from_pixel(1, 1, image::Rgba([0, 255, 0, 255])));
        gltf.json["samplers"] = json!([{ "magFilter": 9728, "minFilter": 9728 }]);
        gltf.json["textures"][texture]["sampler"] = json!(0);
        let material = gltf.material(json!({
            "name": "leaf",
            "alphaMode": "MASK",
            "alphaCutoff": cutoff,
            "pbrMetallicRoughness": { "baseColorFactor": [1.0, 1.0, 1.0, factor], "baseColorTexture": { "index": texture } }
        }));
        let board = gltf
            .material(json!({ "name": "board", "pbrMetallicRoughness": { "baseColorTexture": { "index": green } } }));
        let leaf = gltf.mesh("plane", &[(&plane(1.0), Some(material))]);
        gltf.node(json!({ "name": "plane", "mesh": leaf }));
        let behind = gltf.mesh("board", &[(&plane(2.0), Some(board))]);
        gltf.node(json!({ "name": "board", "mesh": behind, "translation": [0.0, 0.0, -0.5] }));
        camera_looking_down_z(&mut gltf, "front", [0.0, 0.0, 1.0 / 20f32.to_radians().tan()], 40.0, 1.0);
        let g = bake_file(&gltf.write_gltf(dir.path(), &format!("leaf-{factor}")), 32, 1);
        let drawn = |x: usize| g.masks["leaf"][16 * 32 + x] == 1.0;
        assert_eq!((drawn(8), drawn(24)), (expect_left, expect_right), "factor alpha {factor}, cutoff {cutoff}");
        for x in [8, 24] {
            let (red, green) = (g.maps["base_color.R"][16 * 32 + x], g.maps["base_color.G"][16 * 32 + x]);
            let want = if drawn(x) { (srgb_to_linear(200), srgb_to_linear(200)) } else { (0.0, 1.0) };
            assert!((red - want.0).abs() < 3e-3 && (green - want.1).abs() < 3e-3, "x = {x}: map ({red}, {green})");
        }
    }
}

#[test]
fn textures_smaller_than_their_pixels_are_read_from_mip_levels_in_linear_light() {
    let dir = tempfile::tempdir().unwrap();
    let mut gltf = Gltf::new();
    // A checker of single black and white texels, 256² on a 32² image: eight texels a pixel.
    // Its mean light is ½, sRGB 188, where averaging the encoded values would give 128's ≈ 0.22.
    let checker = gltf.texture(&image::RgbaImage::from_fn(256, 256, |x, y| {
        image::Rgba(if (x + y) % 2 == 0 { [0, 0, 0, 255] } else { [255; 4] })
    }));
    let material = gltf
        .material(json!({ "name": "checker", "pbrMetallicRoughness": { "baseColorTexture": { "index": checker } } }));
    let mesh = gltf.mesh("plane", &[(&plane(1.0), Some(material))]);
    gltf.node(json!({ "name": "plane", "mesh": mesh }));
    camera_looking_down_z(&mut gltf, "front", [0.0, 0.0, 1.0 / 20f32.to_radians().tan()], 40.0, 1.0);
    let g = bake_file(&gltf.write_gltf(dir.path(), "checker"), 32, 16);
    let mut worst = 0.0f32;
    for y in 2..30 {
        for x in 2..30 {
            worst = worst.max((g.maps["base_color.R"][y * 32 + x] - 0.5).abs());
        }
    }
    assert!(worst < 0.02, "a pixel's base colour is {worst} from the checker's mean light");
}

#[test]
fn where_three_materials_meet_each_takes_its_share_of_the_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let mut gltf = Gltf::new();
    let red = gltf.texture(&image::RgbaImage::from_pixel(1, 1, image::Rgba([255, 0, 0, 255])));
    let textured =
        gltf.material(json!({ "name": "a", "pbrMetallicRoughness": { "baseColorTexture": { "index": red } } }));
    let green =
        gltf.material(json!({ "name": "b", "pbrMetallicRoughness": { "baseColorFactor": [0.0, 1.0, 0.0, 1.0] } }));
    let blue =
        gltf.material(json!({ "name": "c", "pbrMetallicRoughness": { "baseColorFactor": [0.0, 0.0, 1.0, 1.0] } }));
    // Three strips side by side, their seams at x = ±¼: half-way across pixels 13 and 22 of 36.
    let strip = |from: f32, to: f32| {
        let mut mesh = plane(1.0);
        for p in &mut mesh.positions {
            p[0] = if p[0] < 0.0 { from } else { to };
        }
        mesh
    };
    let (a, b, c) = (strip(-1.0, -0.25), strip(-0.25, 0.25), strip(0.25, 1.0));
    let mesh = gltf.mesh("strips", &[(&a, Some(textured)), (&b, Some(green)), (&c, Some(blue))]);
    gltf.node(json!({ "name": "strips", "mesh": mesh }));
    camera_looking_down_z(&mut gltf, "front", [0.0, 0.0, 1.0 / 20f32.to_radians().tan()], 40.0, 1.0);
    let path = gltf.write_gltf(dir.path(), "strips");
    let g = bake_file(&path, 36, 16);
    let import = Import::new(&Asset::load(&path).unwrap()).unwrap();
    let look = import.look(&dir.path().join("strips.toml"), str::to_string);
    let stacks = lookdev::material::stack::PackedStacks::pack(
        &look,
        lookdev::render::scene::covered_object_ids(&g),
        &g,
        Path::new("strips.exr"),
    )
    .unwrap();
    for (x, want) in [
        (5, [1.0, 0.0, 0.0]),
        (13, [0.5, 0.5, 0.0]),
        (18, [0.0, 1.0, 0.0]),
        (22, [0.0, 0.5, 0.5]),
        (30, [0.0, 0.0, 1.0]),
    ] {
        let base = stacks.resolve_gbuffer_pixel(&g, 18 * 36 + x).base_color;
        assert!(base.iter().zip(want).all(|(b, w)| (b - w).abs() < 2e-3), "x = {x}: {base:?}, want {want:?}");
    }
}

#[test]
fn a_material_the_scene_draws_without_vertex_colours_binds_no_base_colour_map() {
    let dir = tempfile::tempdir().unwrap();
    let mut gltf = Gltf::new();
    let plain =
        gltf.material(json!({ "name": "plain", "pbrMetallicRoughness": { "baseColorFactor": [0.5, 0.5, 0.5, 1.0] } }));
    let drawn = gltf.mesh("drawn", &[(&plane(1.0), Some(plain))]);
    gltf.node(json!({ "name": "drawn", "mesh": drawn }));
    // A mesh with vertex colours in the same material, which no node of the scene places.
    let mut coloured = plane(1.0);
    coloured.colors = Some(vec![[1.0, 0.0, 0.0, 1.0]; 4]);
    gltf.mesh("unplaced", &[(&coloured, Some(plain))]);
    camera_looking_down_z(&mut gltf, "front", [0.0, 0.0, 1.0 / 20f32.to_radians().tan()], 40.0, 1.0);
    let path = gltf.write_gltf(dir.path(), "unplaced");
    let g = bake_file(&path, 16, 1);
    assert!(g.maps.is_empty(), "{:?}", g.maps.keys());
    let import = Import::new(&Asset::load(&path).unwrap()).unwrap();
    assert!(import.materials[0].mapped.maps.is_empty(), "the import binds what the bake writes");
}

#[test]
fn shading_normals_that_a_normal_map_turns_away_from_the_eye_are_bent_back() {
    let dir = tempfile::tempdir().unwrap();
    let (image, _) = quadrant_normal_map();
    let mut gltf = Gltf::new();
    let texture = gltf.texture(&image);
    let material = gltf.material(json!({ "name": "bumpy", "normalTexture": { "index": texture } }));
    let mesh = gltf.mesh("plane", &[(&plane(1.0), Some(material))]);
    gltf.node(json!({ "name": "plane", "mesh": mesh }));
    let path = gltf.write_gltf(dir.path(), "grazing");
    // Seen from 80° off the plane's normal, from below: the quadrants tilted down face away.
    let ctx = common::gpu::graphics_context();
    let asset = Asset::load(&path).unwrap();
    let camera = CameraChoice::Frame { yaw_degrees: 0.0, pitch_degrees: -80.0, fov_degrees: 30.0 };
    let g =
        bake(&ctx, &asset, &BakeOptions { width: 48, height: 48, samples: 4, camera, visibility: None }, |_, _, _| {})
            .unwrap();
    common::gpu::finish(ctx);
    let covered: Vec<usize> = (0..g.coverage.len()).filter(|&p| g.coverage[p] > 0.0).collect();
    assert!(covered.len() > 100, "{} covered pixels", covered.len());
    for p in covered {
        let (n, v) = (Vec3::from(g.normal[p]), Vec3::from(g.view[p]));
        assert!(n.dot(v) > 0.0, "pixel {p}: N·V = {}", n.dot(v));
    }
}

#[test]
fn the_named_camera_an_orthographic_camera_and_framing_each_look_where_they_should() {
    let dir = tempfile::tempdir().unwrap();
    let mut gltf = Gltf::new();
    let mesh = gltf.mesh("sphere", &[(&uv_sphere(1.0, 32, 16), None)]);
    gltf.node(json!({ "name": "ball", "mesh": mesh }));
    camera_looking_down_z(&mut gltf, "front", [0.0, 0.0, 6.0], 30.0, 1.0);
    // From +X, looking down −X: the camera's −Z turned 90° about +Y.
    let side = gltf.camera(json!({ "name": "side-lens", "type": "orthographic",
        "orthographic": { "xmag": 1.5, "ymag": 1.5, "znear": 0.1, "zfar": 20.0 } }));
    let turn = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
    gltf.node(json!({ "name": "side", "camera": side, "translation": [6.0, 0.0, 0.0], "rotation": turn.to_array() }));
    let path = gltf.write_gltf(dir.path(), "cameras");
    let asset = Asset::load(&path).unwrap();
    let ctx = common::gpu::graphics_context();
    let size = 33;
    let centre = (size / 2 * size + size / 2) as usize;
    let bake_with = |camera: CameraChoice| {
        bake(
            &ctx,
            &asset,
            &BakeOptions { width: size, height: size, samples: 1, camera, visibility: None },
            |_, _, _| {},
        )
        .unwrap()
    };
    // The scene's first camera by default, and the same by name.
    for choice in [CameraChoice::Default, CameraChoice::Named("front".into())] {
        let g = bake_with(choice);
        assert!(angle_degrees(Vec3::from(g.view[centre]), Vec3::Z) < 0.5);
        assert!(angle_degrees(Vec3::from(g.normal[centre]), Vec3::Z) < 2.0);
    }
    // The orthographic camera by its camera's name: every view vector is +X, and the sphere of
    // radius 1 fills 2/3 of a frame 3 units high.
    let g = bake_with(CameraChoice::Named("side-lens".into()));
    let covered: Vec<usize> = (0..g.coverage.len()).filter(|&p| g.coverage[p] == 1.0).collect();
    assert!(covered.iter().all(|&p| angle_degrees(Vec3::from(g.view[p]), Vec3::X) < 0.01));
    let expected = std::f32::consts::PI * (size as f32 / 3.0).powi(2);
    assert!(
        (covered.len() as f32 - expected).abs() < 0.1 * expected,
        "{} covered pixels, about {expected} expected",
        covered.len()
    );
    // Framing from yaw 90° looks from +X; from pitch 60° down onto the top.
    for (yaw, pitch, toward) in [(90.0, 0.0, Vec3::X), (0.0, 60.0, Vec3::new(0.0, 60f32.to_radians().sin(), 0.5))] {
        let g = bake_with(CameraChoice::Frame { yaw_degrees: yaw, pitch_degrees: pitch, fov_degrees: 30.0 });
        assert!(angle_degrees(Vec3::from(g.view[centre]), toward) < 0.5, "yaw {yaw}, pitch {pitch}");
        // The sphere touches the frame's edges: the middle row is covered from edge to edge.
        let row = size as usize / 2;
        assert!(g.coverage[row * size as usize + 1] > 0.0 && g.coverage[row * size as usize + size as usize - 2] > 0.0);
    }
    common::gpu::finish(ctx);
}
