//! Viewer snapshots, driven by scripts under a virtual X server (Xvfb) with validation on:
//! taking one, comparing it with the live image (split, side by side, ΔE), restoring its look
//! as one undoable edit, and finding it again in a second viewer run on the same look.
//!
//! Without Xvfb these tests say so and pass, except in CI (`CI` set), where that fails.
#![cfg(feature = "viewer")]

mod common;

use common::viewer::*;
use image::RgbImage;
use lookdev::material::look::Look;
use lookdev::material::params::{Param, Value};
use std::path::Path;
use std::process::{Output, Stdio};
use std::time::Instant;

/// A window wide enough for two 160² images side by side at 1:1 between the panels.
const WIDE: [&str; 2] = ["1400", "680"];

/// `lookdev view` on the case's g-buffer in a [`WIDE`] window at 1:1.
fn view_wide(case: &Case, args: &[&str]) -> Output {
    let mut all = vec!["view", "--gbuffer", "g.exr", "--window-size", WIDE[0], WIDE[1], "--zoom", "1"];
    all.extend_from_slice(args);
    let mut child = case.command(&all).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > HANG {
            child.kill().unwrap();
            panic!("the viewer hung: {:?}", child.wait_with_output().unwrap());
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    child.wait_with_output().unwrap()
}

/// The case's look as the viewer saves it, so that saved files can be compared as text.
fn canonical_look(case: &Case) -> String {
    let text = Look::load(&case.path("look.toml")).unwrap().to_toml();
    case.write("look.toml", &text);
    text
}

/// The report line of screenshot `name`.
fn report(output: &Output, name: &str) -> String {
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    stdout
        .lines()
        .find(|l| l.starts_with("lookdev: screenshot") && l.contains(name))
        .unwrap_or_else(|| panic!("no screenshot {name} reported: {stdout}"))
        .to_string()
}

/// The split column a screenshot report gives.
fn split_column(line: &str) -> u32 {
    let rest = line.split("; split at image column ").nth(1).expect("the split is reported");
    rest.split(' ').next().unwrap().parse().unwrap()
}

/// The ΔE mean and max a screenshot report gives.
fn delta_e(line: &str) -> (f64, f64) {
    let rest = line.split("ΔE2000 live").nth(1).unwrap_or_else(|| panic!("no ΔE reported: {line}"));
    let number = |key: &str| rest.split(key).nth(1).unwrap().split([' ', ';', ')']).next().unwrap().parse().unwrap();
    (number("mean "), number("max "))
}

/// Rows at the top of a split image that carry the halves' labels, and columns either side of
/// the divider line: left out when comparing halves with renders.
const LABEL_ROWS: u32 = 28;
const DIVIDER_MARGIN: u32 = 3;

fn region(image: &RgbImage, columns: std::ops::Range<u32>) -> RgbImage {
    image::imageops::crop_imm(image, columns.start, LABEL_ROWS, columns.end - columns.start, SIZE - LABEL_ROWS)
        .to_image()
}

/// One text attribute of an EXR's header.
fn exr_attribute(path: &Path, name: &str) -> Option<String> {
    let meta = exr::meta::MetaData::read_from_file(path, false).unwrap();
    meta.headers[0].own_attributes.other.iter().find_map(|(key, value)| match value {
        exr::meta::attribute::AttributeValue::Text(text) if key == name => Some(text.to_string()),
        _ => None,
    })
}

/// The RGBA samples of an EXR, row by row.
fn exr_pixels(path: &Path) -> Vec<[f32; 4]> {
    use exr::prelude::{read_first_rgba_layer_from_file, RgbaChannels};
    let image = read_first_rgba_layer_from_file(
        path,
        |size, _: &RgbaChannels| vec![[0f32; 4]; size.width() * size.height()],
        |pixels: &mut Vec<[f32; 4]>, position, (r, g, b, a): (f32, f32, f32, f32)| {
            pixels[position.y() * SIZE as usize + position.x()] = [r, g, b, a];
        },
    )
    .unwrap();
    image.layer_data.channel_data.pixels
}

#[test]
fn snapshot_edit_compare_restore_round_trips_the_look_and_a_second_run_finds_it() {
    let Some(case) = Case::new() else { return };
    let before = canonical_look(&case);
    // Snapshot, edit, compare it three ways, restore it, save; then undo the restore and save
    // what undo brings back. `P` is the snapshot hotkey.
    case.write(
        "snap.script",
        "wait-spp 4\nsnapshot before\nselect 1 1\nset roughness 0.9\nrotate 30\nwait-spp 4\n\
         compare snapshot before split\ndivider 0.5\nwait-spp 4\nscreenshot split.png\n\
         compare snapshot before side\nscreenshot side.png\n\
         compare snapshot before delta-e\nscreenshot edited-delta.png\n\
         restore before\nwait-spp 4\nscreenshot restored-delta.png\nsave-look\n\
         key P\nwait-spp 4\ncompare off\nundo\nwait-spp 4\nsave-look edited.toml\n",
    );
    let output = view_wide(&case, &["look.toml", "--script", "snap.script", "--exit-after-spp", "4"]);
    assert_success(&output);
    let stdout = String::from_utf8_lossy(&output.stdout);

    // The files, beside the look, and the EXR as `lookdev render` writes it.
    let folder = case.path("look.snapshots");
    for name in ["before.toml", "before.exr", "before.png", "snapshot-1.toml", "snapshot-1.exr", "snapshot-1.png"] {
        assert!(folder.join(name).is_file(), "{name} is written: {stdout}");
    }
    // The EXR records the look as rendered (docs/formats.md#metadata): the same materials, every
    // layer's parameters written out.
    let recorded = exr_attribute(&folder.join("before.exr"), "lookdev/look").unwrap();
    let recorded = Look::parse(&recorded, Path::new("recorded.toml")).unwrap();
    let materials = |look: &Look| -> Vec<(Option<u32>, Vec<lookdev::material::Params>)> {
        look.objects.iter().map(|o| (o.id, o.layers.iter().map(|l| l.params).collect())).collect()
    };
    assert_eq!(materials(&recorded), materials(&Look::parse(&before, &case.path("look.toml")).unwrap()));
    assert_eq!(exr_attribute(&folder.join("before.exr"), "lookdev/seed").as_deref(), Some("0"));
    let rendered = case.render("look.toml", 4, "before.png");
    let args = ["render", "--gbuffer", "g.exr", "--look", "look.toml", "--spp", "4", "--quiet", "--out", "before.exr"];
    assert_success(&case.command(&args).output().unwrap());
    let (snapshot, render) = (exr_pixels(&folder.join("before.exr")), exr_pixels(&case.path("before.exr")));
    let worst =
        snapshot.iter().zip(&render).flat_map(|(a, b)| (0..4).map(move |k| (a[k] - b[k]).abs())).fold(0.0, f32::max);
    assert!(worst < 1e-4, "the snapshot's radiance is the render's: largest difference {worst}");
    let png = image::open(folder.join("before.png")).unwrap().into_rgb8();
    assert_matches_render(&png, &rendered);

    // Restore round-trips the look exactly (saved with the g-buffer it is open on, which the
    // file opened without); undo brings back the edited one.
    let kept = before.replacen("\n\n[[object]]", "\n\n[gbuffer]\nfile = \"g.exr\"\n\n[[object]]", 1);
    assert_eq!(std::fs::read_to_string(case.path("look.toml")).unwrap(), kept, "save-look after restore");
    let mut edited = Look::load(&case.path("look.toml")).unwrap();
    let ball = edited.objects.iter_mut().find(|o| o.id == Some(1)).unwrap();
    ball.layers[1].params.set(Param::Roughness, Value::Scalar(0.9)).unwrap();
    edited.environment.rotation = Some(30.0);
    let mut undone = Look::load(&case.path("edited.toml")).unwrap();
    undone.file = edited.file.clone();
    assert_eq!(undone, edited, "undo after restore brings back the edited look");
    let edited_render = case.render("edited.toml", 4, "edited.png");
    assert_differs(&edited_render, &rendered, "the edit changes the image");

    // Split: live (edited) left of the divider, the snapshot right of it.
    let line = report(&output, "split.png");
    let column = split_column(&line);
    assert_eq!(column, SIZE / 2);
    assert!(line.contains("A: live | B: snapshot before · 4 spp"), "{line}");
    let shot = case.screenshot_image(&output, "split.png");
    let (left, right) = (0..column - DIVIDER_MARGIN, column + DIVIDER_MARGIN..SIZE);
    assert_matches_render(&region(&shot, left.clone()), &region(&edited_render, left));
    assert_matches_render(&region(&shot, right.clone()), &region(&rendered, right));

    // Side by side: each whole image, the live one where the image is, the snapshot beside it.
    let line = report(&output, "side.png");
    let at = line.split("; snapshot before is at ").nth(1).expect("the snapshot's place is reported");
    let (x, y) = at.split([';', ')']).next().unwrap().split_once(',').unwrap();
    let (x, y): (u32, u32) = (x.parse().unwrap(), y.trim().parse().unwrap());
    let window = image::open(case.path("side.png")).unwrap().into_rgb8();
    assert_matches_render(&case.screenshot_image(&output, "side.png"), &edited_render);
    assert_matches_render(&image::imageops::crop_imm(&window, x, y, SIZE, SIZE).to_image(), &rendered);

    // ΔE: non-zero after the edit; zero everywhere once restored, and the heat map black.
    let (mean, max) = delta_e(&report(&output, "edited-delta.png"));
    assert!(mean > 0.5 && max > 5.0, "the edit shows in ΔE: mean {mean}, max {max}");
    let edited_heat = case.screenshot_image(&output, "edited-delta.png");
    assert!(edited_heat.pixels().filter(|p| p.0 != [0, 0, 0]).count() > 1000, "the heat map shows the edit");
    assert_eq!(delta_e(&report(&output, "restored-delta.png")), (0.0, 0.0));
    let heat = case.screenshot_image(&output, "restored-delta.png");
    assert!(heat.pixels().all(|p| p.0 == [0, 0, 0]), "zero ΔE is black everywhere");

    // A second run on the same look lists the snapshots, compares and restores them.
    case.write(
        "again.script",
        "wait-spp 4\ncompare snapshot before delta-e\nscreenshot same.png\nselect 1 1\nset metallic 0\n\
         wait-spp 4\ncompare snapshot before split\nwait-spp 4\nscreenshot again.png\nrestore before\n\
         delete-snapshot snapshot-1\nsave-look\n",
    );
    let output = case.view(&["look.toml", "--script", "again.script", "--exit-after-spp", "4"]);
    assert_success(&output);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains("lookdev: snapshots of look.toml: before (4 spp"), "listed: {stdout}");
    assert_eq!(delta_e(&report(&output, "same.png")), (0.0, 0.0), "the same look, another day");
    let shot = case.screenshot_image(&output, "again.png");
    let column = split_column(&report(&output, "again.png"));
    let right = column + DIVIDER_MARGIN..SIZE;
    assert_matches_render(&region(&shot, right.clone()), &region(&rendered, right));
    assert_eq!(std::fs::read_to_string(case.path("look.toml")).unwrap(), kept, "restored from disk exactly");
    assert!(!folder.join("snapshot-1.toml").exists() && !folder.join("snapshot-1.exr").exists(), "deleted");
    assert!(folder.join("before.toml").is_file());
}

#[test]
fn snapshot_problems_are_clear_errors_and_a_corrupt_file_is_a_warning() {
    let Some(case) = Case::new() else { return };
    // A bad name is refused before a window opens, with its line.
    case.write("name.script", "wait-spp 1\nsnapshot ../up\n");
    let output = case.view(&["look.toml", "--script", "name.script"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(stderr(&output).contains("name.script:2: snapshot name '../up' has '/'"), "{}", stderr(&output));

    // A corrupt snapshot, one of another g-buffer's size, and one whose image is missing.
    let folder = case.path("look.snapshots");
    case.write("look.snapshots/broken.toml", "[snapshot\nname = 3\n");
    let look = std::fs::read_to_string(case.path("look.toml")).unwrap();
    let header = |name: &str, size: u32| {
        let mut table = toml::Table::new();
        let mut snapshot = toml::Table::new();
        snapshot.insert("name".into(), name.into());
        snapshot.insert("spp".into(), 4.into());
        snapshot.insert("taken".into(), "2026-12-02T10:00:00Z".into());
        snapshot.insert("width".into(), i64::from(size).into());
        snapshot.insert("height".into(), i64::from(size).into());
        snapshot.insert("look".into(), look.clone().into());
        table.insert("snapshot".into(), snapshot.into());
        table.to_string()
    };
    case.write("look.snapshots/big.toml", &header("big", 320));
    RgbImage::new(320, 320).save(folder.join("big.png")).unwrap();
    std::fs::write(folder.join("big.exr"), b"").unwrap();
    case.write("look.snapshots/lost.toml", &header("lost", SIZE));
    std::fs::write(folder.join("lost.exr"), b"").unwrap();

    // Listed with warnings, and the viewer opens; a missing snapshot is named with those there
    // are, which are listed before the first line runs.
    case.write("missing.script", "restore bigg\n");
    let output = case.view(&["look.toml", "--script", "missing.script", "--exit-after-spp", "1"]);
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
    let text = stderr(&output);
    assert!(text.contains("warning: ") && text.contains("broken.toml:1: TOML syntax error"), "{text}");
    assert!(text.contains("lost.png: file not found; this snapshot is skipped"), "{text}");
    assert!(
        text.contains("missing.script:1: no snapshot named 'bigg' (did you mean 'big'?); there are: big"),
        "{text}"
    );
    assert!(!text.contains("panicked"), "{text}");

    // Another g-buffer's snapshot cannot be compared; a name in use cannot be taken again.
    for (script, problem) in [
        ("wait-spp 1\ncompare snapshot big side\n", "size.script:2: snapshot 'big' is 320x320, but the g-buffer"),
        ("wait-spp 1\nsnapshot big\n", "size.script:2: a snapshot named 'big' already exists"),
    ] {
        case.write("size.script", script);
        let output = case.view(&["look.toml", "--script", "size.script", "--exit-after-spp", "1"]);
        assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
        assert!(stderr(&output).contains(problem), "{}", stderr(&output));
    }

    // A look without a file has nowhere to keep them.
    case.write("unsaved.script", "wait-spp 1\nsnapshot\n");
    let output = case.view(&["--script", "unsaved.script", "--exit-after-spp", "1"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(stderr(&output).contains("unsaved.script:2: snapshot: the look has no file yet"), "{}", stderr(&output));
}

#[test]
fn restore_is_one_undoable_edit_of_look_and_settings() {
    use lookdev::render::settings::{Overrides, Settings};
    use lookdev::viewer_state::{Document, Edit};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("look.toml");
    std::fs::write(&path, LOOK).unwrap();
    let look = Look::load(&path).unwrap();
    let settings = Settings::resolve(&look, &Overrides::default()).unwrap();
    let mut document = Document::new(look, Some(path.clone()), settings);
    let (kept_look, kept_settings) = (document.look().clone(), document.settings().clone());
    document.apply(Edit::SetRotation(12.0)).unwrap();
    document.apply(Edit::SetExposure(1.5)).unwrap();
    let (edited_look, edited_settings) = (document.look().clone(), document.settings().clone());
    let restore = Edit::Restore { look: Box::new(kept_look.clone()), settings: Box::new(kept_settings.clone()) };
    document.apply(restore).unwrap();
    assert_eq!((document.look(), document.settings()), (&kept_look, &kept_settings));
    assert!(!document.is_dirty(), "back to the file");
    assert!(document.undo());
    assert_eq!((document.look(), document.settings()), (&edited_look, &edited_settings), "one step back");
    assert!(document.redo());
    assert_eq!(document.look(), &kept_look);
}

/// `B` flips in place between the live image and the newest snapshot, and, while a snapshot is
/// compared, between the comparison and the snapshot alone; each screenshot line says which
/// image is on screen, and the flipped image is the snapshot's pixels where the live one was.
#[test]
fn b_flips_between_the_live_image_and_a_snapshot_in_place() {
    let Some(case) = Case::new() else { return };
    case.write(
        "flip.script",
        "wait-spp 4\nkey B\nscreenshot nothing.png\nsnapshot before\nselect 1 1\nset roughness 0.9\nwait-spp 4\n\
         screenshot live.png\nkey B\nscreenshot flipped.png\nkey B\nscreenshot back.png\n\
         compare snapshot before split\nkey B\nscreenshot split-flip.png\nkey B\nscreenshot split-return.png\n",
    );
    let output = view_wide(&case, &["look.toml", "--script", "flip.script", "--exit-after-spp", "4"]);
    assert_success(&output);
    // Nothing to flip to yet: the view says nothing of it.
    assert!(!report(&output, "nothing.png").contains("showing"), "{}", report(&output, "nothing.png"));
    let snapshot = image::open(case.path("look.snapshots/before.png")).unwrap().into_rgb8();
    let live = case.screenshot_image(&output, "live.png");
    assert_differs(&live, &snapshot, "the edit changes the image");
    for (shot, says, image) in [
        ("live.png", "; showing live", &live),
        ("flipped.png", "; showing snapshot before", &snapshot),
        ("back.png", "; showing live", &live),
        ("split-flip.png", "; showing snapshot before", &snapshot),
    ] {
        let line = report(&output, shot);
        assert!(line.contains(says), "{line}");
        assert_matches_render(&case.screenshot_image(&output, shot), image);
    }
    // Where the live image was: the flip moves nothing.
    assert_eq!(placement(&output, "flipped.png"), placement(&output, "live.png"));
    let line = report(&output, "split-return.png");
    assert!(line.contains("; showing live | snapshot before") && line.contains("; split at image column"), "{line}");
}
