//! Directional visibility (docs/formats.md#visibility): traced masks against closed forms, the
//! relight kernel's use of them against the masks' own integrals, and the g-buffer's channels.

mod common;

use glam::Vec3;
use lookdev::environment::Environment;
use lookdev::gbuffer::GBuffer;
use lookdev::render::Lighting;
use lookdev::shading::model::{Diffuse, Fresnel, Model};
use lookdev::visibility::{self, Grid, Mesh, Quadrature, SurfacePoint};
use std::f32::consts::PI;

/// A UV sphere of `segments` × `rings` quads (two triangles each), counter-clockwise outside.
fn sphere(centre: Vec3, radius: f32, segments: u32, rings: u32) -> Vec<[Vec3; 3]> {
    let point = |s: u32, r: u32| {
        let (phi, theta) = (2.0 * PI * s as f32 / segments as f32, PI * r as f32 / rings as f32);
        centre + radius * Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
    };
    let mut triangles = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let (a, b, c, d) = (point(s, r), point(s + 1, r), point(s + 1, r + 1), point(s, r + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    triangles
}

/// A square of the plane y = 0, `half` to each side, facing +Y.
fn ground(half: f32) -> Vec<[Vec3; 3]> {
    let corner = |x: f32, z: f32| Vec3::new(x * half, 0.0, z * half);
    vec![
        [corner(-1.0, -1.0), corner(-1.0, 1.0), corner(1.0, 1.0)],
        [corner(-1.0, -1.0), corner(1.0, 1.0), corner(1.0, -1.0)],
    ]
}

/// The unit sphere resting on the ground at the origin.
fn sphere_on_ground() -> Mesh {
    let mut triangles = sphere(Vec3::Y, 1.0, 192, 96);
    triangles.extend(ground(50.0));
    Mesh::new(triangles)
}

/// The unoccluded share of a ground point's hemisphere at `distance` from where a unit sphere
/// touches the ground: the sphere, tangent to the horizon, covers a cap whose cosine-weighted
/// share is (R/D)³.
fn ground_occlusion(distance: f32) -> f32 {
    1.0 - (1.0 / (distance * distance + 1.0).sqrt()).powi(3)
}

/// Ground points at these distances from the contact point, each at several azimuths.
fn ground_points() -> Vec<(f32, SurfacePoint)> {
    let mut points = Vec::new();
    for distance in [0.1, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0] {
        for k in 0..7 {
            let azimuth = 0.3 + k as f32 * 0.83;
            let position = Vec3::new(distance * azimuth.cos(), 0.0, distance * azimuth.sin());
            points.push((distance, SurfacePoint { position, geometric: Vec3::Y, shading: Vec3::Y }));
        }
    }
    points
}

/// The largest error of the traced masks' occlusion over `points`, against `exact`.
fn worst_error(grid: Grid, mesh: &Mesh, points: &[(f32, SurfacePoint)], exact: impl Fn(f32) -> f32) -> f32 {
    let surfaces: Vec<Option<SurfacePoint>> = points.iter().map(|&(_, p)| Some(p)).collect();
    let traced = visibility::trace(grid, &surfaces, mesh, 1e-4);
    let quadrature = Quadrature::new(grid);
    points
        .iter()
        .enumerate()
        .map(|(i, (key, point))| (quadrature.occlusion(traced.pixel(i), point.shading) - exact(*key)).abs())
        .fold(0.0, f32::max)
}

#[test]
fn a_sphere_on_the_ground_occludes_it_as_the_closed_form_says() {
    let mesh = sphere_on_ground();
    let points = ground_points();
    let mut errors = Vec::new();
    for side in visibility::SIDES {
        let grid = Grid::new(side).unwrap();
        let error = worst_error(grid, &mesh, &points, ground_occlusion);
        eprintln!("sphere on the ground, {} directions: worst occlusion error {error:.4}", grid.cells());
        errors.push(error);
    }
    // From 256 directions (side 16) on, every point is within 1% of the closed form; the
    // default 1024 within 0.5%.
    assert!(errors[1] < 0.01 && errors[2] < 0.005 && errors[3] < 0.005, "{errors:?}");
    assert!(errors[0] < 0.05, "{errors:?}");
}

#[test]
fn a_hemispherical_cavity_sees_half_its_sky_everywhere() {
    // The inside of the lower half of a unit sphere, open to the sky. From any point of a sphere's
    // inner surface, the share of it in a region is the region's share of the sphere's area, so
    // the opening (standing for the missing upper half) is seen at exactly 1/2.
    let bowl: Vec<[Vec3; 3]> =
        sphere(Vec3::ZERO, 1.0, 192, 96).into_iter().filter(|t| t.iter().all(|v| v.y <= 1e-6)).collect();
    let mesh = Mesh::new(bowl);
    let mut points = Vec::new();
    for polar in [100.0f32, 120.0, 140.0, 160.0, 175.0] {
        for k in 0..5 {
            let (theta, phi) = (polar.to_radians(), 0.2 + k as f32 * 1.2);
            // A point just inside the tessellated surface, whose normal faces the centre.
            let outward = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            let position = outward * 0.999;
            points.push((0.0, SurfacePoint { position, geometric: -outward, shading: -outward }));
        }
    }
    for (side, tolerance) in [(16, 0.01), (32, 0.005)] {
        let grid = Grid::new(side).unwrap();
        let error = worst_error(grid, &mesh, &points, |_| 0.5);
        eprintln!("hemispherical cavity, {} directions: worst occlusion error {error:.4}", grid.cells());
        assert!(error < tolerance, "{} directions: {error}", grid.cells());
    }
}

#[test]
fn visibility_is_the_same_bits_on_every_run() {
    let mesh = sphere_on_ground();
    let surfaces: Vec<Option<SurfacePoint>> = ground_points().into_iter().map(|(_, p)| Some(p)).collect();
    let grid = Grid::new(16).unwrap();
    let first = visibility::trace(grid, &surfaces, &mesh, 1e-4);
    assert_eq!(first, visibility::trace(grid, &surfaces, &mesh, 1e-4));
    // From 4 away, the sphere's centre is blocked and straight up is open.
    let far = surfaces.len() - 1;
    assert!(first.seen(far, Vec3::Y));
    assert!(!first.seen(far, (Vec3::Y - surfaces[far].unwrap().position).normalize()));
}

/// An orthographic view straight down at the ground around the sphere, `size` pixels a side over
/// [−3, 3]², every pixel covered, with its visibility traced on `grid`.
fn ground_gbuffer(size: u32, grid: Grid) -> GBuffer {
    let mut g = lookdev::lab::furnace::sphere(size);
    let pixels = (size * size) as usize;
    g.normal = vec![[0.0, 1.0, 0.0]; pixels];
    g.view = vec![[0.0, 1.0, 0.0]; pixels];
    g.tangent = vec![[1.0, 0.0, 0.0]; pixels];
    g.coverage = vec![1.0; pixels];
    g.object_id = vec![1; pixels];
    let surfaces: Vec<Option<SurfacePoint>> = (0..pixels)
        .map(|p| {
            let (x, y) = ((p as u32 % size) as f32 + 0.5, (p as u32 / size) as f32 + 0.5);
            let position = Vec3::new(x / size as f32 * 6.0 - 3.0, 0.0, y / size as f32 * 6.0 - 3.0);
            Some(SurfacePoint { position, geometric: Vec3::Y, shading: Vec3::Y })
        })
        .collect();
    g.visibility = Some(visibility::trace(grid, &surfaces, &sphere_on_ground(), 1e-4));
    g
}

/// A renderer of `g` in Lambert diffuse with no specular at all (the exact dielectric Fresnel of
/// specular 0 is 0), white, with the background off and the environment turned `rotation`
/// degrees: under a white sky, a pixel's radiance is its occlusion. Every object catches
/// shadows when `catcher` is set.
fn lambert_white(
    ctx: &lookdev::gpu::Context,
    g: &GBuffer,
    env: &Environment,
    rotation: f32,
    catcher: bool,
) -> lookdev::render::Renderer {
    let model = Model { diffuse: Diffuse::Lambert, fresnel: Fresnel::Dielectric, ..Model::default() };
    let look = common::scenes::look(&format!(
        "[[object]]\nshadow_catcher = {catcher}\n[[object.layer]]\n[object.layer.set]\n\
         base_color = [1.0, 1.0, 1.0]\nspecular = 0.0\nroughness = 1.0\n"
    ));
    let ids = lookdev::render::scene::covered_object_ids(g);
    let stacks = lookdev::material::stack::PackedStacks::pack(&look, ids, g, std::path::Path::new("ground")).unwrap();
    let mut renderer = lookdev::render::Renderer::with_model(ctx, g, env, &model).unwrap();
    renderer.set_stacks(&stacks).unwrap();
    renderer.set_lighting(Lighting { background: false, rotation_degrees: rotation, ..Lighting::default() });
    renderer
}

#[test]
fn under_a_white_sky_the_ground_renders_its_stored_occlusion() {
    let ctx = common::gpu::context();
    let size = 48;
    let grid = Grid::new(32).unwrap();
    let g = ground_gbuffer(size, grid);
    let env = Environment::uniform([1.0; 3], 64, 32);
    let mut renderer = lambert_white(&ctx, &g, &env, 0.0, false);
    let spp = 512;
    renderer.render_samples(spp).unwrap();
    let radiance = renderer.read_radiance().unwrap();
    let stored = visibility::occlusion(&g);

    // Unbiased with respect to the stored visibility: the mean over the image, and over rings
    // about the contact point, agree with the masks' own integral to within the noise.
    let mean = |values: &mut dyn Iterator<Item = f32>| {
        let (sum, n) = values.fold((0.0f64, 0usize), |(s, n), v| (s + v as f64, n + 1));
        (sum / n as f64) as f32
    };
    let rendered: Vec<f32> = radiance.iter().map(|p| p[1]).collect();
    let (image, expected) = (mean(&mut rendered.iter().copied()), mean(&mut stored.iter().copied()));
    assert!((image - expected).abs() < 0.004, "image mean {image} against the stored occlusion's {expected}");

    // Against the closed form, ring by ring (distances from the contact point).
    let distance = |p: usize| {
        let (x, y) = ((p as u32 % size) as f32 + 0.5, (p as u32 / size) as f32 + 0.5);
        Vec3::new(x / size as f32 * 6.0 - 3.0, 0.0, y / size as f32 * 6.0 - 3.0).length()
    };
    for (inner, outer) in [(0.3, 0.7), (0.7, 1.2), (1.2, 2.0), (2.0, 3.0)] {
        let ring: Vec<usize> = (0..rendered.len()).filter(|&p| (inner..outer).contains(&distance(p))).collect();
        let got = mean(&mut ring.iter().map(|&p| rendered[p]));
        let exact = mean(&mut ring.iter().map(|&p| ground_occlusion(distance(p))));
        eprintln!("ring {inner}-{outer} ({} px): rendered {got:.4}, closed form {exact:.4}", ring.len());
        assert!((got - exact).abs() < 0.01, "ring {inner}-{outer}: rendered {got}, closed form {exact}");
    }

    // Without the visibility the same ground is lit by the whole sky.
    let mut open = g.clone();
    open.visibility = None;
    let mut renderer = lambert_white(&ctx, &open, &env, 0.0, false);
    renderer.render_samples(64).unwrap();
    let unoccluded = mean(&mut renderer.read_radiance().unwrap().iter().map(|p| p[1]));
    assert!((unoccluded - 1.0).abs() < 0.01, "{unoccluded}");
    drop(renderer);
    common::gpu::finish(ctx);
}

/// The ground as a shadow catcher under a white sky: its `shadow` share is its stored occlusion
/// (a white Lambert ground sees all its light unshadowed), ring by ring against the closed
/// form; over the background (white) it shows that share, and without it a black shadow whose
/// alpha is 1 minus it.
#[test]
fn a_shadow_catcher_under_a_white_sky_is_darkened_by_its_occlusion() {
    let ctx = common::gpu::context();
    let size = 48;
    let g = ground_gbuffer(size, Grid::new(32).unwrap());
    let env = Environment::uniform([1.0; 3], 64, 32);
    let mut renderer = lambert_white(&ctx, &g, &env, 0.0, true);
    assert!(renderer.has_shadow_catcher());
    renderer.set_lighting(Lighting::default());
    let spp = 512;
    renderer.render_samples(spp).unwrap();
    let share: Vec<f32> = renderer.read_shadow().unwrap().iter().map(|s| s[1]).collect();
    let shown: Vec<f32> = renderer.read_radiance().unwrap().iter().map(|p| p[1]).collect();
    for (s, p) in share.iter().zip(&shown) {
        assert!((s - p).abs() < 1e-5, "over a white background the catcher shows its share: {p} against {s}");
    }
    let distance = |p: usize| {
        let (x, y) = ((p as u32 % size) as f32 + 0.5, (p as u32 / size) as f32 + 0.5);
        Vec3::new(x / size as f32 * 6.0 - 3.0, 0.0, y / size as f32 * 6.0 - 3.0).length()
    };
    let mean =
        |pixels: &[usize], f: &dyn Fn(usize) -> f32| pixels.iter().map(|&p| f(p)).sum::<f32>() / pixels.len() as f32;
    for (inner, outer) in [(0.3, 0.7), (0.7, 1.2), (1.2, 2.0), (2.0, 3.0)] {
        let ring: Vec<usize> = (0..share.len()).filter(|&p| (inner..outer).contains(&distance(p))).collect();
        let got = mean(&ring, &|p| share[p]);
        let exact = mean(&ring, &|p| ground_occlusion(distance(p)));
        eprintln!("ring {inner}-{outer} ({} px): shadow share {got:.4}, closed form {exact:.4}", ring.len());
        assert!((got - exact).abs() < 0.01, "ring {inner}-{outer}: shadow share {got}, closed form {exact}");
    }

    // Without the background: black, with 1 minus the share as alpha.
    renderer.set_lighting(Lighting { background: false, ..Lighting::default() });
    renderer.render_samples(spp).unwrap();
    let share = renderer.read_shadow().unwrap();
    for (s, p) in share.iter().zip(renderer.read_radiance().unwrap()) {
        assert_eq!(&p[..3], &[0.0; 3]);
        assert!((p[3] - (1.0 - (s[0] + s[1] + s[2]) / 3.0)).abs() < 1e-5, "alpha {} against share {s:?}", p[3]);
    }
    drop(renderer);
    common::gpu::finish(ctx);
}

#[test]
fn turning_the_environment_turns_the_shadow_with_it() {
    // A sky that is bright in one small patch: the ground's shadow of the sphere falls away from
    // the patch, and turning the environment by 180° moves it to the other side.
    let ctx = common::gpu::context();
    let size = 32;
    let g = ground_gbuffer(size, Grid::new(32).unwrap());
    let mut texels = vec![[0.0f32; 3]; 64 * 32];
    // A sun 45° above the horizon toward +X (u = 0.75, v = 0.25).
    texels[8 * 64 + 48] = [5000.0; 3];
    let env = Environment::new(64, 32, texels, "a sun");
    let left_and_right = |rotation: f32| {
        let mut renderer = lambert_white(&ctx, &g, &env, rotation, false);
        renderer.render_samples(64).unwrap();
        let radiance = renderer.read_radiance().unwrap();
        // The ground just beside the sphere, at x = ∓1.5 (toward −X and toward +X).
        let at = |x: f32| {
            let column = ((x + 3.0) / 6.0 * size as f32) as usize;
            radiance[(size as usize / 2) * size as usize + column][1]
        };
        (at(-1.5), at(1.5))
    };
    let (left, right) = left_and_right(0.0);
    assert!(left < 0.2 * right, "the sun at +X shades the −X side: {left} against {right}");
    let (left, right) = left_and_right(180.0);
    assert!(right < 0.2 * left, "turned 180°, the shadow falls on +X: {left} against {right}");
    common::gpu::finish(ctx);
}

/// A glTF asset: a unit sphere resting on a wide ground, seen straight down by an orthographic
/// camera framing [−3, 3]² (image up is −Z).
fn sphere_on_ground_asset(dir: &std::path::Path) -> std::path::PathBuf {
    use common::gltf::{plane, uv_sphere, Gltf};
    use serde_json::json;
    let mut gltf = Gltf::new();
    let ball = uv_sphere(1.0, 128, 64);
    let ground = plane(100.0);
    let ball_mesh = gltf.mesh("ball", &[(&ball, None)]);
    let ground_mesh = gltf.mesh("ground", &[(&ground, None)]);
    // −90° about X: the plane's +Z normal turns to +Y, and the camera's −Z view to −Y.
    let down = [-std::f32::consts::FRAC_1_SQRT_2, 0.0, 0.0, std::f32::consts::FRAC_1_SQRT_2];
    gltf.node(json!({ "name": "ball", "mesh": ball_mesh, "translation": [0.0, 1.0, 0.0] }));
    gltf.node(json!({ "name": "ground", "mesh": ground_mesh, "rotation": down }));
    let camera = gltf.camera(json!({
        "type": "orthographic",
        "orthographic": { "xmag": 3.0, "ymag": 3.0, "znear": 0.1, "zfar": 100.0 }
    }));
    gltf.node(json!({ "name": "camera", "camera": camera, "translation": [0.0, 10.0, 0.0], "rotation": down }));
    gltf.write_glb(dir, "sphere-on-ground")
}

#[test]
fn a_baked_asset_s_visibility_matches_exact_tracing() {
    use lookdev::asset::bake::{bake, BakeOptions};
    use lookdev::asset::camera::CameraChoice;
    let dir = tempfile::tempdir().unwrap();
    let asset = lookdev::asset::Asset::load(&sphere_on_ground_asset(dir.path())).unwrap();
    let ctx = common::gpu::graphics_context();
    let size = 48u32;
    // One sample a pixel, at its centre, so that each pixel's surface point is known exactly.
    for (side, occlusion_tolerance, disagreement_tolerance) in [(16, 0.015, 0.03), (32, 0.01, 0.015)] {
        let options = BakeOptions {
            width: size,
            height: size,
            samples: 1,
            camera: CameraChoice::Default,
            visibility: Some(Grid::new(side).unwrap()),
        };
        let g = bake(&ctx, &asset, &options, |_, _, _| {}).unwrap();
        let visibility = g.visibility.as_ref().expect("the bake traced visibility");
        let occlusion = visibility::occlusion(&g);
        let ball_id = *g.object_names.iter().find(|(_, name)| name.starts_with("ball")).unwrap().0;
        let (mut worst, mut disagreeing, mut asked) = (0.0f32, 0.0f32, 0.0f32);
        for (p, &occluded) in occlusion.iter().enumerate() {
            let (x, y) = ((p as u32 % size) as f32 + 0.5, (p as u32 / size) as f32 + 0.5);
            let (wx, wz) = ((2.0 * x / size as f32 - 1.0) * 3.0, (2.0 * y / size as f32 - 1.0) * 3.0);
            let r2 = wx * wx + wz * wz;
            // The surface under the pixel's centre, its normal and its exact occlusion: a ground
            // point beside the ball, or a point on the ball, which sees the sky above the
            // horizontal ((1 + cos θ)/2 of its cosine lobe).
            let (position, normal, exact) = if g.object_id[p] == ball_id && r2 < 0.95 {
                let position = Vec3::new(wx, 1.0 + (1.0 - r2).sqrt(), wz);
                let normal = position - Vec3::Y;
                (position, normal, (1.0 + normal.y) / 2.0)
            } else if g.object_id[p] != ball_id && r2 > 1.1 {
                (Vec3::new(wx, 0.0, wz), Vec3::Y, ground_occlusion(r2.sqrt()))
            } else {
                continue; // the ball's rim, seen edge on
            };
            worst = worst.max((occluded - exact).abs());
            // Each stored bit against an exact trace of the analytic scene, weighted by cosine.
            for d in fibonacci(400).filter(|d| d.dot(normal) > 0.0) {
                let origin = position + normal * 1e-4;
                let to_centre = Vec3::Y - origin;
                let along = to_centre.dot(d);
                let hits_ball = along > 0.0 && to_centre.length_squared() - along * along < 1.0;
                let exact_seen = !hits_ball && d.y > 0.0;
                let w = d.dot(normal);
                asked += w;
                if visibility.seen(p, d) != exact_seen {
                    disagreeing += w;
                }
            }
        }
        let disagreement = disagreeing / asked;
        eprintln!(
            "baked, {} directions: worst occlusion error {worst:.4}, bits disagreeing with exact tracing {:.2}% (cosine-weighted)",
            side * side,
            disagreement * 100.0
        );
        assert!(worst < occlusion_tolerance, "side {side}: {worst}");
        assert!(disagreement < disagreement_tolerance, "side {side}: {disagreement}");
    }
    common::gpu::finish(ctx);
}

fn fibonacci(n: usize) -> impl Iterator<Item = Vec3> {
    let golden = PI * (3.0 - 5.0f32.sqrt());
    (0..n).map(move |i| {
        let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
        let r = (1.0 - y * y).sqrt();
        Vec3::new(r * (golden * i as f32).cos(), y, r * (golden * i as f32).sin())
    })
}

#[test]
fn visibility_too_large_for_the_device_is_a_named_error() {
    use lookdev::render::scene::{GBufferSpec, Scene, SceneSpec};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("wide.exr");
    let device = |max: u32| lookdev::gpu::DeviceInfo {
        name: "a small device".into(),
        device_type: ash::vk::PhysicalDeviceType::CPU,
        timestamp_period_ns: None,
        max_image_dimension_2d: max,
        max_color_attachments: 8,
        max_image_array_layers: 256,
        subgroup_size: 8,
    };
    for (side, fits) in [(16, true), (64, false)] {
        let mut g = GBuffer::sphere(256, 256);
        let grid = Grid::new(side).unwrap();
        g.visibility = Some(visibility::Visibility { grid, words: vec![u32::MAX; g.pixel_count() * grid.words()] });
        g.write(&path).unwrap();
        let spec = SceneSpec {
            gbuffer: GBufferSpec { file: Some(path.clone()), ..GBufferSpec::default() },
            quiet: true,
            ..SceneSpec::default()
        };
        let scene = Scene::load(&spec).unwrap();
        // 256² pixels of 32 texels at 4096 a row: 512 rows, over a 256-texel limit.
        match scene.check_device(&device(256)) {
            Ok(()) => assert!(fits, "side {side} passed"),
            Err(error) => {
                assert!(!fits, "side {side}: {error}");
                assert_eq!(error.exit_code(), 2);
                let message = error.to_string();
                assert!(message.starts_with(&format!("{}: ", path.display())), "{message}");
                assert!(
                    message.contains("4096 directions a pixel at 256x256") && message.contains("--visibility"),
                    "{message}"
                );
            }
        }
    }
}

#[test]
fn an_object_that_sees_no_sky_is_a_warning_and_a_lint_finding() {
    let dir = tempfile::tempdir().unwrap();
    let (blind, open) = (dir.path().join("blind.exr"), dir.path().join("open.exr"));
    for (path, word) in [(&blind, 0u32), (&open, u32::MAX)] {
        let mut g = GBuffer::sphere(32, 32);
        let grid = Grid::new(8).unwrap();
        g.visibility = Some(visibility::Visibility { grid, words: vec![word; g.pixel_count() * grid.words()] });
        g.write(path).unwrap();
    }
    let look = dir.path().join("look.toml");
    std::fs::write(&look, "[[object]]\n[[object.layer]]\n").unwrap();
    let lookdev =
        |args: &[&str]| std::process::Command::new(env!("CARGO_BIN_EXE_lookdev")).args(args).output().unwrap();
    let out = dir.path().join("out.png");
    let rendered =
        lookdev(&["render", "--gbuffer", blind.to_str().unwrap(), "--spp", "1", "--out", out.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&rendered.stderr).into_owned();
    assert!(rendered.status.success(), "{text}");
    assert!(text.contains("blind.exr: object 1 'sphere': 100% of its pixels see the sky along no direction"), "{text}");
    let linted = lookdev(&["lint", look.to_str().unwrap(), "--gbuffer", blind.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&linted.stdout).into_owned();
    assert_eq!(linted.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains("blind.exr: object 1 'sphere': 100% of its pixels"), "{stdout}");
    // Seeing everything, or read without its visibility, it is clean.
    for args in
        [vec!["--gbuffer", open.to_str().unwrap()], vec!["--gbuffer", blind.to_str().unwrap(), "--no-visibility"]]
    {
        let linted = lookdev(&[&["lint", look.to_str().unwrap()], &args[..]].concat());
        assert!(linted.status.success(), "{args:?}: {}", String::from_utf8_lossy(&linted.stdout));
    }

    // A shadow catcher with no visibility to catch shadows from: a warning and a finding at its
    // stack's line; with visibility, neither.
    std::fs::write(&look, "[[object]]\nshadow_catcher = true\n[[object.layer]]\n").unwrap();
    let expected = "look.toml:1: this stack catches shadows, but";
    let look = look.to_str().unwrap();
    let open = open.to_str().unwrap();
    let rendered = lookdev(&[
        "render",
        "--gbuffer",
        open,
        "--look",
        look,
        "--no-visibility",
        "--spp",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    let text = String::from_utf8_lossy(&rendered.stderr).into_owned();
    assert!(rendered.status.success() && text.contains(expected), "{text}");
    let linted = lookdev(&["lint", look, "--gbuffer", open, "--no-visibility"]);
    let stdout = String::from_utf8_lossy(&linted.stdout).into_owned();
    assert_eq!(linted.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains(expected) && stdout.contains("open.exr has no visibility"), "{stdout}");
    let rendered =
        lookdev(&["render", "--gbuffer", open, "--look", look, "--spp", "1", "--out", out.to_str().unwrap()]);
    assert!(!String::from_utf8_lossy(&rendered.stderr).contains("catches shadows"));
    assert!(lookdev(&["lint", look, "--gbuffer", open]).status.success());
}

/// Any renderer's file traces its visibility through the scene's triangles given by
/// `--occluders`: a hand-mapped EXR (normals and positions under names of its own) of the
/// sphere on the ground seen from above, and the same scene as glTF. The occlusion of the
/// ground and of the ball against their closed forms, as for the bake.
#[test]
fn a_hand_mapped_file_is_traced_through_the_occluders_it_is_given() {
    use exr::prelude::*;
    use lookdev::gbuffer::source::Channels;
    use lookdev::gbuffer::SourceOptions;
    let dir = tempfile::tempdir().unwrap();
    let occluders = sphere_on_ground_asset(dir.path());
    let size = 48usize;
    let (mut positions, mut normals, mut exact) = (Vec::new(), Vec::new(), Vec::new());
    for p in 0..size * size {
        let (x, y) = ((p % size) as f32 + 0.5, (p / size) as f32 + 0.5);
        let (wx, wz) = ((2.0 * x / size as f32 - 1.0) * 3.0, (2.0 * y / size as f32 - 1.0) * 3.0);
        let r2 = wx * wx + wz * wz;
        let (position, normal) = if r2 < 1.0 {
            let position = Vec3::new(wx, 1.0 + (1.0 - r2).sqrt(), wz);
            (position, position - Vec3::Y)
        } else {
            (Vec3::new(wx, 0.0, wz), Vec3::Y)
        };
        // The ball's rim, seen edge on, and the ground right under it are left out.
        exact.push(match r2 {
            r2 if r2 < 0.95 => Some((1.0 + normal.y) / 2.0),
            r2 if r2 > 1.1 => Some(ground_occlusion(r2.sqrt())),
            _ => None,
        });
        positions.push(position);
        normals.push(normal);
    }
    let channels: Vec<AnyChannel<FlatSamples>> = [("Pw", &positions), ("Nw", &normals)]
        .into_iter()
        .flat_map(|(layer, vectors)| {
            ["X", "Y", "Z"].into_iter().enumerate().map(move |(k, c)| {
                AnyChannel::new(
                    Text::from(format!("{layer}.{c}").as_str()),
                    FlatSamples::F32(vectors.iter().map(|v| v[k]).collect()),
                )
            })
        })
        .collect();
    let path = dir.path().join("mapped.exr");
    let layer = Layer::new(
        (size, size),
        LayerAttributes::default(),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(channels.into()),
    );
    Image::from_layer(layer).write().to_file(&path).unwrap();

    let options = SourceOptions {
        channels: Channels { normal: Some("Nw".into()), position: Some("Pw".into()), ..Channels::default() },
        camera_position: Some(Vec3::new(0.0, 50.0, 0.0)),
        occluders: Some(occluders.clone()),
        ..SourceOptions::default()
    };
    let read = GBuffer::read_with(&path, &options).unwrap();
    let visibility = read.gbuffer.visibility.as_ref().expect("traced through the occluders");
    // A small image gets the fine grid by default.
    assert_eq!(visibility.grid, Grid::new(visibility::default_side(size * size)).unwrap());
    assert!(read.detected.summary(&path).contains("visibility from sphere-on-ground.glb, traced over 64² directions"));
    let occlusion = visibility::occlusion(&read.gbuffer);
    let worst = (0..size * size).filter_map(|p| exact[p].map(|e: f32| (occlusion[p] - e).abs())).fold(0.0f32, f32::max);
    eprintln!("hand-mapped, traced through glTF occluders: worst occlusion error {worst:.4}");
    assert!(worst < 0.01, "{worst}");

    // Without positions (lookdev's own file has none) there is nothing to trace from.
    let own = dir.path().join("own.exr");
    GBuffer::sphere(8, 8).write(&own).unwrap();
    let error = GBuffer::read_with(&own, &SourceOptions { occluders: Some(occluders), ..SourceOptions::default() })
        .err()
        .expect("refused")
        .to_string();
    assert!(error.contains("own.exr") && error.contains("no P or Position layer"), "{error}");
}
