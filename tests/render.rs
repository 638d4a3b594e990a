//! The relight engine against references: furnace renders against integrated albedo, the GPU
//! kernel against its CPU mirror pixel by pixel, GPU resolve and display against the Rust
//! blending and tone maps, and determinism.

mod common;

use common::scenes::{look, orthographic_sphere, renderer};
use glam::Vec3;
use lookdev::environment::Environment;
use lookdev::gbuffer::GBuffer;
use lookdev::material::stack::PackedStacks;
use lookdev::material::{Look, Params};
use lookdev::render::Lighting;
use lookdev::shading::tonemap::{self, Tonemap};
use std::path::Path;

fn one_material_look(params: &Params) -> Look {
    let mut look = Look::default_material();
    look.objects[0].layers[0].params = *params;
    look
}

/// A white furnace: a sphere under a uniform environment of radiance 1 shows, at every pixel,
/// the directional albedo of that pixel's view angle (in that pixel's own shading frame).
#[test]
fn furnace_matches_integrated_albedo() {
    let ctx = common::gpu::context();
    let env = Environment::uniform([1.0; 3], 64, 32);
    let size = 32;
    let gbuffer = orthographic_sphere(size);
    let spp = 2048;
    let materials = [
        ("white dielectric, roughness 0.5", Params { base_color: [1.0; 3], ..Params::default() }),
        (
            "white metal, roughness 1",
            Params { base_color: [1.0; 3], metallic: 1.0, roughness: 1.0, ..Params::default() },
        ),
        (
            "metal, roughness 0.2",
            Params { base_color: [0.9, 0.6, 0.3], metallic: 1.0, roughness: 0.2, ..Params::default() },
        ),
        (
            "coat, sheen, subsurface, anisotropy",
            Params {
                base_color: [0.5, 0.3, 0.2],
                subsurface: 0.6,
                roughness: 0.4,
                anisotropic: 0.7,
                sheen: 1.0,
                clearcoat: 1.0,
                clearcoat_gloss: 0.7,
                ..Params::default()
            },
        ),
    ];
    for (name, params) in materials {
        let mut r = renderer(&ctx, &gbuffer, &env, &one_material_look(&params), Lighting::default());
        lookdev::render::progressive::accumulate(&mut r, spp, |_| {}).unwrap();
        let radiance = r.read_radiance().unwrap();
        let (mut worst, mut sum_error, mut count) = (0.0f64, 0.0f64, 0);
        // Every third pixel along the diagonal and the middle row: all view angles, both frames.
        let pixels: Vec<(u32, u32)> =
            (0..size).step_by(3).map(|i| (i, i)).chain((0..size).step_by(3).map(|i| (i, size / 2))).collect();
        for (x, y) in pixels {
            let i = (y * size + x) as usize;
            if gbuffer.coverage[i] < 1.0 {
                continue;
            }
            let frame =
                lookdev::shading::frame::Frame::new(Vec3::from(gbuffer.normal[i]), Vec3::from(gbuffer.tangent[i]));
            let v = frame.to_local(Vec3::from(gbuffer.view[i]));
            let expected = common::albedo::directional_albedo_at(&params, [v.x as f64, v.y as f64, v.z as f64]);
            for c in 0..3 {
                let got = radiance[i][c] as f64;
                let error = (got - expected[c]).abs() / expected[c].max(0.05);
                worst = worst.max(error);
                sum_error += error;
                count += 1;
                assert!(
                    error < 0.01,
                    "{name}: pixel ({x}, {y}) channel {c}, view {v}: rendered {got:.4}, integrated {:.4}",
                    expected[c]
                );
            }
        }
        eprintln!(
            "{name}: worst {:.3}%, mean {:.3}% over {count} values",
            worst * 100.0,
            sum_error / count as f64 * 100.0
        );
        assert!(sum_error / (count as f64) < 0.002, "{name}: mean error {}", sum_error / count as f64);
    }
    // The closed form at the centre pixel: a white metal of roughness 1 seen head-on reflects 1 − ln 2.
    let params = Params { base_color: [1.0; 3], metallic: 1.0, roughness: 1.0, ..Params::default() };
    let mut r = renderer(&ctx, &gbuffer, &env, &one_material_look(&params), Lighting::default());
    lookdev::render::progressive::accumulate(&mut r, 4096, |_| {}).unwrap();
    let centre = r.read_radiance().unwrap()[((size / 2) * size + size / 2) as usize];
    let v_centre = Vec3::from(gbuffer.normal[((size / 2) * size + size / 2) as usize]).z;
    assert!(v_centre > 0.998);
    assert!((centre[1] as f64 - (1.0 - 2f64.ln())).abs() < 0.01, "centre {centre:?}");
    drop(r);
    common::gpu::finish(ctx);
}

fn shaderball_scene(size: u32) -> (GBuffer, Look, PackedStacks) {
    let gbuffer = GBuffer::shaderball(size, size);
    let look = Look::builtin_default();
    let ids = lookdev::render::scene::covered_object_ids(&gbuffer);
    let stacks = PackedStacks::pack(&look, ids, &gbuffer, Path::new("shader ball")).unwrap();
    (gbuffer, look, stacks)
}

/// The shader ball with maps: a colour map `tex` whose hue changes across the image, a scalar
/// map `rough` from the grunge mask; and a look that binds them on a bottom layer, through a
/// striped gold layer, and on an emissive layer blended in through the gradient.
fn mapped_shaderball_scene(size: u32) -> (GBuffer, Look, PackedStacks) {
    let mut gbuffer = GBuffer::shaderball(size, size);
    let (w, h) = (gbuffer.width as f32, gbuffer.height as f32);
    let at = |i: usize| ((i as u32 % gbuffer.width) as f32 / w, (i as u32 / gbuffer.width) as f32 / h);
    let pixels = gbuffer.pixel_count();
    let tex: [Vec<f32>; 3] = [
        (0..pixels).map(|i| at(i).0).collect(),
        (0..pixels).map(|i| at(i).1).collect(),
        (0..pixels).map(|i| 1.0 - at(i).0 * at(i).1).collect(),
    ];
    for (channel, values) in ["R", "G", "B"].into_iter().zip(tex) {
        gbuffer.maps.insert(format!("tex.{channel}"), values);
    }
    gbuffer.maps.insert("rough".into(), gbuffer.masks["grunge"].clone());
    let text = r#"
[[object]]
[[object.layer]]
preset = "red-plastic"
[object.layer.set]
base_color = [1.0, 1.0, 1.0]
[object.layer.map]
base_color = "tex"
roughness = "rough"
[[object.layer]]
preset = "gold"
mask = "stripes"
[object.layer.map]
roughness = "tex.G"
metallic = "tex.B"
[[object.layer]]
mask = "gradient"
opacity = 0.8
[object.layer.set]
emission = [3.0, 1.5, 0.25]
sheen = 1.0
[object.layer.map]
emission = "tex"
sheen = "tex.R"
"#;
    let look = Look::parse(text, Path::new("mapped.toml")).unwrap();
    let ids = lookdev::render::scene::covered_object_ids(&gbuffer);
    let stacks = PackedStacks::pack(&look, ids, &gbuffer, Path::new("mapped shader ball")).unwrap();
    (gbuffer, look, stacks)
}

fn resolved_params(resolved: &[[f32; 4]], pixels: usize, i: usize) -> Params {
    let mut gpu = [0.0f32; 20];
    for k in 0..5 {
        gpu[4 * k..4 * k + 4].copy_from_slice(&resolved[k * pixels + i]);
    }
    Params::from_gpu(&gpu)
}

/// The GPU's per-pixel blend of `stacks` over `gbuffer`, compared with the CPU's value by value;
/// returns how many covered pixels blend metal with a dielectric.
fn check_resolve(ctx: &lookdev::gpu::Context, gbuffer: &GBuffer, look: &Look, stacks: &PackedStacks) -> usize {
    check_resolve_within(ctx, gbuffer, look, stacks, 1e-6)
}

/// [`check_resolve`], within `tolerance` of each value's magnitude (at least 1).
fn check_resolve_within(
    ctx: &lookdev::gpu::Context,
    gbuffer: &GBuffer,
    look: &Look,
    stacks: &PackedStacks,
    tolerance: f32,
) -> usize {
    let r = renderer(ctx, gbuffer, &Environment::studio(), look, Lighting::default());
    let resolved = r.read_resolved().unwrap();
    let pixels = gbuffer.pixel_count();
    let mut blended = 0;
    for i in (0..pixels).filter(|&i| gbuffer.coverage[i] > 0.0) {
        let cpu = stacks.resolve_gbuffer_pixel(gbuffer, i);
        let gpu = resolved_params(&resolved, pixels, i);
        let (a, b) = (cpu.to_gpu(), gpu.to_gpu());
        for k in 0..a.len() {
            let tolerance = tolerance * a[k].abs().max(1.0);
            assert!((a[k] - b[k]).abs() <= tolerance, "pixel {i} value {k}: CPU {} GPU {}", a[k], b[k]);
        }
        if gpu.metallic > 0.05 && gpu.metallic < 0.95 {
            blended += 1;
        }
    }
    blended
}

/// The GPU's per-pixel blend of the layer stacks is the CPU's, parameter by parameter: masks and
/// opacity on the built-in look, and maps bound on bottom, masked and partly opaque layers.
#[test]
fn gpu_resolve_matches_the_cpu_blend() {
    let ctx = common::gpu::context();
    let (gbuffer, look, stacks) = shaderball_scene(96);
    // Count pixels where the layers really mix, so the test sees blending at work.
    let blended = check_resolve(&ctx, &gbuffer, &look, &stacks);
    assert!(blended > 20, "only {blended} pixels blend layers");

    let (gbuffer, look, stacks) = mapped_shaderball_scene(96);
    let blended = check_resolve(&ctx, &gbuffer, &look, &stacks);
    assert!(blended > 20, "only {blended} pixels blend layers");
    // The maps are at work: base colour follows the hue, emission is there and varies.
    let pixels = gbuffer.pixel_count();
    let covered: Vec<Params> =
        (0..pixels).filter(|&i| gbuffer.coverage[i] > 0.0).map(|i| stacks.resolve_gbuffer_pixel(&gbuffer, i)).collect();
    let spread = |f: &dyn Fn(&Params) -> f32| {
        let values: Vec<f32> = covered.iter().map(f).collect();
        values.iter().cloned().fold(f32::MIN, f32::max) - values.iter().cloned().fold(f32::MAX, f32::min)
    };
    assert!(spread(&|p| p.base_color[0] - p.base_color[1]) > 0.3, "the hue does not vary");
    assert!(spread(&|p| p.emission[0]) > 1.0, "emission does not vary");
    assert!(spread(&|p| p.sheen) > 0.1);
    common::gpu::finish(ctx);
}

/// A mask's blur and levels blend on the GPU as the CPU mirror blends them (the levels' power
/// may round differently there, so within 1e-5), and they change where the layers show.
#[test]
fn gpu_resolve_applies_mask_blur_and_levels_as_the_cpu_does() {
    let ctx = common::gpu::context();
    let (gbuffer, plain, _) = shaderball_scene(96);
    let text = Look::builtin_default_text().replacen(
        "mask = \"stripes\"\n",
        "mask = \"stripes\"\nmask_blur = 2.5\nmask_black = 0.2\nmask_white = 0.7\nmask_gamma = 1.8\n",
        1,
    );
    let look = Look::parse(&text, Path::new("adjusted.toml")).unwrap();
    let ids = lookdev::render::scene::covered_object_ids(&gbuffer);
    let stacks = PackedStacks::pack(&look, ids.clone(), &gbuffer, Path::new("shader ball")).unwrap();
    assert!(stacks.channels.contains(&"mask.stripes@blur2.5".to_string()), "{:?}", stacks.channels);
    let blended = check_resolve_within(&ctx, &gbuffer, &look, &stacks, 1e-5);
    assert!(blended > 20, "only {blended} pixels blend layers");
    // The adjustments are at work: the gold's share moves at many pixels.
    let before = PackedStacks::pack(&plain, ids, &gbuffer, Path::new("shader ball")).unwrap();
    let moved = (0..gbuffer.pixel_count())
        .filter(|&i| gbuffer.coverage[i] > 0.0 && gbuffer.object_id[i] == 1)
        .filter(|&i| {
            let (a, b) = (before.resolve_gbuffer_pixel(&gbuffer, i), stacks.resolve_gbuffer_pixel(&gbuffer, i));
            (a.metallic - b.metallic).abs() > 0.05
        })
        .count();
    assert!(moved > 100, "only {moved} pixels changed");
    common::gpu::finish(ctx);
}

/// relight.comp and its CPU mirror agree pixel by pixel, on the built-in scene with its layered
/// look, a rotated studio environment, antialiased edges and the background.
#[test]
fn gpu_relight_matches_the_cpu_mirror() {
    let ctx = common::gpu::context();
    relight_matches_the_cpu_mirror(&ctx, shaderball_scene(40), true);
    common::gpu::finish(ctx);
}

/// The same with maps and emission.
#[test]
fn gpu_relight_with_maps_and_emission_matches_the_cpu_mirror() {
    let ctx = common::gpu::context();
    relight_matches_the_cpu_mirror(&ctx, mapped_shaderball_scene(40), true);
    common::gpu::finish(ctx);
}

/// The same with the pedestal catching the ball's shadow, over the background and without it
/// (a black shadow with alpha); the `shadow` shares agree too.
#[test]
fn gpu_shadow_catcher_matches_the_cpu_mirror() {
    let ctx = common::gpu::context();
    let (gbuffer, mut look, _) = shaderball_scene(40);
    look.objects.iter_mut().find(|o| o.id == Some(2)).unwrap().shadow_catcher = true;
    let ids = lookdev::render::scene::covered_object_ids(&gbuffer);
    let stacks = PackedStacks::pack(&look, ids, &gbuffer, Path::new("shader ball")).unwrap();
    assert_eq!(stacks.shadow_catcher_objects().into_iter().collect::<Vec<_>>(), [2]);
    for background in [true, false] {
        relight_matches_the_cpu_mirror(&ctx, (gbuffer.clone(), look.clone(), stacks.clone()), background);
    }
    common::gpu::finish(ctx);
}

fn relight_matches_the_cpu_mirror(
    ctx: &lookdev::gpu::Context,
    (gbuffer, look, stacks): (GBuffer, Look, PackedStacks),
    background: bool,
) {
    let env = Environment::studio();
    let lighting = Lighting { rotation_degrees: 37.0, intensity: 1.3, background };
    let seed = 9;
    let spp = 24;
    let mut r = renderer(ctx, &gbuffer, &env, &look, lighting);
    r.set_seed(seed);
    r.render_samples(10).unwrap();
    r.render_samples(14).unwrap();
    let radiance = r.read_radiance().unwrap();
    let shadow = r.read_shadow().unwrap();
    let reference = common::reference_render::Reference::new(&gbuffer, &env, r.sampling(), lighting, seed);
    let catchers = stacks.shadow_catcher_objects();
    let pixels = gbuffer.pixel_count();
    let (mut off, mut covered, mut shadowed) = (0, 0, 0);
    for y in 0..gbuffer.height {
        for x in 0..gbuffer.width {
            let i = (y * gbuffer.width + x) as usize;
            let params =
                if gbuffer.coverage[i] > 0.0 { stacks.resolve_gbuffer_pixel(&gbuffer, i) } else { Params::default() };
            let catcher = gbuffer.coverage[i] > 0.0 && catchers.contains(&gbuffer.object_id[i]);
            let cpu = if catcher {
                let share = reference.shadow(x, y, &params, spp);
                let gpu = glam::Vec3::from(shadow[i]);
                assert!((gpu - share).abs().max_element() < 1e-3, "pixel ({x}, {y}): shadow GPU {gpu} CPU {share}");
                shadowed += (share.max_element() < 0.8) as usize;
                reference.catcher_pixel(x, y, &params, spp)
            } else {
                assert_eq!(shadow[i], [1.0; 3], "pixel ({x}, {y}) catches no shadow");
                reference.pixel(x, y, &params, spp)
            };
            let gpu = glam::Vec4::from(radiance[i]);
            covered += (gbuffer.coverage[i] > 0.0) as usize;
            let error = ((gpu - cpu).abs() / cpu.abs().max(glam::Vec4::splat(0.02))).max_element();
            if error > 1e-3 {
                off += 1;
                // Float differences may flip a rare sampling decision; the result must still be close.
                assert!(error < 0.1, "pixel ({x}, {y}): GPU {gpu} CPU {cpu}");
            }
        }
    }
    assert!(covered > 300, "{covered}");
    eprintln!("{shadowed} pixels of a catcher in shadow");
    assert!(catchers.is_empty() || shadowed > 10, "only {shadowed} pixels of the catcher are in shadow");
    eprintln!("{off} of {pixels} pixels differ by more than 0.1%");
    assert!(off * 400 <= pixels, "{off} of {pixels} pixels differ by more than 0.1%");
}

/// finalize.comp applies exposure, each tone map and the sRGB OETF exactly as the Rust mirror.
#[test]
fn gpu_display_matches_the_rust_tonemaps() {
    let ctx = common::gpu::context();
    let (gbuffer, look, _) = shaderball_scene(48);
    let mut r =
        renderer(&ctx, &gbuffer, &Environment::studio(), &look, Lighting { intensity: 3.0, ..Lighting::default() });
    r.render_samples(4).unwrap();
    let radiance = r.read_radiance().unwrap();
    for tonemap in Tonemap::ALL {
        for exposure in [-1.0f32, 0.0, 1.5] {
            let pixels = r.read_display(exposure, tonemap).unwrap();
            for (i, rad) in radiance.iter().enumerate() {
                let expected = tonemap::display_pixel(Vec3::new(rad[0], rad[1], rad[2]), exposure, tonemap);
                for c in 0..3 {
                    let got = pixels[4 * i + c];
                    assert!(
                        (got as i32 - expected[c] as i32).abs() <= 1,
                        "{tonemap} EV {exposure} pixel {i} channel {c}: GPU {got} CPU {}",
                        expected[c]
                    );
                }
                assert_eq!(pixels[4 * i + 3], 255);
            }
        }
    }
    // Without a background, alpha is the coverage and colour is un-premultiplied.
    r.set_lighting(Lighting { background: false, ..Lighting::default() });
    r.render_samples(2).unwrap();
    let radiance = r.read_radiance().unwrap();
    let pixels = r.read_display(0.0, Tonemap::Linear).unwrap();
    let mut partial = 0;
    for (i, rad) in radiance.iter().enumerate() {
        let alpha = (rad[3] * 255.0 + 0.5) as i32;
        assert!((pixels[4 * i + 3] as i32 - alpha).abs() <= 1, "pixel {i}: alpha {} vs {alpha}", pixels[4 * i + 3]);
        if rad[3] == 0.0 {
            assert_eq!(&pixels[4 * i..4 * i + 3], &[0, 0, 0]);
        } else {
            // The EXR radiance is premultiplied; the PNG colour is the surface's own.
            let own = Vec3::new(rad[0], rad[1], rad[2]) / rad[3];
            let expected = tonemap::display_pixel(own, 0.0, Tonemap::Linear);
            for c in 0..3 {
                assert!(
                    (pixels[4 * i + c] as i32 - expected[c] as i32).abs() <= 1,
                    "pixel {i}: {:?} vs {expected:?}",
                    &pixels[4 * i..4 * i + 3]
                );
            }
            partial += (rad[3] < 1.0) as usize;
        }
    }
    assert!(partial > 10, "only {partial} partly covered pixels");
    drop(r);
    common::gpu::finish(ctx);
}

/// The same inputs and seed give the same bits, however the samples are split into passes; a
/// different seed gives a different image.
#[test]
fn renders_are_deterministic() {
    let ctx = common::gpu::context();
    let (gbuffer, look, _) = shaderball_scene(64);
    let env = Environment::studio();
    let render = |splits: &[u32], seed: u32| {
        let mut r = renderer(&ctx, &gbuffer, &env, &look, Lighting::default());
        r.set_seed(seed);
        for &n in splits {
            r.render_samples(n).unwrap();
        }
        r.read_radiance().unwrap()
    };
    let a = render(&[16], 3);
    assert_eq!(a, render(&[16], 3));
    assert_eq!(a, render(&[1, 5, 10], 3));
    assert_ne!(a, render(&[16], 4));
    // Bands of rows, as the viewer renders a frame's share, each at its own pace.
    let mut r = renderer(&ctx, &gbuffer, &env, &look, Lighting::default());
    r.set_seed(3);
    r.render_rows(0, 20, 16).unwrap();
    r.render_rows(20, 30, 6).unwrap();
    r.render_rows(50, 100, 16).unwrap();
    r.render_rows(20, 30, 10).unwrap();
    assert_eq!(a, r.read_radiance().unwrap());
    // A restart starts every pixel over, band by band, without clearing the image first.
    r.set_seed(4);
    r.render_rows(0, 40, 16).unwrap();
    r.render_rows(40, 24, 16).unwrap();
    assert_eq!(render(&[16], 4), r.read_radiance().unwrap());
    drop(r);
    common::gpu::finish(ctx);
}

/// An accumulation's first dispatch is sized by the pace the renderer last measured: at a pace
/// that does every sample within a dispatch's target, one dispatch; at a crawl, one sample
/// first. Either way the image is the same, and the accumulation measures a pace.
#[test]
fn the_first_dispatch_follows_the_measured_pace() {
    let ctx = common::gpu::context();
    let (gbuffer, look, _) = shaderball_scene(64);
    let env = Environment::studio();
    let accumulate = |pace: f64| {
        let mut r = renderer(&ctx, &gbuffer, &env, &look, Lighting::default());
        r.set_pace(pace);
        let stats = lookdev::render::progressive::accumulate(&mut r, 8, |_| {}).unwrap();
        (stats.dispatches, r.read_radiance().unwrap(), r.pace())
    };
    let (fast, fast_image, _) = accumulate(1e15);
    let (slow, slow_image, measured) = accumulate(1.0);
    assert_eq!(fast, 1, "every sample in one dispatch");
    assert!(slow >= 2, "one sample first, then the rest: {slow} dispatches");
    assert!(fast_image == slow_image, "the split changes no bits");
    assert!(measured.is_some_and(|p| p > 1.0), "the accumulation measured its pace: {measured:?}");
    common::gpu::finish(ctx);
}

/// Reading the radiance finalizes only the rows that changed since they were last finalized,
/// with the display's exposure and tone map: the display pixels the viewer shows stay as they
/// were made, and the radiance is that of the current sums.
#[test]
fn reading_the_radiance_keeps_the_display_and_finalizes_what_changed() {
    let ctx = common::gpu::context();
    let (gbuffer, look, _) = shaderball_scene(64);
    let env = Environment::studio();
    let mut r = renderer(&ctx, &gbuffer, &env, &look, Lighting::default());
    r.render_samples(2).unwrap();
    let two = r.read_radiance().unwrap();
    r.finalize_rows(0, r.height, 1.5, Tonemap::Aces).unwrap();
    let shown = r.display_image().read(&ctx).unwrap();
    assert!(r.read_radiance().unwrap() == two, "the same sums, the same radiance");
    assert!(r.display_image().read(&ctx).unwrap() == shown, "the display as it was made");
    // Rows 0..32 relit, 0..16 finalized: the read finalizes 16..32, as a finalize of all does.
    r.render_rows(0, 32, 1).unwrap();
    r.finalize_rows(0, 16, 1.5, Tonemap::Aces).unwrap();
    let read = r.read_radiance().unwrap();
    assert!(read != two, "rows relit since read anew");
    let shown = r.display_image().read(&ctx).unwrap();
    r.finalize_rows(0, r.height, 1.5, Tonemap::Aces).unwrap();
    assert!(r.read_radiance().unwrap() == read, "every changed row was finalized before the read");
    assert!(r.display_image().read(&ctx).unwrap() == shown, "with the display's exposure and tone map");
    drop(r);
    common::gpu::finish(ctx);
}

/// Every image the passes write, and every display image, starts cleared: what an earlier image
/// left in the same memory is never read back, or shown by the viewer before its first pass.
#[test]
fn new_images_start_cleared_not_with_what_freed_memory_held() {
    use lookdev::gpu::Image;
    let ctx = common::gpu::context();
    let float =
        |ctx: &lookdev::gpu::Context| Image::new(ctx, ash::vk::Format::R32G32B32A32_SFLOAT, 16, 16, 1, false).unwrap();
    for round in 0..8 {
        // Leave a pattern in memory the allocator is likely to hand out again.
        for stale in [float(&ctx), Image::display(&ctx, 32, 32).unwrap()] {
            stale.upload(&ctx, &vec![0x5a; stale.byte_size() as usize]).unwrap();
        }
        for fresh in [float(&ctx), Image::display(&ctx, 32, 32).unwrap()] {
            let bytes = fresh.read(&ctx).unwrap();
            let stale = bytes.iter().filter(|&&b| b != 0).count();
            assert_eq!(stale, 0, "round {round}: {stale} of {} bytes of a new image are not zero", bytes.len());
        }
    }
    common::gpu::finish(ctx);
}

#[test]
fn layered_look_from_toml_renders_masks_where_they_are() {
    // Left half gold, right half rubber: the two halves of the sphere must differ in colour.
    let ctx = common::gpu::context();
    let gbuffer = orthographic_sphere(32);
    let look = look("[[object]]\n[[object.layer]]\npreset = \"blue-rubber\"\n[[object.layer]]\npreset = \"gold\"\nmask = \"left\"\n");
    let mut r = renderer(&ctx, &gbuffer, &Environment::studio(), &look, Lighting::default());
    r.render_samples(64).unwrap();
    let radiance = r.read_radiance().unwrap();
    let at = |x: u32, y: u32| radiance[(y * 32 + x) as usize];
    let (left, right) = (at(10, 16), at(22, 16));
    // Gold is red > blue; blue rubber is blue > red.
    assert!(left[0] > left[2], "left {left:?}");
    assert!(right[2] > right[0], "right {right:?}");
    drop(r);
    common::gpu::finish(ctx);
}

/// Large images are uploaded a band of rows at a time through one small staging buffer: every
/// layer and row lands where it belongs whatever the band (one row, a few, a ragged last band,
/// the whole image), and the device holds no second copy of the image meanwhile.
#[test]
fn uploads_in_bands_of_rows_put_every_texel_in_place() {
    use lookdev::gpu::Image;
    let ctx = common::gpu::context();
    let (width, height, layers) = (13u32, 11u32, 3u32);
    let image = Image::new(&ctx, ash::vk::Format::R32_UINT, width, height, layers, true).unwrap();
    let texel = |layer: u32, x: u32, y: u32| layer * 1_000_000 + y * 1000 + x;
    let expected: Vec<u8> = (0..layers)
        .flat_map(|l| (0..height).flat_map(move |y| (0..width).map(move |x| texel(l, x, y))))
        .flat_map(u32::to_le_bytes)
        .collect();
    for chunk in [1, 4 * 13, 4 * 13 * 4, 4 * 13 * 11, 1 << 20] {
        image.upload(&ctx, &vec![0; expected.len()]).unwrap();
        let before = ctx.memory().current();
        image
            .upload_rows_within(&ctx, chunk, |layer, first_row, bytes| {
                let out: &mut [u32] = bytemuck::cast_slice_mut(bytes);
                for (i, v) in out.iter_mut().enumerate() {
                    *v = texel(layer, i as u32 % width, first_row + i as u32 / width);
                }
            })
            .unwrap();
        assert_eq!(ctx.memory().current(), before, "the staging memory is given back");
        assert!(image.read(&ctx).unwrap() == expected, "bands of {chunk} bytes");
    }
    assert!(ctx.memory().peak() >= image.byte_size());
    common::gpu::finish(ctx);
}
