//! Golden images of the built-in scene (see `common::golden` for the tolerance and how to
//! regenerate them).

mod common;

use common::golden::golden;

use lookdev::material::Look;
use lookdev::render::scene::{GBufferSpec, LookSource, Scene, SceneSpec};
use lookdev::render::{progressive, Renderer};

fn render(look: Look, size: u32, spp: u32) -> Vec<u8> {
    let ctx = common::gpu::context();
    let scene = Scene::load(&SceneSpec {
        look: LookSource::Given(Box::new(look)),
        gbuffer: GBufferSpec { builtin_size: Some((size, size)), ..GBufferSpec::default() },
        ..SceneSpec::default()
    })
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
    look.render.tonemap = Some(lookdev::shading::tonemap::Tonemap::Agx);
    look.render.exposure = Some(1.0);
    golden("shaderball_chrome_agx.png", 192, 192, &render(look, 192, 256));
}
