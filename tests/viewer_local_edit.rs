//! Edit-local re-convergence in the viewer (docs/commands.md#edit-local-re-convergence), under
//! Xvfb on lavapipe with validation on: an edit of the pedestal's stack restarts the pedestal's
//! pixels only, the ball's stay bit for bit, and once caught up the image is `lookdev render`'s
//! of the edited look; a turn of the light still restarts every pixel.

mod common;

use common::viewer::{assert_success, Case};
use lookdev::gbuffer::{GBuffer, BALL_ID, PEDESTAL_ID};
use std::process::Output;

const SPP: u32 = 8;

/// A viewer run with passes swept over many frames (1 ms of relighting a frame), so that a
/// screenshot right after an edit lands while the restarted pixels catch up.
fn view_slowly(case: &Case, script: &str) -> Output {
    case.write("case.script", script);
    let spp = SPP.to_string();
    let args = ["view", "--gbuffer", "g.exr", "--window-size", "960", "680", "--zoom", "1", "look.toml"];
    let mut command = case.command(&args);
    command.args(["--script", "case.script", "--exit-after-spp", &spp]).env("LOOKDEV_FRAME_BUDGET_MS", "1");
    let output = command.output().unwrap();
    assert_success(&output);
    output
}

/// The screenshot line that names `name`.
fn screenshot_line(output: &Output, name: &str) -> String {
    let stdout = String::from_utf8_lossy(&output.stdout);
    stdout.lines().find(|l| l.starts_with("lookdev: screenshot") && l.contains(name)).unwrap().to_string()
}

/// The covered pixels of `object`.
fn pixels_of(gbuffer: &GBuffer, object: u32) -> Vec<usize> {
    (0..gbuffer.pixel_count()).filter(|&i| gbuffer.object_id[i] == object && gbuffer.coverage[i] > 0.0).collect()
}

#[test]
fn an_edit_of_the_pedestal_restarts_only_its_pixels_and_ends_as_a_fresh_render() {
    let Some(case) = Case::new() else { return };
    let gbuffer = GBuffer::read(&case.path("g.exr")).unwrap();
    let pedestal = pixels_of(&gbuffer, PEDESTAL_ID);
    let output = view_slowly(
        &case,
        &format!(
            "wait-spp {SPP}\nsave-image before.exr\nscreenshot before.png\n\
             select default 0\nset roughness 0.85\nscreenshot edited.png\n\
             wait-spp {SPP}\nsave-image after.exr\nsave-look edited.toml\n\
             undo\nscreenshot undoing.png\nwait-spp {SPP}\nsave-image undone.exr\n"
        ),
    );

    // Right after the edit: the pedestal's pixels, and only they, catch up; the rest show what
    // they showed, byte for byte.
    let region = format!("re-converging {} px: ", grouped(pedestal.len()));
    for shot in ["edited.png", "undoing.png"] {
        let line = screenshot_line(&output, shot);
        assert!(line.contains(&region), "{shot}: {line} (expected {region})");
        assert!(line.contains(&format!("/{SPP} spp")), "{line}");
    }
    let (before, edited) = (case.screenshot_image(&output, "before.png"), case.screenshot_image(&output, "edited.png"));
    let mut moved = 0;
    for i in 0..gbuffer.pixel_count() {
        let (x, y) = ((i % gbuffer.width as usize) as u32, (i / gbuffer.width as usize) as u32);
        if pedestal.binary_search(&i).is_ok() {
            moved += (before.get_pixel(x, y) != edited.get_pixel(x, y)) as usize;
        } else {
            assert_eq!(before.get_pixel(x, y), edited.get_pixel(x, y), "pixel {x},{y} is not the pedestal's");
        }
    }
    assert!(moved > 0, "the pedestal shows the new roughness where it has samples");

    // Caught up: the ball's pixels and the background are as before, bit for bit, and the
    // image is `lookdev render`'s of the edited look.
    let (before, after) = (case.exr_bits("before.exr"), case.exr_bits("after.exr"));
    for i in (0..gbuffer.pixel_count()).filter(|i| pedestal.binary_search(i).is_err()) {
        assert_eq!(before[i], after[i], "pixel {i} (object {}) kept its samples", gbuffer.object_id[i]);
    }
    assert!(pedestal.iter().any(|&i| before[i] != after[i]), "the pedestal changed");
    assert!(!pixels_of(&gbuffer, BALL_ID).is_empty());
    let spp = SPP.to_string();
    let render = ["render", "--gbuffer", "g.exr", "--look", "edited.toml", "--spp", &spp, "--quiet", "--out", "r.exr"];
    assert_success(&case.command(&render).output().unwrap());
    assert!(after == case.exr_bits("r.exr"), "the viewer's image is lookdev render's of the edited look, bit for bit");
    // Undone the same way, the first image comes back.
    assert!(case.exr_bits("undone.exr") == before, "undone: the first image, bit for bit");
}

#[test]
fn a_turn_of_the_light_still_restarts_every_pixel() {
    let Some(case) = Case::new() else { return };
    let gbuffer = GBuffer::read(&case.path("g.exr")).unwrap();
    let output =
        view_slowly(&case, &format!("wait-spp {SPP}\nscreenshot before.png\nrotate 30\nscreenshot turned.png\n"));
    let line = screenshot_line(&output, "turned.png");
    assert!(!line.contains("re-converging"), "{line}");
    assert!(line.contains(" 0 spp"), "every pixel starts again: {line}");
    let (before, turned) = (case.screenshot_image(&output, "before.png"), case.screenshot_image(&output, "turned.png"));
    let ball = pixels_of(&gbuffer, BALL_ID);
    let moved = ball
        .iter()
        .filter(|&&i| {
            before.get_pixel(i as u32 % gbuffer.width, i as u32 / gbuffer.width)
                != turned.get_pixel(i as u32 % gbuffer.width, i as u32 / gbuffer.width)
        })
        .count();
    assert!(moved * 2 > ball.len(), "the ball shows the turned light at once: {moved} of {} pixels moved", ball.len());
}

/// 12345 as the status bar writes it: "12 345".
fn grouped(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

/// An edit in the middle of a pass, rows a band of samples apart: the restarted pixels catch up
/// with each row's own count, and the pass then goes on where it was, so that the image is still
/// `lookdev render`'s at the target (it overshot the target in rows below the edit's band).
#[test]
fn an_edit_in_the_middle_of_a_pass_ends_as_a_fresh_render() {
    let Some(case) = Case::new() else { return };
    let output = view_slowly(
        &case,
        &format!(
            "wait-spp 1\nselect default 0\nset roughness 0.85\nset roughness 0.6\n\
             wait-spp {SPP}\nsave-image after.exr\nsave-look edited.toml\n"
        ),
    );
    let spp = SPP.to_string();
    let render = ["render", "--gbuffer", "g.exr", "--look", "edited.toml", "--spp", &spp, "--quiet", "--out", "r.exr"];
    assert_success(&case.command(&render).output().unwrap());
    assert!(case.exr_bits("after.exr") == case.exr_bits("r.exr"), "{}", common::viewer::stderr(&output));
}
