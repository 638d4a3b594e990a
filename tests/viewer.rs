//! The interactive viewer, driven through its headless hooks under a virtual X server (Xvfb) on
//! whatever Vulkan driver is installed (lavapipe in CI), with validation on. A run renders to
//! `--exit-after-spp`, saves the window with `--screenshot` and reports where the image sits in
//! it, so the image can be compared with `lookdev render` of the same look.
//!
//! Without Xvfb these tests say so and pass, except in CI (`CI` set), where that fails: the
//! viewer is part of what CI vouches for.
#![cfg(feature = "viewer")]

mod common;

use common::viewer::*;
use image::RgbImage;
use lookdev::gbuffer::GBuffer;
use lookdev::material::look::Look;
use lookdev::material::params::{Param, Value};
use lookdev::viewer::thumbnails::{self, Thumbnails};
use std::path::Path;
use std::process::{Output, Stdio};
use std::time::{Duration, Instant};
#[test]
fn the_viewer_opens_renders_and_its_screenshot_matches_lookdev_render() {
    let Some(case) = Case::new() else { return };
    let output = case.view(&["look.toml", "--seed", "7", "--exit-after-spp", "6", "--screenshot", "shot.png"]);
    assert_success(&output);
    let report = stderr(&output);
    assert!(report.contains("frame time") && report.contains("samples/s") && report.contains("6 spp"), "{report}");

    let shot = case.screenshot_image(&output, "shot.png");
    let mut seeded = Look::load(&case.path("look.toml")).unwrap();
    seeded.render.seed = Some(7);
    case.write("seeded.toml", &seeded.to_toml());
    let render = case.render("seeded.toml", 6, "render.png");
    assert_matches_render(&shot, &render);
    // Not a blank window that happens to match a blank render.
    let (_, mean_level) = difference(&shot, &RgbImage::new(SIZE, SIZE));
    assert!(mean_level > 20.0, "the image is nearly black: {mean_level}");
}

/// Left alone, with no script and no input events at all, the viewer relights until the target
/// and draws the window only as the image changes: a few frames, most of the relighting in
/// slices between them. The interactive budget is 1 ms, so that the frames alone would take
/// hundreds to get there.
#[test]
fn left_alone_the_viewer_reaches_its_target_drawing_only_as_the_image_changes() {
    let Some(case) = Case::new() else { return };
    let output = case
        .view_with_env(&["look.toml", "--seed", "7", "--exit-after-spp", "48"], &[("LOOKDEV_FRAME_BUDGET_MS", "1")]);
    assert_success(&output);
    let report = stderr(&output);
    assert!(report.contains(": 48 spp;"), "{report}");
    let count = |after: &str| -> u64 {
        let at = report.find(after).unwrap_or_else(|| panic!("no '{after}' in {report}"));
        let digits: String = report[..at].chars().rev().skip(1).take_while(char::is_ascii_digit).collect();
        digits.chars().rev().collect::<String>().parse().unwrap()
    };
    let (frames, slices) = (count("frames drawn"), count("relighting slices"));
    assert!(slices >= 1, "{report}");
    assert!(frames <= 16, "{frames} frames drawn for 48 spp: {report}");
}

/// A look saved in the viewer keeps its scene, whatever flags opened it: the g-buffer file,
/// relative to the look, or the built-in scene's size. Either renders on its own, from another
/// folder, at the size the viewer showed.
#[test]
fn a_saved_look_reopens_on_its_scene() {
    let Some(case) = Case::new() else { return };
    case.write("deep/er/.keep", "");
    case.write("file.script", "save-look deep/er/on-file.toml\n");
    assert_success(&case.view(&["look.toml", "--script", "file.script", "--exit-after-spp", "1"]));
    let text = std::fs::read_to_string(case.path("deep/er/on-file.toml")).unwrap();
    assert!(text.contains("[gbuffer]\nfile = \"../../g.exr\"\n"), "{text}");

    case.write("builtin.script", "save-look deep/er/built-in.toml\n");
    let builtin = case
        .command(&["view", "--size", "72", "56", "--script", "builtin.script", "--exit-after-spp", "1"])
        .output()
        .unwrap();
    assert_success(&builtin);
    let text = std::fs::read_to_string(case.path("deep/er/built-in.toml")).unwrap();
    assert!(text.contains("[gbuffer]\nsize = [72, 56]\n"), "{text}");

    for (look, size) in [("deep/er/on-file.toml", (SIZE, SIZE)), ("deep/er/built-in.toml", (72, 56))] {
        let out = case.arg(&format!("{look}.png"));
        let rendered = std::process::Command::new(env!("CARGO_BIN_EXE_lookdev"))
            .args(["render", "--look", &case.arg(look), "--spp", "1", "--quiet", "--out", &out])
            .current_dir(std::env::temp_dir())
            .output()
            .unwrap();
        assert_success(&rendered);
        assert_eq!(image::image_dimensions(&out).unwrap(), size, "{look}");
    }
}

/// H hides the side panels, so that the image has the window's width (at 1:1, it then sits
/// in the middle of the window), and H again brings them back.
#[test]
fn h_hides_the_side_panels_and_brings_them_back() {
    let Some(case) = Case::new() else { return };
    case.write("tab.script", "key H\nscreenshot hidden.png\nkey H\nscreenshot shown.png\n");
    let output = case.view(&["look.toml", "--script", "tab.script", "--exit-after-spp", "1"]);
    assert_success(&output);
    let left = |shot: &str| placement(&output, shot).x;
    let window: f32 = WINDOW[0].parse().unwrap();
    assert_eq!(left("hidden.png"), (window - SIZE as f32) / 2.0);
    assert!(left("shown.png") > left("hidden.png") + 40.0, "the left panel is back");
}

/// The layer keys, through the interface as a real key press: Ctrl+J duplicates the selected
/// layer and selects the copy, Ctrl+, hides it, Delete removes it.
#[test]
fn layer_keys_duplicate_hide_and_remove_the_selected_layer() {
    let Some(case) = Case::new() else { return };
    case.write(
        "keys.script",
        "select 1 0\nkey ctrl+J\nkey ctrl+Comma\nsave-look copied.toml\nkey Delete\nsave-look removed.toml\n",
    );
    assert_success(&case.view(&["look.toml", "--script", "keys.script", "--exit-after-spp", "1"]));
    let ball = |file: &str| -> Vec<(Option<String>, bool)> {
        let look = Look::load(&case.path(file)).unwrap();
        let stack = look.objects.iter().find(|o| o.id == Some(1)).unwrap();
        stack.layers.iter().map(|l| (l.preset.clone(), l.enabled)).collect()
    };
    let preset = |name: &str| Some(name.to_string());
    assert_eq!(
        ball("copied.toml"),
        [(preset("blue-rubber"), true), (preset("blue-rubber"), false), (preset("gold"), true)],
        "the copy above the original, hidden"
    );
    assert_eq!(ball("removed.toml"), [(preset("blue-rubber"), true), (preset("gold"), true)]);
}

/// A layer renamed and its mask blurred and levelled are saved in the look; S solos the layer
/// (the image is `render`'s of the look with that layer alone in its stack) and S again ends
/// it; L tints where the selected layer shows.
#[test]
fn layers_are_renamed_adjusted_soloed_and_overlaid() {
    let Some(case) = Case::new() else { return };
    case.write(
        "layer.script",
        "select 1 1\nrename Gold trim\nmask-adjust 0.2 0.7 1.5 2\nsave-look adjusted.toml\nkey S\nwait-spp 4\n\
         screenshot solo.png\nkey S\nwait-spp 4\nscreenshot plain.png\nkey L\nscreenshot overlay.png\n",
    );
    let output = case.view(&["look.toml", "--script", "layer.script", "--exit-after-spp", "4"]);
    assert_success(&output);
    let adjusted = Look::load(&case.path("adjusted.toml")).unwrap();
    let gold = &adjusted.stack_for(1).unwrap().layers[1];
    assert_eq!(gold.name.as_deref(), Some("Gold trim"));
    let adjust = gold.mask_adjust;
    assert_eq!((adjust.black, adjust.white, adjust.gamma, adjust.blur), (0.2, 0.7, 1.5, 2.0));

    let soloed = LOOK.replace("preset = \"blue-rubber\"\n[[object.layer]]\n", "");
    case.write("soloed.toml", &soloed);
    let solo = case.screenshot_image(&output, "solo.png");
    assert_matches_render(&solo, &case.render("soloed.toml", 4, "soloed.png"));
    let plain = case.screenshot_image(&output, "plain.png");
    assert_matches_render(&plain, &case.render("adjusted.toml", 4, "adjusted.png"));

    // The overlay tints the striped ball orange where the gold shows, and nothing else.
    let overlay = case.screenshot_image(&output, "overlay.png");
    let tinted = overlay.pixels().zip(plain.pixels()).filter(|(o, p)| o[0] as i32 - p[0] as i32 > 30).count();
    let bluer = overlay.pixels().zip(plain.pixels()).filter(|(o, p)| o[2] as i32 - p[2] as i32 > 2).count();
    assert!(tinted > 500, "only {tinted} pixels tinted");
    assert_eq!(bluer, 0, "the tint only adds orange");
}

/// `view --set` reaches every object, as `render --set` does, also on a look with no default
/// stack: the pedestal (object 2), which has no stack of its own, takes the red too.
#[test]
fn view_set_reaches_the_objects_render_set_reaches() {
    let Some(case) = Case::new() else { return };
    case.write("ball-only.toml", "[[object]]\nid = 1\n[[object.layer]]\npreset = \"gold\"\n");
    let set = ["--set", "base_color=0.9,0.1,0.1", "--seed", "3"];
    let output =
        case.view(&[&["ball-only.toml"][..], &set, &["--exit-after-spp", "4", "--screenshot", "shot.png"]].concat());
    assert_success(&output);
    let shot = case.screenshot_image(&output, "shot.png");
    let render = |out: &str, set: &[&str]| {
        let args = [
            &["render", "--gbuffer", "g.exr", "--look", "ball-only.toml", "--spp", "4", "--quiet"][..],
            set,
            &["--seed", "3", "--out", out],
        ]
        .concat();
        assert_success(&case.command(&args).output().unwrap());
        image::open(case.path(out)).unwrap().into_rgb8()
    };
    let with_set = render("set.png", &set[..2]);
    assert_matches_render(&shot, &with_set);
    assert_differs(&with_set, &render("plain.png", &[]), "--set on the stackless pedestal");
}

#[test]
fn a_scripted_edit_changes_the_image_and_is_saved_to_the_look() {
    let Some(case) = Case::new() else { return };
    case.write(
        "edit.script",
        "select 1 0\nset roughness 0.15\nset base_color 0.8, 0.1, 0.1\nadd chrome\nmask grunge\ninvert on\n\
         opacity 0.7\nsave-look edited.toml\n",
    );
    let output =
        case.view(&["look.toml", "--script", "edit.script", "--exit-after-spp", "4", "--screenshot", "shot.png"]);
    assert_success(&output);

    let original = Look::load(&case.path("look.toml")).unwrap();
    let edited = Look::load(&case.path("edited.toml")).unwrap();
    assert_eq!(std::fs::read_to_string(case.path("look.toml")).unwrap(), LOOK, "the opened look is untouched");
    let ball = edited.stack_for(1).unwrap();
    assert_eq!(ball.layers.len(), 3);
    let bottom = &ball.layers[0];
    assert_eq!(bottom.preset.as_deref(), Some("blue-rubber"));
    assert_eq!(bottom.params.get(Param::Roughness), Value::Scalar(0.15));
    assert_eq!(bottom.params.get(Param::BaseColor), Value::Color([0.8, 0.1, 0.1]));
    assert_eq!(bottom.overrides, vec![Param::BaseColor, Param::Roughness]);
    let added = &ball.layers[2];
    assert_eq!(added.preset.as_deref(), Some("chrome"));
    assert_eq!((added.mask.as_deref(), added.invert, added.opacity), (Some("grunge"), true, 0.7));
    assert!(added.overrides.is_empty());
    assert_eq!(ball.layers[1], original.stack_for(1).unwrap().layers[1], "the gold layer is as it was");
    assert_eq!(edited.stack_for(2), original.stack_for(2), "the pedestal is as it was");

    let shot = case.screenshot_image(&output, "shot.png");
    assert_matches_render(&shot, &case.render("edited.toml", 4, "edited.png"));
    assert_differs(&shot, &case.render("look.toml", 4, "original.png"), "edited vs original");
}

/// The case's g-buffer with maps: the colour map `tex` (a hue across the image) and the scalar
/// map `rough` (the grunge mask).
fn write_mapped_gbuffer(case: &Case) -> GBuffer {
    let mut gbuffer = GBuffer::shaderball(SIZE, SIZE);
    let n = gbuffer.pixel_count();
    let at = |i: usize| ((i as u32 % SIZE) as f32 / SIZE as f32, (i as u32 / SIZE) as f32 / SIZE as f32);
    gbuffer.maps.insert("tex.R".into(), (0..n).map(|i| at(i).0).collect());
    gbuffer.maps.insert("tex.G".into(), (0..n).map(|i| at(i).1).collect());
    gbuffer.maps.insert("tex.B".into(), (0..n).map(|i| 1.0 - at(i).0).collect());
    gbuffer.maps.insert("rough".into(), gbuffer.masks["grunge"].clone());
    gbuffer.write(&case.path("g.exr")).unwrap();
    GBuffer::read(&case.path("g.exr")).unwrap()
}

#[test]
fn scripted_map_bindings_undo_exactly_and_save_exactly_what_is_bound() {
    let Some(case) = Case::new() else { return };
    let gbuffer = write_mapped_gbuffer(&case);
    let ball = (0..gbuffer.pixel_count()).find(|&i| gbuffer.object_id[i] == 1 && gbuffer.coverage[i] == 1.0).unwrap();
    case.write(
        "bind.script",
        &format!(
            "select 1 0\nmap base_color tex\nmap roughness rough\nmap emission tex.G\nset emission 2,1,0.5\n\
             save-look all.toml\nundo\nundo\nsave-look two.toml\nmap roughness none\nsave-look one.toml\nundo\n\
             undo\nundo\nsave-look none.toml\nredo\nredo\nredo\nwait-spp 4\npick {} {}\n",
            ball as u32 % SIZE,
            ball as u32 / SIZE
        ),
    );
    let output =
        case.view(&["look.toml", "--script", "bind.script", "--exit-after-spp", "4", "--screenshot", "shot.png"]);
    assert_success(&output);
    let bound = |file: &str| -> Vec<(Param, String)> {
        let look = Look::load(&case.path(file)).unwrap();
        look.stack_for(1).unwrap().layers[0].maps.iter().map(|(p, m)| (*p, m.clone())).collect()
    };
    let pair = |p: Param, m: &str| (p, m.to_string());
    assert_eq!(
        bound("all.toml"),
        [pair(Param::BaseColor, "tex"), pair(Param::Roughness, "rough"), pair(Param::Emission, "tex.G")]
    );
    assert_eq!(bound("two.toml"), [pair(Param::BaseColor, "tex"), pair(Param::Roughness, "rough")]);
    assert_eq!(bound("one.toml"), [pair(Param::BaseColor, "tex")]);
    assert!(bound("none.toml").is_empty());
    let original = Look::load(&case.path("look.toml")).unwrap();
    let none = Look::load(&case.path("none.toml")).unwrap();
    assert_eq!(none.objects, original.objects, "undone back to the start, everything is as it was");
    let all = Look::load(&case.path("all.toml")).unwrap();
    assert_eq!(all.stack_for(1).unwrap().layers[0].params.emission, [2.0, 1.0, 0.5]);

    // Redone to `one`: the screenshot is that look's render, and the inspector shows the maps.
    let shot = case.screenshot_image(&output, "shot.png");
    assert_matches_render(&shot, &case.render("one.toml", 4, "one.png"));
    assert_differs(&shot, &case.render("none.toml", 4, "none.png"), "bound vs unbound");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let pick = stdout.lines().find(|l| l.starts_with("lookdev: pixel")).expect("the pick is reported");
    let tex_r = gbuffer.maps["tex.R"][ball];
    assert!(pick.contains(&format!("map.tex.R {tex_r:.4}")), "{pick}");
    assert!(pick.contains(&format!("map.rough {:.4}", gbuffer.maps["rough"][ball])), "{pick}");
}

#[test]
fn bindings_the_gbuffer_cannot_satisfy_stop_the_script_at_their_line() {
    let Some(case) = Case::new() else { return };
    write_mapped_gbuffer(&case);
    for (script, phrase) in [
        ("select 1 0\nmap roughness tex\n", "bad.script:2: map 'tex' of the g-buffer g.exr is a colour map"),
        (
            "select 1 0\n\nmap base_color texx\n",
            "bad.script:3: map 'texx' (bound to base_color) is not in the g-buffer",
        ),
        ("select 1 0\nmap shine tex\n", "bad.script:2: unknown parameter 'shine'"),
    ] {
        case.write("bad.script", script);
        let output = case.view(&["look.toml", "--script", "bad.script"]);
        assert_eq!(output.status.code(), Some(2), "{script}");
        let text = stderr(&output);
        assert!(text.contains(phrase) && !text.contains("panicked"), "{text}");
        assert_eq!(text.trim().lines().filter(|l| l.contains("error")).count(), 1, "{text}");
    }
}

/// `select` of an object the g-buffer lacks stops the script at that line, naming the objects
/// there are, rather than leaving nothing selected for the next line to trip over.
#[test]
fn selecting_an_object_the_gbuffer_lacks_stops_the_script_at_its_line() {
    let Some(case) = Case::new() else { return };
    case.write("select.script", "select 1 0\n\nselect 7\nset roughness 0.5\n");
    let output = case.view(&["look.toml", "--script", "select.script"]);
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
    let text = stderr(&output);
    assert!(
        text.contains("select.script:3: object 7 is not in the g-buffer g.exr (it has: 1 'ball', 2 'pedestal')"),
        "{text}"
    );
    assert!(!text.contains("panicked") && !text.contains("no layer is selected"), "{text}");
    assert_eq!(text.trim_end().lines().count(), 1, "one line: {text}");
}

#[test]
fn rotating_the_light_changes_the_image_and_leaves_the_materials_alone() {
    let Some(case) = Case::new() else { return };
    case.write("rotate.script", "rotate 120\nsave-look rotated.toml\n");
    let output =
        case.view(&["look.toml", "--script", "rotate.script", "--exit-after-spp", "4", "--screenshot", "shot.png"]);
    assert_success(&output);

    let original = Look::load(&case.path("look.toml")).unwrap();
    let rotated = Look::load(&case.path("rotated.toml")).unwrap();
    assert_eq!(rotated.environment.rotation, Some(120.0));
    assert_eq!(rotated.objects, original.objects, "a rotation changes no material");

    let shot = case.screenshot_image(&output, "shot.png");
    assert_matches_render(&shot, &case.render("rotated.toml", 4, "rotated.png"));
    assert_differs(&shot, &case.render("look.toml", 4, "original.png"), "rotated vs original");
}

#[test]
fn undo_restores_the_previous_state_and_redo_brings_it_back() {
    let Some(case) = Case::new() else { return };
    case.write(
        "undo.script",
        "select 1 1\nset roughness 0.9\nset metallic 0\nrotate 45\nundo\nundo\nundo\nredo\nsave-look undone.toml\n",
    );
    let output =
        case.view(&["look.toml", "--script", "undo.script", "--exit-after-spp", "4", "--screenshot", "shot.png"]);
    assert_success(&output);

    let original = Look::load(&case.path("look.toml")).unwrap();
    let undone = Look::load(&case.path("undone.toml")).unwrap();
    let gold = &undone.stack_for(1).unwrap().layers[1];
    assert_eq!(gold.params.get(Param::Roughness), Value::Scalar(0.9), "redone");
    let original_gold = &original.stack_for(1).unwrap().layers[1];
    assert_eq!(gold.params.get(Param::Metallic), original_gold.params.get(Param::Metallic), "undone");
    assert_eq!(undone.environment.rotation, Some(-90.0), "undone");

    let shot = case.screenshot_image(&output, "shot.png");
    assert_matches_render(&shot, &case.render("undone.toml", 4, "undone.png"));
}

#[test]
fn a_click_inspects_the_pixel_and_selects_its_object() {
    let Some(case) = Case::new() else { return };
    // As the viewer reads it: masks are stored as half floats.
    let gbuffer = GBuffer::read(&case.path("g.exr")).unwrap();
    let stripes = &gbuffer.masks["stripes"];
    let ball = half_striped_ball_pixel(&gbuffer);
    let pedestal =
        (0..gbuffer.pixel_count()).find(|&i| gbuffer.object_id[i] == 2 && gbuffer.coverage[i] == 1.0).unwrap();
    let xy = |i: usize| format!("{} {}", i as u32 % SIZE, i as u32 / SIZE);
    case.write(
        "pick.script",
        &format!(
            "wait-spp 4\npick {}\nset roughness 0.33\npick {}\nset sheen 0.5\nsave-look picked.toml\n",
            xy(ball),
            xy(pedestal)
        ),
    );
    let output = case.view(&["look.toml", "--script", "pick.script", "--exit-after-spp", "4"]);
    assert_success(&output);
    let stdout = String::from_utf8_lossy(&output.stdout);
    let picks: Vec<&str> = stdout.lines().filter(|l| l.starts_with("lookdev: pixel")).collect();
    assert_eq!(picks.len(), 2, "{stdout}");

    // The ball pixel: its object, its mask, the gold layer's weight, the blend, the radiance.
    let line = picks[0];
    let m = stripes[ball];
    assert!(
        line.contains(&format!("pixel {}: object 1 'ball', coverage 1.0000", xy(ball).replace(' ', ","))),
        "{line}"
    );
    assert!(line.contains(&format!("mask.stripes {m:.4}")), "{line}");
    assert!(line.contains(&format!("[1 gold blend {m:.4} share {m:.4}]")), "{line}");
    assert!(line.contains(&format!("[0 blue-rubber blend 1.0000 share {:.4}]", 1.0 - m)), "{line}");
    let look = Look::load(&case.path("look.toml")).unwrap();
    let layers = &look.stack_for(1).unwrap().layers;
    let expected = layers[0].params.metallic * (1.0 - m) + layers[1].params.metallic * m;
    let metallic: f32 = line.split(" metallic=").nth(1).and_then(|v| v.split(' ').next()).unwrap().parse().unwrap();
    // Printed to four decimals, for people.
    assert!((metallic - expected).abs() <= 5e-5, "the blended material: {line}");
    assert_radiance_is_rendered(&case, line, ball);

    // Each click selected the object under it: the ball's top layer got the roughness, and the
    // pedestal, which used the default stack, got a stack of its own with the sheen.
    let picked = Look::load(&case.path("picked.toml")).unwrap();
    assert_eq!(picked.stack_for(1).unwrap().layers[1].params.get(Param::Roughness), Value::Scalar(0.33));
    let pedestal_stack = picked.objects.iter().find(|o| o.id == Some(2)).expect("the pedestal has its own stack");
    assert_eq!(pedestal_stack.layers[0].params.get(Param::Sheen), Value::Scalar(0.5));
    let default = picked.objects.iter().find(|o| o.id.is_none()).unwrap();
    assert_eq!(default.layers[0].params.get(Param::Sheen), Value::Scalar(0.0), "the default stack is untouched");
}

/// The inspector follows the image: an edit and its undo change the blended material it shows,
/// and its radiance keeps up with the accumulation rather than staying at the pick's.
#[test]
fn the_inspector_follows_edits_undo_and_accumulation() {
    let Some(case) = Case::new() else { return };
    let gbuffer = GBuffer::read(&case.path("g.exr")).unwrap();
    let ball = half_striped_ball_pixel(&gbuffer);
    let xy = format!("{} {}", ball as u32 % SIZE, ball as u32 / SIZE);
    case.write(
        "inspect.script",
        &format!("wait-spp 1\npick {xy}\ninspect\nset roughness 0.9\ninspect\nundo\ninspect\nwait-spp 4\ninspect\n"),
    );
    let output = case.view(&["look.toml", "--script", "inspect.script", "--exit-after-spp", "4"]);
    assert_success(&output);
    let stdout = String::from_utf8_lossy(&output.stdout);
    let lines: Vec<&str> = stdout.lines().filter(|l| l.starts_with("lookdev: pixel")).collect();
    assert_eq!(lines.len(), 5, "{stdout}");
    let roughness = |line: &str| -> f32 {
        line.split(" roughness=").nth(1).and_then(|v| v.split(' ').next()).unwrap().parse().unwrap()
    };
    let (picked, edited, undone, converged) = (lines[1], lines[2], lines[3], lines[4]);
    assert!(roughness(edited) > roughness(picked) + 0.1, "the edit shows:\n{picked}\n{edited}");
    assert_eq!(roughness(undone), roughness(picked), "the undo shows:\n{picked}\n{undone}");

    // Converged, the inspector shows the 4-spp radiance that `lookdev render` gives.
    assert_radiance_is_rendered(&case, converged, ball);
}

/// Between the first pass and the target the inspector keeps up: passes after the first add
/// several samples each (1, 5, 9, …), stepping over the powers of two it was read back at, so
/// after a change it stayed at its 1-spp reading until the target.
#[test]
fn the_inspector_keeps_up_with_accumulation_after_a_change() {
    let Some(case) = Case::new() else { return };
    let gbuffer = GBuffer::read(&case.path("g.exr")).unwrap();
    let ball = half_striped_ball_pixel(&gbuffer);
    let xy = format!("{} {}", ball as u32 % SIZE, ball as u32 / SIZE);
    case.write("follow.script", &format!("wait-spp 1\npick {xy}\nrotate 30\nwait-spp 6\ninspect\n"));
    let output = case.view(&["look.toml", "--script", "follow.script", "--spp", "64", "--exit-after-spp", "64"]);
    assert_success(&output);
    let stdout = String::from_utf8_lossy(&output.stdout);
    let line = stdout.lines().filter(|l| l.starts_with("lookdev: pixel")).nth(1).expect("inspect printed");
    let spp: u32 = line.rsplit(" at ").next().and_then(|s| s.split(' ').next()).unwrap().parse().unwrap();
    assert!((4..64).contains(&spp), "the inspector read back at {spp} spp after 6 were reached:\n{line}");
}

/// The panels keep their width whatever their values' widths: a four- and five-digit emission
/// neither widens the layer panel nor moves or rescales the image.
#[test]
fn wide_values_move_neither_the_panels_nor_the_image() {
    let Some(case) = Case::new() else { return };
    let gbuffer = GBuffer::read(&case.path("g.exr")).unwrap();
    let ball = (0..gbuffer.pixel_count()).find(|&i| gbuffer.object_id[i] == 1 && gbuffer.coverage[i] == 1.0).unwrap();
    let xy = format!("{} {}", ball as u32 % SIZE, ball as u32 / SIZE);
    case.write(
        "wide.script",
        &format!(
            "zoom fit\nwait-spp 1\npick {xy}\nscreenshot narrow.png\nset emission 12345.5,6789.25,1000.125\nwait-spp 1\nscreenshot wide.png\n"
        ),
    );
    let output = case.view(&["look.toml", "--script", "wide.script", "--exit-after-spp", "1"]);
    assert_success(&output);
    assert_eq!(placement(&output, "narrow.png"), placement(&output, "wide.png"));
}

/// The scale a screenshot line reports the image at.
fn reported_scale(output: &Output, name: &str) -> f32 {
    placement(output, name).scale
}

/// Fit magnifies an image smaller than the view (a 160² g-buffer fills the middle of the
/// window), `1` shows it 1:1 and `F` fits it again: the hotkeys, typed by the script's `key`.
#[test]
fn fit_magnifies_a_small_image_and_the_zoom_keys_work() {
    let Some(case) = Case::new() else { return };
    case.write(
        "zoom.script",
        "zoom fit\nwait-spp 1\nscreenshot fit.png\nkey 1\nscreenshot one.png\nkey F\nscreenshot again.png\nzoom 2\nscreenshot two.png\n",
    );
    let output = case.view(&["look.toml", "--script", "zoom.script", "--exit-after-spp", "1"]);
    assert_success(&output);
    let fit = reported_scale(&output, "fit.png");
    assert!(fit > 1.2, "fit magnifies the 160² image to fill the view: scale {fit}");
    assert_eq!(reported_scale(&output, "one.png"), 1.0);
    assert_eq!(reported_scale(&output, "again.png"), fit);
    assert_eq!(reported_scale(&output, "two.png"), 2.0);
    let bad = case.command(&["view", "--gbuffer", "g.exr", "--zoom", "fitt"]).output().unwrap();
    let text = stderr(&bad);
    assert!(!bad.status.success() && text.contains("--zoom: zoom 'fitt' is neither 'fit' nor a scale"), "{text}");
}

/// Fitted, the image leaves the footer band (the hint line and the pixel readout) free even
/// where the view's height limits it, as with the side panels hidden: no text over the image.
#[test]
fn a_fitted_image_leaves_the_footer_free() {
    let Some(case) = Case::new() else { return };
    case.write("footer.script", "key H\nzoom fit\nwait-spp 1\nscreenshot fit.png\n");
    let output = case.view(&["look.toml", "--script", "footer.script", "--exit-after-spp", "1"]);
    assert_success(&output);
    let Placement { y, height, .. } = placement(&output, "fit.png");
    let window: f32 = WINDOW[1].parse().unwrap();
    // Under the image: the footer band (24 points) and the status bar (at least 18).
    assert!(window - (y + height) >= 24.0 + 18.0, "the image reaches {} of {window}", y + height);
}

/// A ball pixel inside the image, half in a stripe, so the gold layer's weight is telling.
fn half_striped_ball_pixel(gbuffer: &GBuffer) -> usize {
    let stripes = &gbuffer.masks["stripes"];
    (0..gbuffer.pixel_count())
        .filter(|&i| gbuffer.object_id[i] == 1 && gbuffer.coverage[i] == 1.0)
        .min_by(|&a, &b| (stripes[a] - 0.5).abs().total_cmp(&(stripes[b] - 0.5).abs()))
        .unwrap()
}

/// An inspector line at 4 spp shows the radiance `lookdev render` gives `pixel` of the case's
/// look at 4 spp.
fn assert_radiance_is_rendered(case: &Case, line: &str, pixel: usize) {
    assert!(line.ends_with("at 4 spp"), "{line}");
    let radiance: Vec<f32> = line
        .split("radiance ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let args = ["render", "--gbuffer", "g.exr", "--look", "look.toml", "--spp", "4", "--quiet", "--out", "r.exr"];
    assert_success(&case.command(&args).output().unwrap());
    let rendered = read_exr_pixel(&case.path("r.exr"), pixel);
    assert!(rendered[0] > 0.0, "a lit pixel");
    for c in 0..3 {
        assert!((radiance[c] - rendered[c]).abs() <= 1e-5 * rendered[c].abs().max(1.0), "{radiance:?} vs {rendered:?}");
    }
}

fn read_exr_pixel(path: &Path, index: usize) -> [f32; 3] {
    use exr::prelude::{read_first_rgba_layer_from_file, RgbaChannels};
    let image = read_first_rgba_layer_from_file(
        path,
        |resolution, _: &RgbaChannels| vec![[0.0f32; 3]; resolution.width() * resolution.height()],
        |pixels, position, (r, g, b, _a): (f32, f32, f32, f32)| {
            pixels[position.y() * SIZE as usize + position.x()] = [r, g, b];
        },
    )
    .unwrap();
    image.layer_data.channel_data.pixels[index]
}

#[test]
fn unsaved_edits_are_asked_about_before_closing() {
    let Some(case) = Case::new() else { return };
    // Cancel keeps the viewer open (the save after it runs); discard closes without saving.
    case.write(
        "close.script",
        "select 1 1\nset roughness 0.35\nquit\nanswer cancel\nsave-look kept.toml\nset roughness 0.4\nquit\nanswer discard\n",
    );
    let output = case.view(&["look.toml", "--script", "close.script"]);
    assert_success(&output);
    let kept = Look::load(&case.path("kept.toml")).unwrap();
    assert_eq!(kept.stack_for(1).unwrap().layers[1].params.get(Param::Roughness), Value::Scalar(0.35));

    // Save writes the look to its own file, then closes.
    std::fs::copy(case.path("look.toml"), case.path("mine.toml")).unwrap();
    case.write("save.script", "select 1 1\nset roughness 0.45\nquit\nanswer save\nset roughness 0.5\n");
    let output = case.view(&["mine.toml", "--script", "save.script"]);
    assert_success(&output);
    let saved = Look::load(&case.path("mine.toml")).unwrap();
    assert_eq!(saved.stack_for(1).unwrap().layers[1].params.get(Param::Roughness), Value::Scalar(0.45));
}

/// A script that raises the unsaved-edits question and does not answer it on the next line
/// stops with an error at the line that raised it, rather than waiting for an answer nobody
/// can give: by `quit`, by `open-look` with more lines after it, and by a key. A key's question
/// answered on the next line is answered.
#[test]
fn a_question_the_script_does_not_answer_is_an_error_at_its_line() {
    let Some(case) = Case::new() else { return };
    case.write("other.toml", "[[object]]\n[[object.layer]]\npreset = \"chrome\"\n");
    for script in [
        "select 1 1\nset roughness 0.37\nquit\n",
        "select 1 1\nset roughness 0.37\nopen-look other.toml\nset roughness 0.5\n",
        "select 1 1\nset roughness 0.37\nkey ctrl+Q\n",
    ] {
        case.write("ask.script", script);
        let output = case.view(&["look.toml", "--script", "ask.script"]);
        let text = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "{script}: {text}");
        assert!(text.contains("ask.script:3: ") && text.contains("answer discard"), "{script}: {text}");
        assert_eq!(text.trim().lines().count(), 1, "{text}");
    }
    case.write("answered.script", "select 1 1\nset roughness 0.37\nkey ctrl+Q\nanswer discard\n");
    assert_success(&case.view(&["look.toml", "--script", "answered.script"]));
}

#[test]
fn saving_never_corrupts_an_existing_look() {
    let Some(case) = Case::new() else { return };
    // A save the viewer refuses: in the other folder, "gold" would name that folder's own preset.
    let existing = "[[object]]\n[[object.layer]]\npreset = \"chrome\"\n";
    case.write("other/look.toml", existing);
    case.write(
        "other/gold.toml",
        "name = \"gold\"\ndescription = \"A folder's own gold.\"\ntags = [\"metal\"]\nbase_color = 0.5\nmetallic = 1.0\n",
    );
    case.write("refused.script", "select 1 1\nset roughness 0.2\nsave-look other/look.toml\n");
    let output = case.view(&["look.toml", "--script", "refused.script"]);
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
    let text = stderr(&output);
    assert!(text.contains("refused.script:3:") && text.contains("not saved"), "{text}");
    assert_eq!(std::fs::read_to_string(case.path("other/look.toml")).unwrap(), existing);

    // A viewer killed while saving over and over leaves a whole look, old or new, every time.
    let mut script = String::from("select 1 1\n");
    for i in 0..400 {
        script += &format!("set roughness {}\nsave-look look.toml\n", (i % 90) as f32 / 100.0 + 0.05);
    }
    case.write("saves.script", &script);
    let mut all = vec!["view", "look.toml", "--gbuffer", "g.exr", "--window-size", WINDOW[0], WINDOW[1]];
    all.extend(["--script", "saves.script"]);
    let mut child = case.command(&all).stdout(Stdio::null()).stderr(Stdio::null()).spawn().unwrap();
    let written = std::fs::metadata(case.path("look.toml")).unwrap().modified().unwrap();
    let start = Instant::now();
    while std::fs::metadata(case.path("look.toml")).unwrap().modified().unwrap() == written {
        assert!(start.elapsed() < HANG, "the viewer never saved");
        assert!(child.try_wait().unwrap().is_none(), "the viewer exited before saving");
        std::thread::sleep(Duration::from_millis(5));
    }
    std::thread::sleep(Duration::from_millis(150));
    child.kill().unwrap();
    child.wait().unwrap();
    let survivor = Look::load(&case.path("look.toml")).expect("the look file is whole");
    let roughness = survivor.stack_for(1).unwrap().layers[1].params.roughness;
    assert!((0.05..0.95).contains(&roughness), "{roughness}");
}

#[test]
fn script_and_display_problems_are_clear_errors() {
    let Some(case) = Case::new() else { return };
    // Found before any window opens.
    case.write("bad.script", "select 1 0\n\nfrobnicate 3\n");
    let output = case.view(&["look.toml", "--script", "bad.script"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(stderr(&output).contains("bad.script:3: unknown command 'frobnicate'"), "{}", stderr(&output));
    // Found while running: the line is named and the viewer stops.
    case.write("mask.script", "select 1 1\nmask nosuch\n");
    let output = case.view(&["look.toml", "--script", "mask.script"]);
    assert_eq!(output.status.code(), Some(2));
    let text = stderr(&output);
    assert!(text.contains("mask.script:2: the g-buffer has no mask 'nosuch'") && !text.contains("panicked"), "{text}");
    case.write("wait.script", "spp 100\nwait-spp 50\n");
    let output = case.view(&["--script", "wait.script", "--exit-after-spp", "2"]);
    assert_eq!(output.status.code(), Some(2));
    let text = stderr(&output);
    assert!(text.contains("wait.script:2: wait-spp 50 would never end: --exit-after-spp 2 stops the viewer"), "{text}");
    assert!(!text.contains("raise it with `spp"), "the script's spp is not what caps it: {text}");

    // No display, or one that cannot be reached.
    let output = case.command(&["view"]).env_remove("DISPLAY").output().unwrap();
    assert_eq!(output.status.code(), Some(1));
    let text = stderr(&output);
    assert!(text.contains("cannot open a window") && text.contains("xvfb") && !text.contains("panicked"), "{text}");
    let output = case.command(&["view"]).env("DISPLAY", ":4242").output().unwrap();
    assert_eq!(output.status.code(), Some(1));
    assert!(stderr(&output).contains("cannot open a window") && !stderr(&output).contains("panicked"));

    // No Vulkan driver.
    let output = case.command(&["view"]).env("VK_ICD_FILENAMES", "/nonexistent/icd.json").output().unwrap();
    assert_eq!(output.status.code(), Some(1));
    let text = stderr(&output);
    assert!(text.contains("mesa-vulkan-drivers") && !text.contains("panicked"), "{text}");
}

/// A start that fails part-way (`LOOKDEV_FAIL_AT` injects the failure) releases what it made:
/// with validation on, an object left alive is reported when its device or instance is destroyed.
#[test]
fn a_viewer_that_fails_while_starting_releases_what_it_made() {
    let Some(case) = Case::new() else { return };
    // Before the surface; after it (with and without a device); after the presenter's command
    // pool, command buffer and semaphore; after its swapchain.
    for step in ["surface", "device", "context-ready", "presenter-fence", "swapchain-view"] {
        let args = ["view", "--gbuffer", "g.exr", "--window-size", WINDOW[0], WINDOW[1]];
        let output = case.command(&args).env("LOOKDEV_FAIL_AT", step).output().unwrap();
        let text = stderr(&output);
        assert_eq!(output.status.code(), Some(1), "{step}: {text}");
        assert!(text.contains(&format!("injected failure at {step}")), "{step}: {text}");
        assert!(!text.contains("validation error") && !text.contains("panicked"), "{step}: {text}");
    }
}

#[test]
fn preset_thumbnails_render_once_and_are_kept_on_disk() {
    let ctx = common::gpu::context();
    let dir = tempfile::tempdir().unwrap();
    let gold = lookdev::material::library::builtin("gold").unwrap().params;
    let chrome = lookdev::material::library::builtin("chrome").unwrap().params;
    let first = {
        let mut thumbnails = Thumbnails::new(&ctx, Some(dir.path().to_path_buf())).unwrap();
        let mut may_render = true;
        let image = thumbnails.get(&gold, &mut may_render).unwrap().expect("rendered").clone();
        assert!(!may_render, "rendering one uses the frame's allowance");
        assert!(thumbnails.get(&chrome, &mut may_render).unwrap().is_none(), "one render per frame");
        image
    };
    assert_eq!(first.dimensions(), (thumbnails::SIZE, thumbnails::SIZE));
    assert!(dir.path().join(thumbnails::file_name(&gold)).is_file(), "kept on disk");
    // The ball's centre is gold: warm, and lit.
    let centre = first.get_pixel(thumbnails::SIZE / 2, thumbnails::SIZE * 2 / 5).0;
    assert!(centre[0] > centre[2] + 20 && centre[0] > 60, "{centre:?}");

    // A new session reads it back without rendering.
    let mut thumbnails = Thumbnails::new(&ctx, Some(dir.path().to_path_buf())).unwrap();
    let mut may_render = false;
    assert_eq!(thumbnails.get(&gold, &mut may_render).unwrap(), Some(&first));
    assert_ne!(thumbnails::file_name(&gold), thumbnails::file_name(&chrome));
    drop(thumbnails);
    common::gpu::finish(ctx);
}

/// Rows at the top of a split image that carry the halves' labels, and columns either side of
/// the divider line: left out when comparing halves with renders.
const LABEL_ROWS: u32 = 28;
const DIVIDER_MARGIN: u32 = 3;

/// The split column a screenshot report gives, and its labels.
fn split_of(output: &Output, name: &str) -> Option<(u32, String)> {
    let stdout = String::from_utf8_lossy(&output.stdout);
    let line = stdout.lines().find(|l| l.starts_with("lookdev: screenshot") && l.contains(name))?;
    let rest = line.split("; split at image column ").nth(1)?;
    let (column, labels) = rest.split_once(' ').unwrap();
    Some((column.parse().unwrap(), labels.to_string()))
}

/// The part of `image` in columns `columns`, below the label rows.
fn region(image: &RgbImage, columns: std::ops::Range<u32>) -> RgbImage {
    image::imageops::crop_imm(image, columns.start, LABEL_ROWS, columns.end - columns.start, SIZE - LABEL_ROWS)
        .to_image()
}

/// Left of the divider the shot is `a`, right of it `b`, each as `lookdev render` makes them.
fn assert_halves(shot: &RgbImage, column: u32, a: &RgbImage, b: &RgbImage) {
    let left = 0..column - DIVIDER_MARGIN;
    let right = column + DIVIDER_MARGIN..SIZE;
    assert_matches_render(&region(shot, left.clone()), &region(a, left.clone()));
    assert_matches_render(&region(shot, right.clone()), &region(b, right.clone()));
    // The halves are told apart: a swap, or B ignored, would fail the lines above.
    assert_differs(&region(a, right.clone()), &region(b, right), "B differs from A");
}

#[test]
fn the_split_view_shows_a_beside_another_model_and_each_half_matches_lookdev_render() {
    let Some(case) = Case::new() else { return };
    let mut seeded = Look::load(&case.path("look.toml")).unwrap();
    seeded.render.seed = Some(3);
    case.write("seeded.toml", &seeded.to_toml());
    let a = case.render("seeded.toml", 4, "a.png");
    let model = ["--model", "diffuse=lambert", "--model", "fresnel=conductor", "--model", "specular_d=beckmann"];
    let args = [["render", "--gbuffer", "g.exr", "--look", "seeded.toml", "--spp", "4", "--quiet"].as_slice(), &model]
        .concat();
    assert_success(&case.command(&[args.as_slice(), &["--out", "b.png"]].concat()).output().unwrap());
    let b = image::open(case.path("b.png")).unwrap().into_rgb8();

    // From the command line, the divider moved by the script; then off, back to the plain image.
    case.write(
        "split.script",
        "divider 0.3\nwait-spp 4\nscreenshot third.png\ndivider 0.5\nwait-spp 4\nscreenshot half.png\n\
         compare off\nwait-spp 4\nscreenshot off.png\n",
    );
    let flags = ["--compare-model", "diffuse=lambert", "--compare-model", "fresnel=conductor"];
    let mut view = vec!["seeded.toml", "--script", "split.script", "--exit-after-spp", "4"];
    view.extend(flags);
    view.extend(["--compare-model", "specular_d=beckmann"]);
    let output = case.view(&view);
    assert_success(&output);
    let (column, labels) = split_of(&output, "half.png").expect("the split is reported");
    assert_eq!(column, SIZE / 2);
    assert!(
        labels.contains("A: default") && labels.contains("B: diffuse=lambert specular_d=beckmann fresnel=conductor"),
        "{labels}"
    );
    assert_halves(&case.screenshot_image(&output, "half.png"), column, &a, &b);
    let (third, _) = split_of(&output, "third.png").unwrap();
    assert_eq!(third, 48);
    assert_halves(&case.screenshot_image(&output, "third.png"), third, &a, &b);
    assert!(split_of(&output, "off.png").is_none(), "compare off ends the split");
    assert_matches_render(&case.screenshot_image(&output, "off.png"), &a);

    // From a script, and swapped: A takes B's model, B A's.
    case.write(
        "swap.script",
        "compare model diffuse=lambert fresnel=conductor specular_d=beckmann\ncompare swap\ndivider 0.5\n",
    );
    let output =
        case.view(&["seeded.toml", "--script", "swap.script", "--exit-after-spp", "4", "--screenshot", "s.png"]);
    assert_success(&output);
    let (column, labels) = split_of(&output, "s.png").unwrap();
    assert!(labels.starts_with("(A: diffuse=lambert") && labels.contains("B: default"), "{labels}");
    assert_halves(&case.screenshot_image(&output, "s.png"), column, &b, &a);
}

/// Right after a split starts, B has not finished a pass: B's half shows A's own pixels (never
/// B's image before its first pass, which held whatever its memory held), and A's half is A.
#[test]
fn until_b_finishes_a_pass_its_half_of_the_split_shows_a() {
    let Some(case) = Case::new() else { return };
    let a = case.render("look.toml", 2, "a.png");
    case.write("early.script", "wait-spp 2\ncompare model diffuse=lambert\nscreenshot early.png\n");
    let output = case.view(&["look.toml", "--script", "early.script", "--exit-after-spp", "2"]);
    assert_success(&output);
    let (column, labels) = split_of(&output, "early.png").expect("the split is reported");
    assert!(labels.contains("B: diffuse=lambert"), "{labels}");
    let shot = case.screenshot_image(&output, "early.png");
    let left = 0..column - DIVIDER_MARGIN;
    let right = column + DIVIDER_MARGIN..SIZE;
    assert_matches_render(&region(&shot, left.clone()), &region(&a, left));
    assert_matches_render(&region(&shot, right.clone()), &region(&a, right));
}

/// Each side's relight kernel is compiled once, for its own look's lobes: B's look (chrome and
/// red plastic) has no clear coat, and its renderer compiled the kernel for every lobe first.
#[test]
fn each_side_of_the_split_compiles_its_relight_kernel_once() {
    let Some(case) = Case::new() else { return };
    case.write("b.toml", "[[object]]\n[[object.layer]]\npreset = \"red-plastic\"\n\n[[object]]\nid = 1\n[[object.layer]]\npreset = \"chrome\"\n");
    let args = ["look.toml", "--compare-look", "b.toml", "--exit-after-spp", "1", "--screenshot", "shot.png"];
    let output = case.view_with_env(&args, &[("LOOKDEV_TIMINGS", "1")]);
    assert_success(&output);
    let stderr = String::from_utf8_lossy(&output.stderr);
    let compiles = stderr.lines().filter(|l| l.contains("timing: pipeline relight ")).count();
    assert_eq!(compiles, 2, "{stderr}");
}

#[test]
fn the_split_view_shows_a_beside_another_look_under_the_same_light() {
    let Some(case) = Case::new() else { return };
    // B: chrome ball, lambert pedestal, its own model; A's seed, rotation and spp apply to both.
    case.write(
        "b.toml",
        "[model]\ndiffuse = \"lambert\"\n\n[[object]]\n[[object.layer]]\npreset = \"red-plastic\"\n\n\
         [[object]]\nid = 1\n[[object.layer]]\npreset = \"chrome\"\n",
    );
    case.write("split.script", "rotate 40\nwait-spp 4\n");
    let output = case.view(&[
        "look.toml",
        "--compare-look",
        "b.toml",
        "--seed",
        "5",
        "--script",
        "split.script",
        "--exit-after-spp",
        "4",
        "--screenshot",
        "shot.png",
    ]);
    assert_success(&output);
    let (column, labels) = split_of(&output, "shot.png").expect("the split is reported");
    assert!(labels.contains("A: look.toml") && labels.contains("B: b.toml · diffuse=lambert"), "{labels}");
    let lit = |name: &str, text: &str| {
        let mut look = Look::load(&case.path(text)).unwrap();
        look.render.seed = Some(5);
        look.environment.rotation = Some(40.0);
        case.write(name, &look.to_toml());
        case.render(name, 4, &format!("{name}.png"))
    };
    let a = lit("a.toml", "look.toml");
    let b = lit("b-lit.toml", "b.toml");
    assert_halves(&case.screenshot_image(&output, "shot.png"), column, &a, &b);
}

#[test]
fn bad_compare_inputs_are_one_line_errors() {
    let Some(case) = Case::new() else { return };
    case.write("broken.toml", "[[object]\n");
    for (args, expected) in [
        (vec!["look.toml", "--compare-look", "missing.toml"], "missing.toml"),
        (vec!["look.toml", "--compare-look", "broken.toml"], "broken.toml"),
        (vec!["look.toml", "--compare-model", "diffuse=lamber"], "--compare-model diffuse=lamber"),
        (vec!["look.toml", "--compare-model", "gtr_gamma"], "--compare-model gtr_gamma: expected KEY=VALUE"),
    ] {
        let output = case.view(&args);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {}", stderr(&output));
        let text = stderr(&output);
        assert!(text.contains(expected) && !text.contains("panicked"), "{args:?}: {text}");
        assert_eq!(text.trim_end().lines().count(), 1, "one line: {text}");
    }
    // A mask B's look needs and the g-buffer lacks, found before the window opens.
    case.write("masked.toml", "[[object]]\n[[object.layer]]\npreset = \"gold\"\nmask = \"nosuch\"\n");
    let output = case.view(&["look.toml", "--compare-look", "masked.toml"]);
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
    assert!(stderr(&output).contains("nosuch"), "{}", stderr(&output));
    // While running, a script's bad look names the line.
    case.write("bad.script", "compare look missing.toml\n");
    let output = case.view(&["look.toml", "--script", "bad.script"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("bad.script:1:") && stderr(&output).contains("missing.toml"),
        "{}",
        stderr(&output)
    );
}

/// The preset library docks beside the layer stack rather than over the image: opened with
/// Ctrl+Shift+N it moves the image over by its width, and Escape closes it and gives the room
/// back. (A window over the image would move nothing.)
#[test]
fn the_preset_library_docks_beside_the_stack_and_escape_closes_it() {
    let Some(case) = Case::new() else { return };
    case.write(
        "library.script",
        "zoom fit\nwait-spp 1\nscreenshot closed.png\nkey ctrl+shift+N\nwait-spp 1\nscreenshot open.png\n\
         key Escape\nwait-spp 1\nscreenshot again.png\n",
    );
    let output = case.view(&["look.toml", "--script", "library.script", "--exit-after-spp", "1"]);
    assert_success(&output);
    let left = |name: &str| placement(&output, name).x;
    let (closed, open, again) = (left("closed.png"), left("open.png"), left("again.png"));
    // The layer stack's panel is 400 points wide; the library, one thumbnail column at least.
    assert!(open >= 400.0 + 96.0, "the image starts at {open} with the library open");
    assert!(open > closed);
    assert_eq!(again, closed, "closed, the library gives the room back");
}
