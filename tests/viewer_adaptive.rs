//! `lookdev view --noise-threshold X --min-spp N`: adaptive sampling as the viewer's target,
//! under Xvfb on lavapipe with validation on. Accumulation stops once every pixel has stopped,
//! before the target spp, and the image is `lookdev render`'s with the same options.

mod common;

use common::viewer::{assert_success, Case};

#[test]
fn the_viewer_stops_where_every_pixel_has_stopped_and_matches_lookdev_render() {
    let Some(case) = Case::new() else { return };
    case.write("wait.script", "wait-spp 64\nsave-image viewer.exr\n");
    // Without the shader ball's visibility: its shadows, mostly blocked with a rare bright
    // direction, keep a pixel or two sampling to 64 spp under this threshold.
    let adaptive = ["--noise-threshold", "0.3", "--min-spp", "4", "--no-visibility"];
    // The g-buffer's default material: under the default light every pixel stops by 64 spp.
    let mut args = vec!["--script", "wait.script", "--exit-after-spp", "64", "--screenshot", "shot.png"];
    args.extend(adaptive);
    let output = case.view(&args);
    assert_success(&output);
    let stdout = String::from_utf8_lossy(&output.stdout);
    let line = stdout.lines().find(|l| l.starts_with("lookdev: screenshot")).unwrap();
    assert!(line.contains("adaptive 0.3: 0 px sampling"), "every pixel has stopped: {line}");
    let spp: u32 = line.split(" spp").next().unwrap().rsplit(' ').next().unwrap().parse().unwrap();
    assert!((4..64).contains(&spp), "stopped before the target: {line}");

    let mut render = vec!["render", "--gbuffer", "g.exr", "--spp", "64", "--quiet"];
    render.extend(adaptive);
    render.extend(["--out", "render.exr"]);
    assert_success(&case.command(&render).output().unwrap());
    assert!(case.exr_bits("viewer.exr") == case.exr_bits("render.exr"), "the same pixels, bit for bit");

    let uniform = ["render", "--gbuffer", "g.exr", "--spp", "64", "--quiet", "--out", "u.exr"];
    assert_success(&case.command(&uniform).output().unwrap());
    assert!(case.exr_bits("u.exr") != case.exr_bits("render.exr"), "adaptive sampling took fewer samples");
}

#[test]
fn a_minimum_without_a_threshold_is_an_error() {
    let Some(case) = Case::new() else { return };
    let output = case.view(&["look.toml", "--min-spp", "4", "--exit-after-spp", "4"]);
    assert_eq!(output.status.code(), Some(2), "{}", common::viewer::stderr(&output));
    let text = common::viewer::stderr(&output);
    assert!(text.contains("--min-spp 4") && text.contains("--noise-threshold"), "{text}");
    assert_eq!(text.trim_end().lines().count(), 1, "one line: {text}");
}
