//! Supersampled g-buffers: a bake written at twice its output size renders at the output size,
//! each output pixel the mean of the four it covers (object ids by vote), in `render` and in
//! `turntable`; a factor that does not divide the g-buffer is a one-line error. The edge error
//! it lowers is measured against Cycles in `tests/blender_shadows.rs`.

mod common;

use common::cli::{assert_bad_input, assert_success, lookdev, stderr};
use common::gltf::{camera_looking_down_z, plane, uv_sphere, Gltf};
use lookdev::gbuffer::GBuffer;
use serde_json::json;
use std::path::Path;

/// A ball in front of a wall, seen by a camera down −Z: silhouettes over another object.
fn ball_before_a_wall(dir: &Path) -> String {
    let mut gltf = Gltf::new();
    let ball = gltf.mesh("ball", &[(&uv_sphere(1.0, 64, 32), None)]);
    gltf.node(json!({ "name": "ball", "mesh": ball }));
    let wall = gltf.mesh("wall", &[(&plane(4.0), None)]);
    gltf.node(json!({ "name": "wall", "mesh": wall, "translation": [0.0, 0.0, -1.5] }));
    camera_looking_down_z(&mut gltf, "front", [0.0, 0.0, 6.0], 40.0, 4.0 / 3.0);
    gltf.write_glb(dir, "scene").to_string_lossy().into_owned()
}

/// Every channel of an EXR's first part, with its size.
fn read(path: &Path) -> (usize, usize, std::collections::BTreeMap<String, Vec<f32>>) {
    use exr::prelude::*;
    let image = read_all_flat_layers_from_file(path).unwrap();
    let layer = &image.layer_data[0];
    let channels =
        layer.channel_data.list.iter().map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect())).collect();
    (layer.size.width(), layer.size.height(), channels)
}

#[test]
fn a_supersampled_bake_renders_at_its_output_size_as_the_mean_of_its_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let arg = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let model = ball_before_a_wall(dir.path());
    let baked = lookdev(&[
        "bake",
        &model,
        "--out",
        &arg("g.exr"),
        "--size",
        "40",
        "30",
        "--supersample",
        "2",
        "--visibility",
        "8",
    ]);
    assert_success(&baked);
    assert!(stderr(&baked).contains("(80x60, supersampled 2x2 for 40x30,"), "{}", stderr(&baked));
    let gbuffer = GBuffer::read(&dir.path().join("g.exr")).unwrap();
    assert_eq!((gbuffer.width, gbuffer.height, gbuffer.supersample), (80, 60, 2));

    let render = |out: &str, extra: &[&str]| {
        let (gbuffer, output) = (arg("g.exr"), arg(out));
        let mut args = vec!["render", "--gbuffer", &gbuffer, "--spp", "8", "--out", &output];
        // A PNG holds no AOVs.
        if out.ends_with(".exr") {
            args.extend(["--aov", "objectId"]);
        }
        args.extend(extra);
        let result = lookdev(&args);
        assert_success(&result);
        stderr(&result)
    };
    let said = render("out.exr", &[]);
    assert!(said.contains("(40x30 from a g-buffer supersampled 2x2,"), "{said}");
    render("full.exr", &["--supersample", "1"]);
    let (w, h, out) = read(&dir.path().join("out.exr"));
    let (fw, fh, full) = read(&dir.path().join("full.exr"));
    assert_eq!((w, h, fw, fh), (40, 30, 80, 60));
    let block = |p: usize| {
        let (x, y) = (p % w * 2, p / w * 2);
        [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)].map(|(x, y)| y * fw + x)
    };
    let (mut edges, mut ids) = (0, std::collections::BTreeSet::new());
    assert_eq!(out["objectId.Y"].len(), w * h);
    for (p, &id) in out["objectId.Y"].iter().enumerate() {
        for c in ["R", "G", "B", "A"] {
            let mean = block(p).iter().map(|&q| full[c][q] as f64).sum::<f64>() / 4.0;
            assert!(
                (out[c][p] as f64 - mean).abs() <= 1e-6 * mean.abs().max(1.0),
                "pixel {p} {c}: {} against {mean}",
                out[c][p]
            );
        }
        let fine = block(p).map(|q| full["objectId.Y"][q]);
        let votes = |id: f32| fine.iter().filter(|&&f| f == id).count();
        assert!(fine.iter().all(|&f| votes(id) >= votes(f)), "pixel {p}: id {id} is not the most common of {fine:?}");
        edges += fine.iter().any(|&f| f != fine[0]) as usize;
        ids.insert(id as u32);
    }
    assert!(edges > 20, "only {edges} output pixels hold more than one object");
    assert_eq!(ids.into_iter().collect::<Vec<_>>(), [1, 2], "the ball and the wall");

    // A PNG and a turntable's frames come out at the output size too.
    render("out.png", &[]);
    assert_eq!(image::image_dimensions(dir.path().join("out.png")).unwrap(), (40, 30));
    let frames = arg("turn_%02d.png");
    assert_success(&lookdev(&[
        "turntable",
        "--gbuffer",
        &arg("g.exr"),
        "--frames",
        "2",
        "--spp",
        "2",
        "--out",
        &frames,
    ]));
    assert_eq!(image::image_dimensions(dir.path().join("turn_01.png")).unwrap(), (40, 30));

    // Factors that do not fit: one line naming the file or the flag.
    let output = lookdev(&["render", "--gbuffer", &arg("g.exr"), "--supersample", "7", "--out", &arg("x.png")]);
    assert_bad_input(&output, &["g.exr", "--supersample 7", "80x60 pixels are not a multiple of 7"]);
    let output = lookdev(&["bake", &model, "--out", &arg("x.exr"), "--supersample", "9"]);
    assert_bad_input(&output, &["--supersample", "1 to 8"]);
}
