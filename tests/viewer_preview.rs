//! The viewer's clean interactive preview, end to end under Xvfb with validation on: the first
//! frame after an edit shows the new state in every row, the passes then land on exactly what
//! `lookdev render` makes, and the denoise display filter is shown but never saved.

mod common;

use common::viewer::{assert_matches_render, assert_success, difference, stderr, Case};

/// An edit that changes every pixel (the light turned off: the new state is black, exactly),
/// then a screenshot in the next frame, with a relighting budget of 1 ms a frame so that the
/// first pass takes many frames on any device, as it does on a slow one at a large size: every
/// row is the new state (the preview, or the pass's first band), none the old. Then the light
/// is turned up and the passes land on exactly what `lookdev render` makes of the edited look.
#[test]
fn the_first_frame_after_an_edit_shows_the_new_state_in_every_row() {
    let Some(case) = Case::new() else { return };
    case.write(
        "edit.script",
        "wait-spp 1\nscreenshot old.png\nintensity 0\nscreenshot dark.png\nwait-spp 1\nintensity 4\nwait-spp 2\n\
         save-look new.toml\nsave-image final.png\n",
    );
    let args = [
        "view",
        "--gbuffer",
        "g.exr",
        "--window-size",
        "960",
        "680",
        "--zoom",
        "1",
        "look.toml",
        "--script",
        "edit.script",
        "--exit-after-spp",
        "2",
        "--screenshot",
        "last.png",
    ];
    let output = case.command(&args).env("LOOKDEV_FRAME_BUDGET_MS", "1").output().unwrap();
    assert_success(&output);
    let stdout = String::from_utf8_lossy(&output.stdout);
    let line = stdout.lines().find(|l| l.contains("screenshot dark.png")).expect("the screenshot is taken");
    assert!(line.contains(", 0 spp"), "the first pass has not landed when the screenshot is taken: {line}");
    let old = case.screenshot_image(&output, "old.png");
    let dark = case.screenshot_image(&output, "dark.png");
    for (y, row) in dark.rows().enumerate() {
        let lit: Vec<(usize, &image::Rgb<u8>)> = row.enumerate().filter(|(_, p)| p.0 != [0, 0, 0]).collect();
        assert!(lit.is_empty(), "row {y} still shows the light before the edit: {:?}", &lit[..lit.len().min(4)]);
    }
    let (_, mean) = difference(&old, &dark);
    assert!(mean > 10.0, "the edit changed the image (mean difference {mean:.1})");
    // Once the passes land, the preview has left no trace.
    let new = case.render("new.toml", 2, "new.png");
    assert_eq!(image::open(case.path("final.png")).unwrap().into_rgb8(), new, "save-image equals lookdev render");
    assert_matches_render(&case.screenshot_image(&output, "last.png"), &new);
    let report = stderr(&output);
    assert!(report.contains("preview after the last change"), "the report gives the preview's time: {report}");
}

/// A bad frame budget is refused before a window opens, naming the variable.
#[test]
fn a_bad_frame_budget_is_refused() {
    let Some(case) = Case::new() else { return };
    let output = case.command(&["view", "--gbuffer", "g.exr"]).env("LOOKDEV_FRAME_BUDGET_MS", "0").output().unwrap();
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
    assert!(
        stderr(&output).contains("LOOKDEV_FRAME_BUDGET_MS=0: expected 1 to 1000 milliseconds"),
        "{}",
        stderr(&output)
    );
}

/// The display filter: `denoise on` changes the view, not `save-image`; `D` turns it off again,
/// and the view is the render's own pixels once more.
#[test]
fn denoise_is_a_display_filter_never_saved() {
    let Some(case) = Case::new() else { return };
    case.write(
        "denoise.script",
        "wait-spp 4\nsave-image off.png\ndenoise on\nwait-spp 4\nscreenshot shown.png\nsave-image saved-on.png\nkey D\nwait-spp 4\n\
         screenshot plain.png\n",
    );
    let output = case.view(&["look.toml", "--script", "denoise.script", "--exit-after-spp", "4"]);
    assert_success(&output);
    let saved_off = std::fs::read(case.path("off.png")).unwrap();
    assert_eq!(
        std::fs::read(case.path("saved-on.png")).unwrap(),
        saved_off,
        "save-image is the same with the filter on"
    );
    let render = case.render("look.toml", 4, "render.png");
    assert_eq!(image::open(case.path("off.png")).unwrap().into_rgb8(), render);
    let on = case.screenshot_image(&output, "shown.png");
    let (largest, mean) = difference(&on, &render);
    assert!(largest > 8 && mean > 0.2, "the filter changes the view: largest {largest}, mean {mean:.3}");
    assert_matches_render(&case.screenshot_image(&output, "plain.png"), &render);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(!stdout.contains("error"), "{stdout}");
}
