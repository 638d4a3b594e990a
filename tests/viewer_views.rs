//! The viewer's views and exposure tools, under a virtual X server with validation on: a
//! parameter view shows its value exactly, a mask view its mask, false colour puts a known
//! radiance in its band, `C` cycles the views and `M` returns to the beauty, object ids have
//! distinct colours, `probe` gives the values `lookdev render --aov` writes, the clipping
//! overlay marks what clips, and an unknown view is a clear error.
#![cfg(feature = "viewer")]

mod common;

use common::viewer::*;
use image::RgbImage;
use lookdev::gbuffer::GBuffer;
use lookdev::render::aov::id_colour;
use lookdev::viewer::views::{value_byte, CLIPPED, CRUSHED, FALSE_COLOURS};
use std::process::Output;

/// Roughness 0.37 on every layer of every stack: the roughness view is 0.37 wherever covered.
const CONSTANT_ROUGHNESS: &str = r#"
[[object]]
[[object.layer]]
preset = "white-ceramic"
[object.layer.set]
roughness = 0.37

[[object]]
id = 1
[[object.layer]]
preset = "blue-rubber"
[object.layer.set]
roughness = 0.37
[[object.layer]]
preset = "gold"
mask = "stripes"
[object.layer.set]
roughness = 0.37
"#;

/// No light, and an emission of 0.72 (two stops over 18% grey) everywhere: the radiance of
/// every covered pixel is exactly 0.72, the background's 0.
const EMISSIVE: &str = r#"
[environment]
intensity = 0.0

[[object]]
[[object.layer]]
preset = "white-ceramic"
[object.layer.set]
emission = [0.72, 0.72, 0.72]
"#;

fn gbuffer(case: &Case) -> GBuffer {
    // As the viewer reads it: masks are stored as half floats.
    GBuffer::read(&case.path("g.exr")).unwrap()
}

fn pixel(image: &RgbImage, p: usize) -> [u8; 3] {
    image.get_pixel(p as u32 % SIZE, p as u32 / SIZE).0
}

fn near(a: [u8; 3], b: [u8; 3]) -> bool {
    a.iter().zip(&b).all(|(x, y)| x.abs_diff(*y) <= 1)
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// The probe lines a run printed, in order.
fn probes(output: &Output) -> Vec<String> {
    stdout(output).lines().filter(|l| l.starts_with("lookdev: view ")).map(str::to_string).collect()
}

#[test]
fn a_parameter_view_shows_the_value_exactly() {
    let Some(case) = Case::new() else { return };
    case.write("rough.toml", CONSTANT_ROUGHNESS);
    case.write(
        "view.script",
        "view roughness\nwait-spp 1\nscreenshot rough.png\nselect 1 0\nset base_color 0.5,0.2159,0\nselect 1 1\n\
         hide\nview base_color\nwait-spp 1\nscreenshot colour.png\n",
    );
    let output = case.view(&["rough.toml", "--script", "view.script", "--exit-after-spp", "1"]);
    assert_success(&output);
    let g = gbuffer(&case);
    let rough = case.screenshot_image(&output, "rough.png");
    let expected = value_byte(0.37);
    assert_eq!(expected, 94);
    let covered: Vec<usize> = (0..g.pixel_count()).filter(|&p| g.coverage[p] > 0.0).collect();
    assert!(covered.len() > 5000, "the ball and pedestal cover the image");
    for &p in &covered {
        assert!(near(pixel(&rough, p), [expected; 3]), "pixel {p}: {:?}, not {expected}", pixel(&rough, p));
    }
    for p in (0..g.pixel_count()).filter(|&p| g.coverage[p] == 0.0) {
        assert!(near(pixel(&rough, p), [0; 3]), "background pixel {p}: {:?}", pixel(&rough, p));
    }
    // A colour shows as a colour, sRGB-encoded: linear (0.5, 0.2159, 0) is (188, 128, 0). The
    // ball's gold layer is hidden, so its bottom layer's colour is the ball's.
    let colour = case.screenshot_image(&output, "colour.png");
    let ball: Vec<usize> = covered.iter().copied().filter(|&p| g.object_id[p] == 1).collect();
    for &p in &ball {
        assert!(near(pixel(&colour, p), [188, 128, 0]), "ball pixel {p}: {:?}", pixel(&colour, p));
    }
}

#[test]
fn a_mask_view_is_the_mask() {
    let Some(case) = Case::new() else { return };
    case.write("mask.script", "view mask.stripes\nwait-spp 1\nscreenshot mask.png\n");
    let output = case.view(&["look.toml", "--script", "mask.script", "--exit-after-spp", "1"]);
    assert_success(&output);
    let g = gbuffer(&case);
    let shot = case.screenshot_image(&output, "mask.png");
    let stripes = &g.masks["stripes"];
    let (mut striped, mut plain) = (0, 0);
    for p in (0..g.pixel_count()).filter(|&p| g.coverage[p] == 1.0) {
        let expected = value_byte(stripes[p]);
        assert!(near(pixel(&shot, p), [expected; 3]), "pixel {p}: {:?}, mask {}", pixel(&shot, p), stripes[p]);
        if stripes[p] > 0.9 {
            striped += 1;
        } else if stripes[p] < 0.1 {
            plain += 1;
        }
    }
    assert!(striped > 500 && plain > 500, "the mask has both: {striped} striped, {plain} plain");
}

#[test]
fn false_colour_puts_a_known_radiance_in_its_band() {
    let Some(case) = Case::new() else { return };
    case.write("emissive.toml", EMISSIVE);
    case.write(
        "false.script",
        "key E\nzoom 1\nwait-spp 1\nprobe 80 80\nscreenshot f0.png\nexposure 1\nwait-spp 1\nscreenshot f1.png\n\
         key E\nzoom 1\nprobe 80 80\n",
    );
    let output = case.view(&["emissive.toml", "--script", "false.script", "--exit-after-spp", "1"]);
    assert_success(&output);
    let g = gbuffer(&case);
    let band = |label: &str| FALSE_COLOURS.iter().find(|(_, l)| *l == label).unwrap().0;
    let (f0, f1) = (case.screenshot_image(&output, "f0.png"), case.screenshot_image(&output, "f1.png"));
    let full: Vec<usize> = (0..g.pixel_count()).filter(|&p| g.coverage[p] == 1.0).collect();
    for &p in &full {
        assert_eq!(pixel(&f0, p), band("+2"), "0.72 is two stops over 18% grey, at pixel {p}");
        assert_eq!(pixel(&f1, p), band("+3"), "after one stop of exposure, at pixel {p}");
    }
    for p in (0..g.pixel_count()).filter(|&p| g.coverage[p] == 0.0) {
        assert_eq!(pixel(&f0, p), band("<−5"), "black is below the bands, at pixel {p}");
    }
    // E toggles: false colour, then back to the beauty.
    let probes = probes(&output);
    assert_eq!(probes.len(), 2, "{}", stdout(&output));
    assert!(
        probes[0].starts_with("lookdev: view falsecolor pixel 80,80 linear 0.720000,0.720000,0.720000"),
        "{}",
        probes[0]
    );
    assert!(probes[1].starts_with("lookdev: view beauty pixel 80,80"), "{}", probes[1]);
}

#[test]
fn c_cycles_the_views_and_m_returns_to_the_beauty() {
    let Some(case) = Case::new() else { return };
    case.write(
        "cycle.script",
        "wait-spp 2\nscreenshot start.png\nkey C\nzoom 1\nwait-spp 2\nprobe 80 80\nscreenshot diffuse.png\nkey C\nzoom 1\n\
         probe 80 80\nkey shift+C\nzoom 1\nprobe 80 80\nkey M\nzoom 1\nwait-spp 2\nprobe 80 80\nkey shift+C\nzoom 1\n\
         probe 80 80\nkey M\nzoom 1\nwait-spp 2\nscreenshot beauty.png\n",
    );
    let output = case.view(&["look.toml", "--script", "cycle.script", "--exit-after-spp", "2"]);
    assert_success(&output);
    let names: Vec<String> = probes(&output).iter().map(|l| l.split_whitespace().nth(2).unwrap().to_string()).collect();
    assert_eq!(names, ["diffuse", "specular", "diffuse", "beauty", "falsecolor"], "{}", stdout(&output));
    let render = case.render("look.toml", 2, "render.png");
    assert_matches_render(&case.screenshot_image(&output, "start.png"), &render);
    assert_matches_render(&case.screenshot_image(&output, "beauty.png"), &render);
    assert_differs(&case.screenshot_image(&output, "diffuse.png"), &render, "the diffuse view");
}

#[test]
fn object_ids_show_as_distinct_stable_colours() {
    let Some(case) = Case::new() else { return };
    case.write("ids.script", "view objectId\nwait-spp 1\nscreenshot ids.png\n");
    let output = case.view(&["look.toml", "--script", "ids.script", "--exit-after-spp", "1"]);
    assert_success(&output);
    let g = gbuffer(&case);
    let shot = case.screenshot_image(&output, "ids.png");
    for p in (0..g.pixel_count()).filter(|&p| g.coverage[p] == 1.0) {
        assert!(near(pixel(&shot, p), id_colour(g.object_id[p])), "pixel {p} of object {}", g.object_id[p]);
    }
    assert_ne!(id_colour(1), id_colour(2));
    for p in (0..g.pixel_count()).filter(|&p| g.coverage[p] == 0.0 && g.object_id[p] == 0) {
        assert!(near(pixel(&shot, p), [0; 3]), "background pixel {p}");
    }
}

/// `probe` prints the values `lookdev render --aov` writes at that pixel: a parameter, a light
/// AOV at the same spp and seed, and a mask; and the display bytes the view shows.
#[test]
fn probe_gives_the_values_render_writes_as_aovs() {
    let Some(case) = Case::new() else { return };
    let g = gbuffer(&case);
    let ball = (0..g.pixel_count())
        .filter(|&p| g.object_id[p] == 1 && g.coverage[p] == 1.0)
        .min_by(|&a, &b| (g.masks["stripes"][a] - 0.5).abs().total_cmp(&(g.masks["stripes"][b] - 0.5).abs()))
        .unwrap();
    let (x, y) = (ball as u32 % SIZE, ball as u32 / SIZE);
    case.write(
        "probe.script",
        &format!(
            "view roughness\nprobe {x} {y}\nview diffuse\nwait-spp 4\nprobe {x} {y}\nview mask.stripes\nprobe {x} {y}\n\
             view layers_ball_1_gold\nprobe {x} {y}\nview N\nprobe {x} {y}\n"
        ),
    );
    let output = case.view(&["look.toml", "--script", "probe.script", "--exit-after-spp", "4"]);
    assert_success(&output);
    let probes = probes(&output);
    assert_eq!(probes.len(), 5, "{}", stdout(&output));
    let aovs = ["roughness", "diffuse", "masks", "layers", "N"].map(|a| ["--aov", a]).concat();
    let args = [
        &["render", "--gbuffer", "g.exr", "--look", "look.toml", "--spp", "4", "--quiet", "--out", "r.exr"][..],
        &aovs,
    ]
    .concat();
    assert_success(&case.command(&args).output().unwrap());
    let exr = exr::prelude::read_all_flat_layers_from_file(case.path("r.exr")).unwrap();
    let channel = |name: &str| -> f32 {
        let layer = &exr.layer_data[0];
        let channel = layer.channel_data.list.iter().find(|c| c.name.to_string() == name);
        channel.unwrap_or_else(|| panic!("no channel {name}")).sample_data.values_as_f32().nth(ball).unwrap()
    };
    for (line, layer, channels) in [
        (&probes[0], "param_roughness", &["Y"][..]),
        (&probes[1], "diffuse", &["R", "G", "B"][..]),
        (&probes[2], "mask_stripes", &["Y"][..]),
        (&probes[3], "layers_ball_1_gold", &["Y"][..]),
        (&probes[4], "N", &["R", "G", "B"][..]),
    ] {
        let linear: Vec<f32> = line
            .split(" linear ")
            .nth(1)
            .unwrap()
            .split(' ')
            .next()
            .unwrap()
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(linear.len(), channels.len(), "{line}");
        for (value, c) in linear.iter().zip(channels) {
            let expected = channel(&format!("{layer}.{c}"));
            assert!((value - expected).abs() <= 1e-5 * expected.abs().max(1.0), "{line}: {layer}.{c} is {expected}");
        }
        assert!(line.contains(&format!("pixel {x},{y} ")), "{line}");
    }
    let roughness: f32 = probes[0].split(" linear ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    let byte = value_byte(roughness);
    assert!(probes[0].ends_with(&format!("display {byte},{byte},{byte}")), "{}", probes[0]);
    // N shows as 0.5·(n + 1) by the value rule, as a normal map stores it.
    let n = g.normal[ball].map(|c| value_byte(0.5 * (c + 1.0)));
    assert!(probes[4].ends_with(&format!("display {},{},{}", n[0], n[1], n[2])), "{}", probes[4]);
}

#[test]
fn the_clipping_overlay_marks_what_clips_and_what_is_crushed() {
    let Some(case) = Case::new() else { return };
    case.write("emissive.toml", EMISSIVE);
    case.write(
        "clip.script",
        "wait-spp 1\nkey X\nzoom 1\nscreenshot c0.png\nexposure 10\nwait-spp 1\nscreenshot c10.png\nclipping off\n\
         wait-spp 1\nscreenshot off.png\n",
    );
    let output = case.view(&["emissive.toml", "--script", "clip.script", "--exit-after-spp", "1"]);
    assert_success(&output);
    let g = gbuffer(&case);
    let (c0, c10, off) = (
        case.screenshot_image(&output, "c0.png"),
        case.screenshot_image(&output, "c10.png"),
        case.screenshot_image(&output, "off.png"),
    );
    let full: Vec<usize> = (0..g.pixel_count()).filter(|&p| g.coverage[p] == 1.0).collect();
    let background: Vec<usize> = (0..g.pixel_count()).filter(|&p| g.coverage[p] == 0.0).collect();
    for &p in &full {
        let shown = pixel(&c0, p);
        assert!(shown != CLIPPED && shown != CRUSHED && shown[0] > 150, "0.72 neither clips nor is crushed: {shown:?}");
        assert_eq!(pixel(&c10, p), CLIPPED, "0.72 at +10 stops clips, at pixel {p}");
        assert!(
            near(pixel(&off, p), [255; 3]),
            "with the overlay off the clipped pixel is white: {:?}",
            pixel(&off, p)
        );
    }
    for &p in &background {
        assert_eq!(pixel(&c0, p), CRUSHED, "the black background is crushed, at pixel {p}");
        assert!(near(pixel(&off, p), [0; 3]), "with the overlay off it is black");
    }
}

#[test]
fn an_unknown_view_stops_the_script_with_a_suggestion() {
    let Some(case) = Case::new() else { return };
    case.write("bad.script", "wait-spp 1\n\nview roughnes\n");
    let output = case.view(&["look.toml", "--script", "bad.script"]);
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
    let text = stderr(&output);
    assert!(text.contains("bad.script:3: unknown view 'roughnes'"), "{text}");
    assert!(text.contains("did you mean 'roughness'?") && !text.contains("panicked"), "{text}");
}

#[test]
fn switching_the_visibility_off_shows_the_render_without_it_and_back() {
    let Some(case) = Case::new() else { return };
    case.write(
        "visibility.script",
        &format!(
            "visibility off\nwait-spp 4\nsave-image off.exr\nvisibility on\nwait-spp 4\nsave-image on.exr\npick {} {}\n",
            SIZE / 2,
            SIZE / 2
        ),
    );
    let output = case.view(&["--script", "visibility.script", "--exit-after-spp", "4"]);
    assert_success(&output);
    // The inspector gives the pixel's share of sky, as the occlusion AOV does.
    let stdout = String::from_utf8_lossy(&output.stdout);
    let pick = stdout.lines().find(|l| l.starts_with("lookdev: pixel")).expect("the pick is reported");
    let occlusion: f32 = pick.split(", occlusion ").nth(1).expect(pick)[..6].parse().unwrap();
    assert!((0.0..=1.0).contains(&occlusion), "{pick}");
    for (image, flags) in [("off", &["--no-visibility"][..]), ("on", &[][..])] {
        let out = format!("{image}-render.exr");
        let mut args = vec!["render", "--gbuffer", "g.exr", "--spp", "4", "--quiet", "--out", &out];
        args.extend(flags);
        assert_success(&case.command(&args).output().unwrap());
        assert!(
            case.exr_bits(&format!("{image}.exr")) == case.exr_bits(&out),
            "{image}: the render's pixels, bit for bit"
        );
    }
    assert!(case.exr_bits("off.exr") != case.exr_bits("on.exr"), "the shader ball's shadows change its image");
}

#[test]
fn a_shadow_catcher_is_toggled_saved_and_undone_as_render_shows_it() {
    let Some(case) = Case::new() else { return };
    case.write(
        "catcher.script",
        "select 2\ncatcher on\nwait-spp 4\nsave-image caught.exr\nsave-look caught.toml\nundo\nwait-spp 4\n\
         save-image plain.exr\n",
    );
    let output = case.view(&["--script", "catcher.script", "--exit-after-spp", "4"]);
    assert_success(&output);
    let saved = std::fs::read_to_string(case.path("caught.toml")).unwrap();
    assert!(saved.contains("id = 2\nshadow_catcher = true\n"), "{saved}");
    for (image, look) in [("caught", Some("caught.toml")), ("plain", None)] {
        let out = format!("{image}-render.exr");
        let mut args = vec!["render", "--gbuffer", "g.exr", "--spp", "4", "--quiet", "--out", &out];
        args.extend(look.map(|l| ["--look", l]).iter().flatten());
        assert_success(&case.command(&args).output().unwrap());
        assert!(
            case.exr_bits(&format!("{image}.exr")) == case.exr_bits(&out),
            "{image}: the render's pixels, bit for bit"
        );
    }
    assert!(case.exr_bits("caught.exr") != case.exr_bits("plain.exr"), "catching shadows changes the image");
}
