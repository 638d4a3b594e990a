//! Backgrounds (docs/formats.md#backgrounds): the environment, none, the environment blurred, a
//! solid colour, or another environment than the one that lights; read and written in looks,
//! and rendered headless as `lookdev render` renders them.

mod common;

use lookdev::environment::backdrop::{Backdrop, Prepared, DEFAULT_BLUR_DEGREES};
use lookdev::environment::EnvironmentRef;
use lookdev::gpu::Context;
use lookdev::material::Look;
use lookdev::render::scene::{GBufferSpec, LookSource, Scene, SceneSpec};
use lookdev::render::{Lighting, Renderer};
use std::path::{Path, PathBuf};

const SPP: u32 = 4;

fn parse(text: &str) -> Look {
    Look::parse(text, Path::new("/looks/shot.toml")).unwrap_or_else(|e| panic!("{text}: {e}"))
}

fn parse_error(text: &str) -> String {
    Look::parse(text, Path::new("/looks/shot.toml")).expect_err(text).to_string()
}

/// The look written and read back.
fn round_trip(look: &Look) -> Look {
    let mut again = Look::parse(&look.to_toml(), Path::new("/looks/shot.toml")).unwrap();
    again.file = look.file.clone();
    again
}

#[test]
fn every_background_mode_reads_and_round_trips() {
    let cases = [
        ("background = true", Some(true), None),
        ("background = false", Some(false), None),
        ("background = \"blur\"", Some(true), Some(Backdrop::Blurred(DEFAULT_BLUR_DEGREES))),
        ("background = \"blur\"\nbackground_blur = 12.5", Some(true), Some(Backdrop::Blurred(12.5))),
        ("background = [0.1, 0.2, 0.3]", Some(true), Some(Backdrop::Colour([0.1, 0.2, 0.3]))),
        ("background_environment = \"builtin:city\"", None, Some(Backdrop::Other(EnvironmentRef::Builtin("city")))),
        (
            "background = true\nbackground_environment = \"plates/yard.exr\"",
            Some(true),
            Some(Backdrop::Other(EnvironmentRef::File(PathBuf::from("/looks/plates/yard.exr")))),
        ),
    ];
    for (keys, shown, backdrop) in cases {
        let look = parse(&format!("[environment]\n{keys}\n"));
        assert_eq!((look.environment.background, &look.environment.backdrop), (shown, &backdrop), "{keys}");
        let again = round_trip(&look);
        assert_eq!(again.environment, look.environment, "{keys} wrote {}", look.to_toml());
    }
    // Old looks write as they did.
    assert!(parse("[environment]\nbackground = false\n").to_toml().contains("background = false"));
    let relative = parse("[environment]\nbackground_environment = \"plates/yard.exr\"\n").to_toml();
    assert!(relative.contains("background_environment = \"plates/yard.exr\""), "{relative}");
}

#[test]
fn bad_background_keys_are_refused_naming_them() {
    let cases = [
        ("background = \"fog\"", "background must be true, false, \"blur\" or a linear colour"),
        ("background = [1, 2]", "background needs three numbers"),
        ("background = [-1, 0, 0]", "must be linear values from 0"),
        ("background = \"blur\"\nbackground_blur = 0", "background_blur 0 must be a number of degrees"),
        ("background = true\nbackground_blur = 3", "background_blur needs background = \"blur\""),
        ("background = false\nbackground_environment = \"builtin:city\"", "background_environment"),
        ("background = [1, 1, 1]\nbackground_environment = \"builtin:city\"", "background_environment"),
        ("background_environment = \"builtin:cty\"", "city"),
    ];
    for (keys, expected) in cases {
        let message = parse_error(&format!("[environment]\n{keys}\n"));
        assert!(message.starts_with("/looks/shot.toml:"), "{message}");
        assert!(message.contains(expected), "{keys}: {message}");
    }
}

/// The built-in shader ball at a small size lit by the built-in `builtin` with the look's
/// `[environment]` keys `keys`, rendered to [`SPP`] with the backdrop set as `lookdev render`
/// sets it.
fn render(ctx: &Context, builtin: &str, keys: &str) -> (Scene, Renderer) {
    let look = parse(&format!("[environment]\nbuiltin = \"{builtin}\"\n{keys}\n"));
    let spec = SceneSpec {
        look: LookSource::Given(Box::new(look)),
        gbuffer: GBufferSpec { builtin_size: Some((48, 32)), size_given: true, ..GBufferSpec::default() },
        quiet: true,
        ..SceneSpec::default()
    };
    let scene = Scene::load(&spec).unwrap();
    let mut renderer = Renderer::new(ctx, &scene.gbuffer, &scene.environment).unwrap();
    renderer.set_stacks(&scene.stacks).unwrap();
    renderer.set_lighting(scene.settings.lighting);
    renderer.set_backdrop(&scene.backdrop).unwrap();
    renderer.render_samples(SPP).unwrap();
    (scene, renderer)
}

/// [`render`]'s scene and linear radiance.
fn radiance(ctx: &Context, builtin: &str, keys: &str) -> (Scene, Vec<[f32; 4]>) {
    let (scene, renderer) = render(ctx, builtin, keys);
    let radiance = renderer.read_radiance().unwrap();
    (scene, radiance)
}

/// The pixels the surface covers entirely, and those it leaves uncovered.
fn pixels(scene: &Scene) -> (Vec<usize>, Vec<usize>) {
    let coverage = &scene.gbuffer.coverage;
    let covered = (0..coverage.len()).filter(|&i| coverage[i] >= 1.0).collect();
    let uncovered = (0..coverage.len()).filter(|&i| coverage[i] <= 0.0).collect();
    (covered, uncovered)
}

/// The mean of the green channel over `pixels`, and the mean absolute difference between each
/// and its right neighbour where both are in `pixels`.
fn mean_and_gradient(radiance: &[[f32; 4]], width: usize, pixels: &[usize]) -> (f64, f64) {
    let mean = pixels.iter().map(|&i| radiance[i][1] as f64).sum::<f64>() / pixels.len() as f64;
    let steps: Vec<f64> = pixels
        .iter()
        .filter(|&&i| (i + 1) % width != 0 && pixels.binary_search(&(i + 1)).is_ok())
        .map(|&i| (radiance[i][1] as f64 - radiance[i + 1][1] as f64).abs())
        .collect();
    (mean, steps.iter().sum::<f64>() / steps.len() as f64)
}

#[test]
fn each_background_renders_behind_the_same_relit_surface() {
    let ctx = common::gpu::context();
    let (scene, sharp_radiance) = radiance(&ctx, "studio", "");
    let (covered, uncovered) = pixels(&scene);
    assert!(covered.len() > 200 && uncovered.len() > 200, "{} {}", covered.len(), uncovered.len());
    let width = scene.gbuffer.width as usize;
    let same_surface = |radiance: &[[f32; 4]], what: &str| {
        for &i in &covered {
            assert_eq!(radiance[i], sharp_radiance[i], "{what}: covered pixel {i}");
        }
    };

    let (_, colour) = radiance(&ctx, "studio", "background = [0.25, 0.5, 2.0]");
    same_surface(&colour, "colour");
    for &i in &uncovered {
        assert_eq!(colour[i], [0.25, 0.5, 2.0, 1.0], "uncovered pixel {i}");
    }

    let (_, blurred) = radiance(&ctx, "studio", "background = \"blur\"\nbackground_blur = 8");
    same_surface(&blurred, "blur");
    let (sharp_mean, sharp_gradient) = mean_and_gradient(&sharp_radiance, width, &uncovered);
    let (blurred_mean, blurred_gradient) = mean_and_gradient(&blurred, width, &uncovered);
    // The view sees a dim part of the studio, which the blur brightens with light from just
    // outside it (the whole map's mean is kept: src/environment/backdrop.rs).
    assert!((blurred_mean - sharp_mean).abs() < 0.5 * sharp_mean, "mean {sharp_mean} blurred {blurred_mean}");
    assert!(blurred_gradient < 0.7 * sharp_gradient, "gradient {sharp_gradient} blurred {blurred_gradient}");

    // Lit by the studio, in front of the sunrise: the sunrise's own background.
    let (_, other) = radiance(&ctx, "studio", "background_environment = \"builtin:sunrise\"");
    same_surface(&other, "other environment");
    let (_, sunrise) = radiance(&ctx, "sunrise", "");
    for &i in &uncovered {
        let (a, b) = (other[i], sunrise[i]);
        let close = (0..4).all(|c| (a[c] - b[c]).abs() <= 1e-5 * b[c].abs().max(1.0));
        assert!(close, "uncovered pixel {i}: {a:?} in front of the studio, {b:?} lit by the sunrise");
    }
    assert!(uncovered.iter().any(|&i| other[i] != sharp_radiance[i]), "the sunrise is not the studio");
    common::gpu::finish(ctx);
}

#[test]
fn changing_the_background_keeps_every_sample() {
    let ctx = common::gpu::context();
    let (scene, mut renderer) = render(&ctx, "studio", "");
    let (covered, uncovered) = pixels(&scene);
    let before = renderer.read_radiance().unwrap();
    let colour = [0.5, 0.25, 0.125];
    renderer.set_backdrop(&Prepared::Colour(colour)).unwrap();
    assert_eq!(renderer.samples(), SPP, "nothing restarted");
    let after = renderer.read_radiance().unwrap();
    assert!(covered.iter().all(|&i| after[i] == before[i]));
    assert!(uncovered.iter().all(|&i| after[i] == [colour[0], colour[1], colour[2], 1.0]));

    // Off and on again: transparent, then the colour, with the same samples throughout.
    let lighting = scene.settings.lighting;
    renderer.set_lighting(Lighting { background: false, ..lighting });
    renderer.write_background().unwrap();
    assert_eq!(renderer.samples(), SPP, "nothing restarted");
    let off = renderer.read_radiance().unwrap();
    assert!(uncovered.iter().all(|&i| off[i] == [0.0; 4]));
    assert!(covered.iter().all(|&i| off[i] == before[i]), "covered pixels are opaque either way");
    renderer.set_lighting(lighting);
    renderer.write_background().unwrap();
    let on = renderer.read_radiance().unwrap();
    assert_eq!(on, after);

    // Back to the environment: the first render's pixels, bit for bit.
    renderer.set_backdrop(&Prepared::Environment).unwrap();
    assert_eq!(renderer.read_radiance().unwrap(), before);
    assert_eq!(renderer.samples(), SPP);
    drop(renderer);
    common::gpu::finish(ctx);
}
