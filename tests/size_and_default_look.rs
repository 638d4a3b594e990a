//! `--size W H` for the built-in scene (render, turntable; the viewer shares the flag) and
//! `lookdev look default`, which writes the built-in default look out.

mod common;

use common::cli::{assert_bad_input, assert_success, stderr};
use image::RgbImage;
use std::path::Path;
use std::process::{Command, Output};

/// `lookdev` in `dir`, validation on, with an empty user preset library so that the look
/// written out resolves its presets as the built-in look does.
fn lookdev_in(dir: &Path, args: &[&str]) -> Output {
    let presets = dir.join("no-presets");
    std::fs::create_dir_all(&presets).unwrap();
    Command::new(env!("CARGO_BIN_EXE_lookdev"))
        .args(args)
        .current_dir(dir)
        .env("LOOKDEV_VALIDATION", "1")
        .env("LOOKDEV_PRESETS", presets)
        .output()
        .unwrap()
}

/// The normals of the built-in scene at `width`×`height`, as `render --aov-display N` shows
/// them: no noise, so two sizes can be compared pixel for pixel.
fn normals(dir: &Path, width: u32, height: u32) -> RgbImage {
    let out = format!("n_{width}x{height}.png");
    let (w, h) = (width.to_string(), height.to_string());
    let output =
        lookdev_in(dir, &["render", "--size", &w, &h, "--aov-display", "N", "--spp", "1", "--quiet", "--out", &out]);
    assert_success(&output);
    image::open(dir.join(out)).unwrap().into_rgb8()
}

/// How many channel values of two same-sized images differ by more than one step.
fn differing(a: &RgbImage, b: &RgbImage) -> usize {
    assert_eq!(a.dimensions(), b.dimensions());
    a.as_raw().iter().zip(b.as_raw()).filter(|(x, y)| x.abs_diff(**y) > 1).count()
}

/// A wide and a tall image have the size asked for and show the square image's scene
/// unstretched: the square is their middle, and only the longer side sees more.
#[test]
fn size_sets_the_image_size_and_the_scene_is_not_stretched() {
    let dir = tempfile::tempdir().unwrap();
    let square = normals(dir.path(), 90, 90);
    let wide = normals(dir.path(), 160, 90);
    let tall = normals(dir.path(), 90, 160);
    assert_eq!(square.dimensions(), (90, 90));
    assert_eq!(wide.dimensions(), (160, 90));
    assert_eq!(tall.dimensions(), (90, 160));
    // The ball is there at all: the middle is not the background.
    let centre = square.get_pixel(45, 40);
    assert!(centre.0 != square.get_pixel(2, 2).0, "no ball in the middle: {centre:?}");
    for (name, image, x, y) in [("160x90", &wide, 35, 0), ("90x160", &tall, 0, 35)] {
        let middle = image::imageops::crop_imm(image, x, y, 90, 90).to_image();
        // Rays through the same points may round differently in the last bit, so an edge pixel
        // may flip: allow a handful of values, far fewer than any stretch would move.
        let changed = differing(&middle, &square);
        eprintln!("{name}: {changed} channel values of the middle differ from the square image by more than one step");
        assert!(changed <= 12, "{name}: its middle 90x90 differs from the square image in {changed} values");
    }
}

#[test]
fn the_beauty_and_a_turntable_take_the_size() {
    let dir = tempfile::tempdir().unwrap();
    let output = lookdev_in(dir.path(), &["render", "--size", "120", "68", "--spp", "1", "--quiet", "--out", "b.png"]);
    assert_success(&output);
    assert_eq!(image::open(dir.path().join("b.png")).unwrap().into_rgb8().dimensions(), (120, 68));
    let args = ["turntable", "--size", "40", "30", "--frames", "2", "--spp", "1", "--quiet", "--out", "t_%02d.png"];
    assert_success(&lookdev_in(dir.path(), &args));
    for frame in ["t_01.png", "t_02.png"] {
        let image = image::open(dir.path().join(frame)).unwrap_or_else(|e| panic!("{frame}: {e}"));
        assert_eq!((image.width(), image.height()), (40, 30), "{frame}");
    }
}

#[test]
fn bad_sizes_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let render = |extra: &[&str]| {
        let mut args = vec!["render", "--spp", "1", "--out", "x.png"];
        args.extend_from_slice(extra);
        lookdev_in(dir.path(), &args)
    };
    assert_bad_input(&render(&["--size", "0", "64"]), &["--size 0 64", "each side must be 1 to 8192 pixels"]);
    assert_bad_input(&render(&["--size", "64", "9000"]), &["--size 64 9000", "1 to 8192"]);
    assert_bad_input(&render(&["--size", "64", "wide"]), &["--size", "wide"]);
    assert_bad_input(&render(&["--size", "64"]), &["--size"]);
    assert_bad_input(
        &render(&["--size", "64", "64", "--gbuffer", "shot.exr"]),
        &["--size 64 64 sizes the built-in shader ball", "--gbuffer shot.exr"],
    );
    // The look names a g-buffer: the size cannot apply to it either.
    std::fs::write(dir.path().join("shot.toml"), "[gbuffer]\nfile = \"shot.exr\"\n").unwrap();
    assert_bad_input(&render(&["--size", "64", "64", "--look", "shot.toml"]), &["shot.toml", "[gbuffer] file"]);
    assert_bad_input(&lookdev_in(dir.path(), &["view", "--size", "0", "5"]), &["each side must be 1 to 8192"]);
    assert!(!dir.path().join("x.png").exists());
}

/// `lookdev look default` prints the built-in look; rendered as a file, it is the default
/// render, bit for bit.
#[test]
fn the_default_look_written_out_renders_as_the_default() {
    let dir = tempfile::tempdir().unwrap();
    let printed = lookdev_in(dir.path(), &["look", "default"]);
    assert_success(&printed);
    let text = String::from_utf8(printed.stdout).unwrap();
    assert_eq!(text, lookdev::material::Look::builtin_default_text());
    assert!(text.contains("preset = \"copper\""), "{text}");
    std::fs::write(dir.path().join("my.toml"), &text).unwrap();

    let size = ["--size", "96", "96", "--spp", "2", "--quiet"];
    let mut default = vec!["render", "--out", "default.png"];
    default.extend_from_slice(&size);
    assert_success(&lookdev_in(dir.path(), &default));
    let mut from_file = vec!["render", "--look", "my.toml", "--out", "mine.png"];
    from_file.extend_from_slice(&size);
    let output = lookdev_in(dir.path(), &from_file);
    assert_success(&output);
    assert!(stderr(&output).is_empty(), "the written look renders without a warning: {}", stderr(&output));
    let read = |name: &str| std::fs::read(dir.path().join(name)).unwrap();
    assert!(read("default.png") == read("mine.png"), "the written look renders differently from the default");
}

#[test]
fn look_default_out_writes_a_file_and_keeps_an_existing_one() {
    let dir = tempfile::tempdir().unwrap();
    assert_success(&lookdev_in(dir.path(), &["look", "default", "--out", "start.toml"]));
    let written = std::fs::read_to_string(dir.path().join("start.toml")).unwrap();
    assert_eq!(written, lookdev::material::Look::builtin_default_text());
    std::fs::write(dir.path().join("start.toml"), "# mine\n").unwrap();
    assert_bad_input(&lookdev_in(dir.path(), &["look", "default", "--out", "start.toml"]), &["start.toml", "--force"]);
    assert_eq!(std::fs::read_to_string(dir.path().join("start.toml")).unwrap(), "# mine\n", "kept");
    assert_success(&lookdev_in(dir.path(), &["look", "default", "--out", "start.toml", "--force"]));
    assert_eq!(std::fs::read_to_string(dir.path().join("start.toml")).unwrap(), written);
}
