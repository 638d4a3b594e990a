//! The viewer's layout under Xvfb, validation on: the panels keep their widths whatever they
//! show, so the image neither moves nor rescales, and `?` opens and closes the hotkey sheet.
//! Without Xvfb these tests say so and pass, except in CI (`CI` set).
#![cfg(feature = "viewer")]

mod common;

use common::viewer::*;
use image::RgbImage;
use lookdev::gbuffer::GBuffer;

/// A name as long as a production asset's.
fn long(stem: &str) -> String {
    format!("{stem}_{}", "the_long_production_asset_name_v042".repeat(2))
}

/// The right panel's content grows wide: the picked pixel's inspector lists a dozen masks of
/// long names and a long object name, the environment is a file of a long name, and the A/B
/// section opens. Neither panel widens, so the fitted image keeps its place and scale.
#[test]
fn long_names_the_inspector_and_the_compare_section_move_no_panel() {
    let Some(case) = Case::new() else { return };
    let mut gbuffer = GBuffer::shaderball(SIZE, SIZE);
    for index in 0..12 {
        let mask = gbuffer.masks["stripes"].clone();
        gbuffer.masks.insert(long(&format!("mask{index:02}")), mask);
    }
    gbuffer.object_names.insert(1, long("ball"));
    gbuffer.write(&case.path("g.exr")).unwrap();
    let env = format!("{}.exr", long("environment"));
    exr::prelude::write_rgb_file(case.path(&env), 64, 32, |x, _| (0.5 + x as f32 / 64.0, 0.6, 0.7)).unwrap();
    let ball = (0..gbuffer.pixel_count()).find(|&i| gbuffer.object_id[i] == 1 && gbuffer.coverage[i] == 1.0).unwrap();
    let xy = format!("{} {}", ball as u32 % SIZE, ball as u32 / SIZE);
    case.write(
        "panels.script",
        &format!(
            "zoom fit\nwait-spp 1\nscreenshot before.png\npick {xy}\nwait-spp 1\nscreenshot picked.png\n\
             env {env}\nwait-spp 1\nscreenshot lit.png\ncompare model diffuse=lambert\nwait-spp 1\n\
             screenshot compared.png\n"
        ),
    );
    let output = case.view(&["look.toml", "--script", "panels.script", "--exit-after-spp", "1"]);
    assert_success(&output);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains(&format!("object 1 '{}'", long("ball"))), "the long name is shown: {stdout}");
    let before = placement(&output, "before.png");
    for after in ["picked.png", "lit.png", "compared.png"] {
        assert_eq!(placement(&output, after), before, "{after} moved the image:\n{stdout}");
    }
}

/// The middle of a window screenshot, where the sheet opens.
fn middle(case: &Case, name: &str) -> RgbImage {
    let shot = image::open(case.path(name)).unwrap().into_rgb8();
    let (w, h) = shot.dimensions();
    image::imageops::crop_imm(&shot, w / 2 - 150, h / 2 - 100, 300, 200).to_image()
}

/// `?` (typed by the script's `key`) opens the hotkey sheet over the middle of the window, and
/// `?` again closes it, leaving the window as it was.
#[test]
fn the_question_mark_opens_and_closes_the_hotkey_sheet() {
    let Some(case) = Case::new() else { return };
    case.write(
        "sheet.script",
        // A script line takes a frame; the `zoom fit`s after each key give egui's window the
        // frame it sizes itself in before the screenshot.
        "zoom fit\nwait-spp 1\nscreenshot closed.png\nkey ?\nzoom fit\nzoom fit\nscreenshot open.png\nkey ?\n\
         zoom fit\nzoom fit\nscreenshot again.png\n",
    );
    let output = case.view(&["look.toml", "--script", "sheet.script", "--exit-after-spp", "1"]);
    assert_success(&output);
    let (closed, open, again) = (middle(&case, "closed.png"), middle(&case, "open.png"), middle(&case, "again.png"));
    assert_differs(&closed, &open, "the sheet opens over the middle of the window");
    let (max, _) = difference(&closed, &again);
    assert_eq!(max, 0, "the sheet closes again, leaving the window as it was");
}
