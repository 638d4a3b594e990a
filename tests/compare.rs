//! `lookdev render --compare`: A and B side by side, each equal to its own render, their ΔE*ab
//! difference image and statistics, and the errors.

mod common;

use common::cli::{assert_bad_input, assert_success, lookdev};
use std::path::Path;

const SIZE: u32 = 64;

fn arg(dir: &Path, name: &str) -> String {
    dir.join(name).to_string_lossy().into_owned()
}

fn png(path: &str) -> image::RgbaImage {
    image::open(path).unwrap_or_else(|e| panic!("{path}: {e}")).to_rgba8()
}

/// Renders the g-buffer with extra flags to `name`.
fn render(dir: &Path, name: &str, extra: &[&str]) -> std::process::Output {
    let (gbuffer, out) = (arg(dir, "g.exr"), arg(dir, name));
    let mut args = vec!["render", "--gbuffer", &gbuffer, "--spp", "8", "--seed", "5", "--out", &out, "--quiet"];
    args.extend_from_slice(extra);
    lookdev(&args)
}

fn setup() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let size = SIZE.to_string();
    assert_success(&lookdev(&[
        "gbuffer",
        "--builtin",
        "shaderball",
        "--size",
        &size,
        &size,
        "--out",
        &arg(dir.path(), "g.exr"),
    ]));
    std::fs::write(dir.path().join("a.toml"), "[[object]]\n[[object.layer]]\npreset = \"gold\"\n").unwrap();
    std::fs::write(dir.path().join("b.toml"), "[[object]]\n[[object.layer]]\npreset = \"blue-rubber\"\n").unwrap();
    dir
}

/// The region of the side-by-side sheet that holds cell `index` (A = 0, B = 1).
fn cell(sheet: &image::RgbaImage, index: u32) -> image::RgbaImage {
    let margin = 8;
    image::imageops::crop_imm(sheet, margin + index * (SIZE + margin), margin, SIZE, SIZE).to_image()
}

/// Parses "mean X" and "max Y" from the printed statistics.
fn statistic(stdout: &str, name: &str) -> f32 {
    let after = stdout.split(&format!("{name} ")).nth(1).unwrap_or_else(|| panic!("no {name} in: {stdout}"));
    after.split([',', ';', ' ']).next().unwrap().parse().unwrap()
}

#[test]
fn a_model_comparison_shows_each_model_as_its_own_render_and_measures_the_difference() {
    let dir = setup();
    let dir = dir.path();
    let output = render(
        dir,
        "ab.png",
        &["--look", &arg(dir, "a.toml"), "--model", "diffuse=lambert", "--model", "specular_d=beckmann", "--compare"],
    );
    assert_success(&output);
    assert_success(&render(dir, "a.png", &["--look", &arg(dir, "a.toml")]));
    assert_success(&render(
        dir,
        "b.png",
        &["--look", &arg(dir, "a.toml"), "--model", "diffuse=lambert", "--model", "specular_d=beckmann"],
    ));
    let sheet = png(&arg(dir, "ab.png"));
    let (a, b) = (png(&arg(dir, "a.png")), png(&arg(dir, "b.png")));
    assert_eq!(cell(&sheet, 0), a, "the left half is the look's own model");
    assert_eq!(cell(&sheet, 1), b, "the right half is the model with the --model changes");
    assert_ne!(a, b);
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(stdout.contains("ΔE*ab"), "{stdout}");
    assert!(statistic(&stdout, "mean") > 0.1, "{stdout}");
    // The difference image: one heat colour a pixel over a scale bar, black where A equals B.
    let diff = png(&arg(dir, "ab.diff.png"));
    assert_eq!(diff.dimensions(), (SIZE, SIZE + 28));
    let corner = diff.get_pixel(0, 0).0;
    assert_eq!(&corner[..3], &[0, 0, 4], "the background is the same in A and B");
    assert!((0..SIZE * SIZE).any(|i| diff.get_pixel(i % SIZE, i / SIZE).0[0] > 40), "differences show");
}

#[test]
fn a_look_compared_with_itself_differs_nowhere_and_with_another_everywhere() {
    let dir = setup();
    let dir = dir.path();
    let same = render(dir, "same.png", &["--look", &arg(dir, "a.toml"), "--compare", &arg(dir, "a.toml")]);
    assert_success(&same);
    let stdout = String::from_utf8_lossy(&same.stdout).into_owned();
    assert_eq!((statistic(&stdout, "mean"), statistic(&stdout, "max")), (0.0, 0.0), "{stdout}");
    let other = render(dir, "other.exr", &["--look", &arg(dir, "a.toml"), "--compare", &arg(dir, "b.toml")]);
    assert_success(&other);
    let stdout = String::from_utf8_lossy(&other.stdout).into_owned();
    assert!(statistic(&stdout, "mean") > 10.0, "gold against blue rubber: {stdout}");
    // EXR: A's radiance then B's, side by side in one image twice as wide.
    let read = |name: &str| {
        exr::prelude::read_first_rgba_layer_from_file(
            arg(dir, name),
            |r, _| (r.width(), vec![[0f32; 4]; r.area()]),
            |(w, p), at, (r, g, b, a): (f32, f32, f32, f32)| p[at.y() * *w + at.x()] = [r, g, b, a],
        )
        .unwrap()
        .layer_data
        .channel_data
        .pixels
    };
    assert_success(&render(dir, "a.exr", &["--look", &arg(dir, "a.toml")]));
    let (both, a) = (read("other.exr"), read("a.exr"));
    assert_eq!(both.0, 2 * SIZE as usize);
    for y in 0..SIZE as usize {
        assert_eq!(&both.1[y * 2 * SIZE as usize..][..SIZE as usize], &a.1[y * SIZE as usize..][..SIZE as usize]);
    }
}

#[test]
fn compare_without_a_second_look_or_model_and_a_missing_look_are_clear_errors() {
    let dir = setup();
    let dir = dir.path();
    assert_bad_input(&render(dir, "x.png", &["--compare"]), &["--compare needs", "--model"]);
    let missing = arg(dir, "missing.toml");
    assert_bad_input(&render(dir, "x.png", &["--compare", &missing]), &["missing.toml"]);
    assert_bad_input(&render(dir, "x.png", &["--model", "diffuse=velvet", "--compare"]), &["velvet"]);
    assert!(!dir.join("x.png").exists() && !dir.join("x.diff.png").exists());
}
