//! Golden images of the built-in scene. A render must match the committed PNG within 5/255 per
//! channel at all but 0.1% of its pixels, as Filament's CI holds its renders on Mesa; the
//! tolerance absorbs a driver's different float rounding, not a change in what is rendered.
//!
//! After an intended change to the rendered image, regenerate with
//! `LOOKDEV_BLESS=1 cargo test --release --test golden`, look at the new PNGs, and commit them.

mod common;

use lookdev::environment::Environment;
use lookdev::gbuffer::GBuffer;
use lookdev::material::Look;
use lookdev::render::scene::Scene;
use lookdev::render::settings::{Overrides, Settings};
use lookdev::render::{progressive, Renderer};
use std::path::PathBuf;

const TOLERANCE: i32 = 5;
const MAX_FAILING: f64 = 0.001;

fn golden(name: &str, width: u32, height: u32, rgba: &[u8]) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden").join(name);
    if std::env::var("LOOKDEV_BLESS").is_ok_and(|v| v == "1") {
        image::RgbaImage::from_raw(width, height, rgba.to_vec()).unwrap().save(&path).unwrap();
        eprintln!("wrote {}", path.display());
        return;
    }
    let expected = image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgba8();
    assert_eq!(expected.dimensions(), (width, height), "{name}: size");
    let failing = expected
        .as_raw()
        .chunks(4)
        .zip(rgba.chunks(4))
        .filter(|(e, g)| e.iter().zip(g.iter()).any(|(a, b)| (*a as i32 - *b as i32).abs() > TOLERANCE))
        .count();
    let fraction = failing as f64 / (width * height) as f64;
    assert!(
        fraction <= MAX_FAILING,
        "{name}: {failing} pixels ({:.3}%) differ by more than {TOLERANCE}/255",
        fraction * 100.0
    );
}

fn render(look: Look, size: u32, spp: u32) -> Vec<u8> {
    let ctx = common::gpu::context();
    let settings = Settings::resolve(&look, &Overrides::default()).unwrap();
    let scene =
        Scene::new(GBuffer::shaderball(size, size), "shader ball".into(), look, Environment::studio(), settings)
            .unwrap();
    let rgba = {
        let mut renderer = Renderer::new(&ctx, &scene.gbuffer, &scene.environment).unwrap();
        renderer.set_stacks(&scene.stacks).unwrap();
        renderer.set_lighting(scene.settings.lighting);
        renderer.set_seed(scene.settings.seed);
        progressive::accumulate(&mut renderer, spp, |_| {}).unwrap();
        renderer.read_display(scene.settings.exposure, scene.settings.tonemap).unwrap()
    };
    common::gpu::finish(ctx);
    rgba
}

/// The built-in scene with the built-in default look: layers, masks, the rotated studio.
#[test]
fn builtin_scene_matches_its_golden_image() {
    golden("shaderball_default.png", 256, 256, &render(Look::builtin_default(), 256, 256));
}

/// The same scene in one glossy metal under the AgX tone map, exposed up a stop.
#[test]
fn glossy_metal_with_agx_matches_its_golden_image() {
    let mut look = Look::builtin_default();
    look.objects.retain(|o| o.id.is_none());
    look.objects[0].layers[0].params = lookdev::material::library::builtin("chrome").unwrap().params;
    look.render.tonemap = Some(lookdev::render::tonemap::Tonemap::Agx);
    look.render.exposure = Some(1.0);
    golden("shaderball_chrome_agx.png", 192, 192, &render(look, 192, 256));
}
