//! The command line as a pipeline uses it: outputs, flags, and a clear one-line error with exit
//! code 2 for every kind of bad input. Every run has Vulkan validation on and fails on any error.

mod common;

use common::cli::{assert_bad_input, assert_success, lookdev, stderr};

use std::path::{Path, PathBuf};
use std::process::Command;

struct Workspace {
    dir: tempfile::TempDir,
}

impl Workspace {
    fn new() -> Workspace {
        Workspace { dir: tempfile::tempdir().unwrap() }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn file(&self, name: &str, text: &str) -> String {
        std::fs::write(self.path(name), text).unwrap();
        self.arg(name)
    }

    fn arg(&self, name: &str) -> String {
        self.path(name).to_string_lossy().into_owned()
    }

    /// A small built-in g-buffer written through the CLI.
    fn gbuffer(&self, size: u32) -> String {
        let out = self.arg("g.exr");
        assert_success(&lookdev(&[
            "gbuffer",
            "--builtin",
            "shaderball",
            "--size",
            &size.to_string(),
            &size.to_string(),
            "--out",
            &out,
        ]));
        out
    }
}

#[allow(clippy::type_complexity)]
fn read_exr(path: &str) -> (usize, usize, Vec<(f32, f32, f32, f32)>) {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |resolution, _| (resolution.width(), resolution.height(), vec![(0.0, 0.0, 0.0, 0.0); resolution.area()]),
        |(w, _, pixels), position, (r, g, b, a): (f32, f32, f32, f32)| {
            pixels[position.y() * *w + position.x()] = (r, g, b, a)
        },
    )
    .unwrap();
    image.layer_data.channel_data.pixels
}

#[test]
fn renders_png_and_exr_and_writes_gbuffers() {
    let ws = Workspace::new();
    let g = ws.gbuffer(48);
    let png = ws.arg("out.png");
    let output = lookdev(&["render", "--gbuffer", &g, "--spp", "8", "--out", &png]);
    assert_success(&output);
    assert!(stderr(&output).contains("wrote"), "a summary line: {}", stderr(&output));
    let image = image::open(&png).unwrap();
    assert_eq!((image.width(), image.height()), (48, 48));
    assert!(image.to_rgb8().pixels().any(|p| p.0 != [0, 0, 0]), "not a black image");

    let exr = ws.arg("out.exr");
    assert_success(&lookdev(&["render", "--gbuffer", &g, "--spp", "8", "--quiet", "--out", &exr]));
    let (w, h, pixels) = read_exr(&exr);
    assert_eq!((w, h), (48, 48));
    // Linear radiance: the ball's highlights may exceed 1, and with a background alpha is 1.
    assert!(pixels.iter().all(|p| p.3 == 1.0 && p.0.is_finite()));

    // Without a background, background pixels are transparent black and alpha is the coverage.
    let exr = ws.arg("nobg.exr");
    assert_success(&lookdev(&["render", "--gbuffer", &g, "--spp", "4", "--no-background", "--quiet", "--out", &exr]));
    let (_, _, pixels) = read_exr(&exr);
    assert_eq!(pixels[0], (0.0, 0.0, 0.0, 0.0));
    assert!(pixels.iter().any(|p| p.3 > 0.0 && p.3 < 1.0), "antialiased coverage reaches alpha");
}

#[test]
fn quiet_prints_nothing() {
    let ws = Workspace::new();
    let g = ws.gbuffer(16);
    let output = lookdev(&["render", "--gbuffer", &g, "--spp", "2", "--quiet", "--out", &ws.arg("q.png")]);
    assert_success(&output);
    assert_eq!(stderr(&output), "");
}

#[test]
fn set_overrides_every_layer_and_flags_override_the_look() {
    let ws = Workspace::new();
    let g = ws.gbuffer(32);
    let render = |extra: &[&str], name: &str| {
        let out = ws.arg(name);
        let mut args = vec!["render", "--gbuffer", &g, "--spp", "4", "--quiet", "--out", &out];
        args.extend_from_slice(extra);
        assert_success(&lookdev(&args));
        read_exr(&out).2
    };
    let plain = render(&[], "plain.exr");
    let metal = render(&["--set", "metallic=1", "--set", "base_color=0.9,0.6,0.3"], "metal.exr");
    assert_ne!(plain, metal);

    // A look without stacks: --set reaches the default material every object falls back to.
    let env_only = ws.file("env-only.toml", "[environment]\nintensity = 1.0\n");
    let grey = render(&["--look", &env_only, "--no-background"], "grey.exr");
    let red = render(&["--look", &env_only, "--no-background", "--set", "base_color=0.8,0.05,0.05"], "red.exr");
    let covered = grey.iter().zip(&red).filter(|(g, _)| g.3 == 1.0).count();
    let redder = grey.iter().zip(&red).filter(|(g, r)| r.0 > g.0 * 0.9 && r.2 < g.2 * 0.5).count();
    assert!(redder * 2 > covered, "{redder} of {covered} pixels turned red");

    // A look's rotation, and the same rotation given as a flag over a look that says otherwise.
    let look_90 = ws.file("r90.toml", "[environment]\nrotation = 90\n[render]\nspp = 4\n");
    let look_0 = ws.file("r0.toml", "[environment]\nrotation = 0\n[render]\nspp = 1\n");
    let from_look = render(&["--look", &look_90], "look.exr");
    let from_flag = render(&["--look", &look_0, "--rotation", "90"], "flag.exr");
    assert_eq!(from_look, from_flag);
    assert_ne!(from_look, plain);
}

#[test]
fn bad_inputs_get_one_clear_line_and_exit_code_2() {
    let ws = Workspace::new();
    let g = ws.gbuffer(16);
    let out = ws.arg("o.png");
    let render = |extra: &[&str]| {
        let mut args = vec!["render", "--spp", "1", "--out", &out];
        args.extend_from_slice(extra);
        lookdev(&args)
    };

    // G-buffers: missing, corrupt, without normals.
    assert_bad_input(&render(&["--gbuffer", &ws.arg("nope.exr")]), &["nope.exr"]);
    let corrupt = ws.file("corrupt.exr", "this is not an OpenEXR file");
    assert_bad_input(&render(&["--gbuffer", &corrupt]), &["corrupt.exr", "OpenEXR"]);
    let studio = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/environment/studio.exr");
    assert_bad_input(&render(&["--gbuffer", studio.to_str().unwrap()]), &["studio.exr", "N.X"]);

    // Looks: a mask the g-buffer lacks, unknown key, unknown parameter, out of range, NaN.
    let look = ws
        .file("mask.toml", "[[object]]\n[[object.layer]]\n[[object.layer]]\npreset = \"gold\"\nmask = \"scratches\"\n");
    assert_bad_input(&render(&["--gbuffer", &g, "--look", &look]), &["mask.toml:3", "scratches", "g.exr"]);
    // A map the g-buffer lacks (it has none), and a bad binding.
    let look = ws.file("map.toml", "[[object]]\n[[object.layer]]\n[object.layer.map]\nbase_color = \"albedo\"\n");
    assert_bad_input(&render(&["--gbuffer", &g, "--look", &look]), &["map.toml:2", "map 'albedo'", "g.exr", "no maps"]);
    let look = ws.file("binding.toml", "[[object]]\n[[object.layer]]\n[object.layer.map]\nrougness = \"r\"\n");
    assert_bad_input(&render(&["--look", &look]), &["binding.toml:4", "rougness", "[object.layer.map]"]);
    let look = ws.file("key.toml", "[render]\nsppp = 4\n");
    assert_bad_input(&render(&["--look", &look]), &["key.toml:2", "sppp"]);
    let look = ws.file("param.toml", "[[object]]\n[[object.layer]]\n[object.layer.set]\nrougness = 0.2\n");
    assert_bad_input(&render(&["--look", &look]), &["param.toml:4", "rougness"]);
    let look = ws.file("range.toml", "[[object]]\n[[object.layer]]\n[object.layer.set]\nroughness = 1.5\n");
    assert_bad_input(&render(&["--look", &look]), &["range.toml:4", "roughness"]);
    let look = ws.file("nan.toml", "[[object]]\n[[object.layer]]\n[object.layer.set]\nmetallic = nan\n");
    assert_bad_input(&render(&["--look", &look]), &["nan.toml:4", "metallic"]);
    assert_bad_input(&render(&["--look", &ws.arg("missing.toml")]), &["missing.toml"]);

    // Environments: not 2:1, NaN/Inf texels, negative texels, missing, wrong format.
    let square = ws.arg("square.exr");
    write_rgb_exr(&square, 8, 8, |_, _| (1.0, 1.0, 1.0));
    assert_bad_input(&render(&["--env", &square]), &["square.exr", "2:1"]);
    let nan = ws.arg("nan.exr");
    write_rgb_exr(&nan, 8, 4, |x, y| {
        if (x, y) == (3, 1) {
            (f32::NAN, 1.0, 1.0)
        } else if x == 0 {
            (f32::INFINITY, 0.0, 0.0)
        } else {
            (1.0, 1.0, 1.0)
        }
    });
    assert_bad_input(&render(&["--env", &nan]), &["nan.exr", "1 NaN", "4 infinite"]);
    assert_bad_input(&render(&["--env", &ws.arg("none.hdr")]), &["none.hdr"]);
    let text = ws.file("env.jpg", "x");
    assert_bad_input(&render(&["--env", &text]), &["env.jpg", ".hdr"]);

    // Flags.
    assert_bad_input(&lookdev(&["render", "--spp", "0", "--out", &out]), &["--spp 0"]);
    assert_bad_input(&lookdev(&["render", "--tonemap", "filmic", "--out", &out]), &["filmic"]);
    assert_bad_input(&lookdev(&["render", "--set", "shininess=1", "--out", &out]), &["shininess"]);
    assert_bad_input(&lookdev(&["render", "--set", "roughness=2", "--out", &out]), &["roughness"]);
    assert_bad_input(&lookdev(&["render", "--out", &ws.arg("o.jpg")]), &["o.jpg"]);
    assert_bad_input(&lookdev(&["render", "--device", "no-such-gpu", "--spp", "1", "--out", &out]), &["no-such-gpu"]);
}

#[test]
fn a_clamped_environment_renders_with_a_warning() {
    let ws = Workspace::new();
    let g = ws.gbuffer(16);
    let negative = ws.arg("neg.exr");
    write_rgb_exr(&negative, 8, 4, |x, _| if x == 2 { (-0.5, 1.0, 1.0) } else { (1.0, 1.0, 1.0) });
    let out = ws.arg("o.png");
    assert_bad_input(
        &lookdev(&["render", "--gbuffer", &g, "--env", &negative, "--out", &out]),
        &["neg.exr", "4 negative"],
    );
    let output = lookdev(&["render", "--gbuffer", &g, "--env", &negative, "--env-clamp", "--spp", "1", "--out", &out]);
    assert_success(&output);
    assert!(stderr(&output).contains("clamped"), "{}", stderr(&output));
}

#[test]
fn a_stack_for_an_object_the_gbuffer_lacks_is_reported_once() {
    let ws = Workspace::new();
    let g = ws.gbuffer(16);
    let look = ws.file("typo.toml", "[[object]]\nid = 1\n[[object.layer]]\npreset = \"gold\"\n\n[[object]]\nid = 7\n[[object.layer]]\npreset = \"chrome\"\n");
    let out = ws.arg("o.png");
    let output = lookdev(&["render", "--gbuffer", &g, "--look", &look, "--spp", "1", "--quiet", "--out", &out]);
    assert_success(&output);
    let warnings: Vec<String> =
        stderr(&output).lines().filter(|l| l.contains("object id 7")).map(String::from).collect();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("typo.toml:8: object id 7 is not in the g-buffer"), "{}", warnings[0]);
}

#[test]
fn a_missing_vulkan_driver_names_the_package() {
    let ws = Workspace::new();
    let output = Command::new(env!("CARGO_BIN_EXE_lookdev"))
        .args(["render", "--spp", "1", "--out", &ws.arg("o.png")])
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .output()
        .unwrap();
    let text = stderr(&output);
    assert_eq!(output.status.code(), Some(1), "{text}");
    assert!(text.contains("mesa-vulkan-drivers") && !text.contains("panicked"), "{text}");
}

fn write_rgb_exr(path: &str, width: usize, height: usize, texel: impl Fn(usize, usize) -> (f32, f32, f32) + Sync) {
    exr::prelude::write_rgb_file(path, width, height, texel).unwrap();
}
