//! Edit-local re-convergence at the renderer: the resolve pass finds exactly the covered pixels
//! whose material an edit changed (checked against the CPU blend), `set_stacks_local` restarts
//! those alone, the others keep their samples bit for bit, and once caught up the image is a
//! fresh render of the edited look's, bit for bit.

mod common;

use common::scenes::{look, orthographic_sphere};
use lookdev::environment::Environment;
use lookdev::gbuffer::GBuffer;
use lookdev::material::stack::{LobesPresent, PackedStacks};
use lookdev::material::{Look, Param, Value};
use lookdev::render::{Lighting, Renderer};
use lookdev::shading::tonemap::Tonemap;
use std::path::Path;

/// A sphere whose bottom layer is rough and grey, with a masked layer over its left half
/// (`left`) and a partly transparent layer over a ramp (`ramp`).
const SPHERE: &str = r#"
[[object]]
[[object.layer]]
preset = "white-ceramic"
[[object.layer]]
preset = "gold"
mask = "left"
[object.layer.set]
roughness = 0.3
[[object.layer]]
preset = "blue-rubber"
mask = "ramp"
opacity = 0.5
"#;

fn pack(look: &Look, gbuffer: &GBuffer) -> PackedStacks {
    let ids = lookdev::render::scene::covered_object_ids(gbuffer);
    PackedStacks::pack(look, ids, gbuffer, Path::new("test g-buffer")).unwrap()
}

/// The covered pixels whose CPU-blended material differs, bit for bit, between two looks.
fn changed_on_cpu(gbuffer: &GBuffer, before: &PackedStacks, after: &PackedStacks) -> Vec<u32> {
    (0..gbuffer.pixel_count())
        .filter(|&i| gbuffer.coverage[i] > 0.0)
        .filter(|&i| {
            let (a, b) = (before.resolve_gbuffer_pixel(gbuffer, i), after.resolve_gbuffer_pixel(gbuffer, i));
            a.to_gpu().iter().zip(b.to_gpu().iter()).any(|(x, y)| x.to_bits() != y.to_bits())
        })
        .map(|i| i as u32)
        .collect()
}

/// The look of `text` with one parameter of one layer set.
fn with_set(text: &str, object: usize, layer: usize, param: Param, value: f32) -> Look {
    let mut edited = look(text);
    edited.objects[object].layers[layer].params.set(param, Value::Scalar(value)).unwrap();
    edited
}

fn renderer(ctx: &lookdev::gpu::Context, gbuffer: &GBuffer, env: &Environment, stacks: &PackedStacks) -> Renderer {
    let mut r = Renderer::new(ctx, gbuffer, env).unwrap();
    r.set_stacks(stacks).unwrap();
    r.set_lighting(Lighting { rotation_degrees: 30.0, ..Lighting::default() });
    r.set_seed(7);
    r
}

fn bits(radiance: &[[f32; 4]]) -> Vec<[u32; 4]> {
    radiance.iter().map(|p| p.map(f32::to_bits)).collect()
}

/// Each edit restarts exactly the covered pixels whose blended material it changes, as the CPU
/// blend finds them: none for no change; the left half for the layer masked by `left`; the
/// right half for the bottom layer, which that layer hides wholly on the left; every covered
/// pixel for the layer over the ramp, which is nowhere 0.
#[test]
fn the_resolve_finds_exactly_the_pixels_an_edit_changes() {
    let ctx = common::gpu::context();
    let env = Environment::default_builtin();
    let gbuffer = orthographic_sphere(48);
    let base = pack(&look(SPHERE), &gbuffer);
    let covered = gbuffer.coverage.iter().filter(|&&a| a > 0.0).count();
    let left =
        (0..gbuffer.pixel_count()).filter(|&i| gbuffer.coverage[i] > 0.0 && gbuffer.masks["left"][i] > 0.0).count();
    let edits = [
        ("no change", look(SPHERE), 0),
        ("the masked layer", with_set(SPHERE, 0, 1, Param::Roughness, 0.6), left),
        ("the bottom layer", with_set(SPHERE, 0, 0, Param::Roughness, 0.9), covered - left),
        ("the ramp layer", with_set(SPHERE, 0, 2, Param::Metallic, 1.0), covered),
    ];
    assert!(left > 0 && left < covered);
    let mut r = renderer(&ctx, &gbuffer, &env, &base);
    r.render_samples(2).unwrap();
    for (what, edit, expected) in edits {
        r.set_stacks(&base).unwrap();
        r.render_samples(2).unwrap();
        let before = bits(&r.read_radiance().unwrap());
        let edited = pack(&edit, &gbuffer);
        let restarted = r.set_stacks_local(&edited).unwrap().expect("no edit changes the scene's lobes");
        let cpu = changed_on_cpu(&gbuffer, &base, &edited);
        assert_eq!(restarted, expected, "{what}");
        assert_eq!(restarted, cpu.len(), "{what}: as many as the CPU blend changes");
        if restarted == 0 {
            assert_eq!(r.restarted_region(), None, "{what}: nothing restarted");
            continue;
        }
        assert_eq!(r.restarted_region(), Some((cpu.len(), 0, 2)), "{what}");
        // A sample for the restarted pixels leaves every other pixel as it was.
        r.render_samples(1).unwrap();
        r.finalize_rows(0, r.height, 0.0, Tonemap::Linear).unwrap();
        let after = bits(&r.read_shown_radiance().unwrap());
        let moved: Vec<u32> = (0..after.len() as u32).filter(|&i| after[i as usize] != before[i as usize]).collect();
        assert!(moved.iter().all(|i| cpu.binary_search(i).is_ok()), "{what}: only changed pixels move");
    }
    common::gpu::finish(ctx);
}

/// The resolve skips the pixels of stacks an edit left alone: after each of a chain of edits
/// (one layer's value in each of two objects' stacks, a masked layer disabled, which drops a
/// channel the layers read, a layer's mask inverted, and back), the resolved material is a
/// fresh renderer's, bit for bit, at every pixel.
#[test]
fn each_edit_resolves_as_a_fresh_renderer_does() {
    let ctx = common::gpu::context();
    let env = Environment::default_builtin();
    // The sphere's lower half is a second object, in gold.
    let mut gbuffer = orthographic_sphere(48);
    let width = gbuffer.width as usize;
    for (i, id) in gbuffer.object_id.iter_mut().enumerate() {
        *id = u32::from(i / width >= width / 2);
    }
    let text = format!("{SPHERE}\n[[object]]\nid = 1\n[[object.layer]]\npreset = \"gold\"\n");
    let mut without_ramp = look(&text);
    without_ramp.objects[0].layers[2].enabled = false;
    let mut inverted = look(&text);
    inverted.objects[0].layers[1].invert = true;
    let edits = [
        ("the first object's masked layer", with_set(&text, 0, 1, Param::Roughness, 0.6)),
        ("the second object's only layer", with_set(&text, 1, 0, Param::Roughness, 0.9)),
        ("the ramp layer disabled", without_ramp),
        ("the mask inverted", inverted),
        ("back to the first look", look(&text)),
    ];
    let mut r = renderer(&ctx, &gbuffer, &env, &pack(&look(&text), &gbuffer));
    for (what, edit) in edits {
        let stacks = pack(&edit, &gbuffer);
        r.set_stacks_local(&stacks).unwrap();
        let fresh = renderer(&ctx, &gbuffer, &env, &stacks);
        let resolved = |r: &Renderer| bits(&r.read_resolved().unwrap());
        assert!(resolved(&r) == resolved(&fresh), "{what}: as a fresh renderer resolves it");
    }
    drop(r);
    common::gpu::finish(ctx);
}

/// After an edit of the pedestal's stack on the shader ball, the ball keeps its samples bit for
/// bit while the pedestal catches up, and then the image is a fresh render's of the edited
/// look, bit for bit. Undoing the edit the same way gives back the first image.
#[test]
fn a_local_restart_keeps_the_rest_and_catches_up_to_a_fresh_render() {
    let ctx = common::gpu::context();
    let env = Environment::default_builtin();
    let gbuffer = GBuffer::shaderball(96, 96);
    let text = "[[object]]\n[[object.layer]]\npreset = \"white-ceramic\"\n\n[[object]]\nid = 1\n[[object.layer]]\npreset = \"gold\"\n";
    let original = pack(&look(text), &gbuffer);
    let edited = pack(&with_set(text, 0, 0, Param::Roughness, 0.85), &gbuffer);
    let spp = 6;

    let mut r = renderer(&ctx, &gbuffer, &env, &original);
    lookdev::render::progressive::accumulate(&mut r, spp, |_| {}).unwrap();
    let before = bits(&r.read_radiance().unwrap());

    let restarted = r.set_stacks_local(&edited).unwrap().expect("the same lobes");
    let pedestal: Vec<usize> =
        (0..gbuffer.pixel_count()).filter(|&i| gbuffer.coverage[i] > 0.0 && gbuffer.object_id[i] != 1).collect();
    assert_eq!(restarted, pedestal.len(), "the pedestal's covered pixels, and only they, restart");
    // A first sample for the pedestal, then the ball's pixels and the background are unchanged.
    r.render_samples(1).unwrap();
    assert_eq!(r.restarted_region().map(|(_, theirs, rest)| (theirs, rest)), Some((1, spp)));
    r.finalize_rows(0, r.height, 0.0, Tonemap::Linear).unwrap();
    let partway = bits(&r.read_shown_radiance().unwrap());
    let kept: Vec<usize> = (0..gbuffer.pixel_count()).filter(|i| !pedestal.contains(i)).collect();
    for &i in &kept {
        assert_eq!(partway[i], before[i], "pixel {i} (object {}) kept its samples", gbuffer.object_id[i]);
    }
    assert!(pedestal.iter().any(|&i| partway[i] != before[i]), "the pedestal shows its new material");

    lookdev::render::progressive::accumulate(&mut r, spp, |_| {}).unwrap();
    assert_eq!(r.restarted_region(), None, "caught up");
    let after = bits(&r.read_radiance().unwrap());
    let mut fresh = renderer(&ctx, &gbuffer, &env, &edited);
    lookdev::render::progressive::accumulate(&mut fresh, spp, |_| {}).unwrap();
    assert!(after == bits(&fresh.read_radiance().unwrap()), "equal to a fresh render of the edit, bit for bit");

    assert_eq!(r.set_stacks_local(&original).unwrap(), Some(pedestal.len()), "undo restarts the same pixels");
    lookdev::render::progressive::accumulate(&mut r, spp, |_| {}).unwrap();
    assert!(bits(&r.read_radiance().unwrap()) == before, "undone, the first image, bit for bit");
    drop((r, fresh));
    common::gpu::finish(ctx);
}

/// An edit that gives the scene a lobe no pixel had (a clear coat on the pedestal, in a scene
/// of bare metals) needs another specialisation of the relight kernel: every pixel restarts,
/// and the image is a fresh render's of the edited look, bit for bit. Taking the coat off again
/// goes back to the first kernel and the first image.
#[test]
fn an_edit_that_gives_the_scene_a_lobe_restarts_everything() {
    let ctx = common::gpu::context();
    let env = Environment::default_builtin();
    let gbuffer = GBuffer::shaderball(64, 64);
    let text = "[[object]]\n[[object.layer]]\npreset = \"chrome\"\n\n[[object]]\nid = 1\n[[object.layer]]\npreset = \"gold\"\n";
    let original = pack(&look(text), &gbuffer);
    let coated = pack(&with_set(text, 0, 0, Param::Clearcoat, 1.0), &gbuffer);
    assert_eq!(original.lobes(), LobesPresent { diffuse: false, clearcoat: false });
    assert_eq!(coated.lobes(), LobesPresent { diffuse: false, clearcoat: true });
    let spp = 4;

    let mut r = renderer(&ctx, &gbuffer, &env, &original);
    lookdev::render::progressive::accumulate(&mut r, spp, |_| {}).unwrap();
    let before = bits(&r.read_radiance().unwrap());
    assert_eq!(r.set_stacks_local(&coated).unwrap(), None, "everything restarts");
    assert_eq!((r.samples(), r.restarted_region(), r.lobes()), (0, None, coated.lobes()));
    lookdev::render::progressive::accumulate(&mut r, spp, |_| {}).unwrap();
    let mut fresh = renderer(&ctx, &gbuffer, &env, &coated);
    lookdev::render::progressive::accumulate(&mut fresh, spp, |_| {}).unwrap();
    let after = bits(&r.read_radiance().unwrap());
    assert!(after == bits(&fresh.read_radiance().unwrap()), "equal to a fresh render of the edit, bit for bit");
    assert!(after != before, "the coat shows");

    assert_eq!(r.set_stacks_local(&original).unwrap(), None, "taking the coat off restarts everything too");
    lookdev::render::progressive::accumulate(&mut r, spp, |_| {}).unwrap();
    assert!(bits(&r.read_radiance().unwrap()) == before, "the first image, bit for bit");
    drop((r, fresh));
    common::gpu::finish(ctx);
}

/// The resolve kernel leaves its map code out while no layer binds a map. A renderer whose
/// stacks come to bind one (the bottom layer's roughness times a ramp) resolves it as the CPU
/// blend does, and as a fresh renderer does, bit for bit; unbinding it gives back the first
/// material.
#[test]
fn binding_a_map_resolves_it_on_a_renderer_made_without_maps() {
    let ctx = common::gpu::context();
    let env = Environment::default_builtin();
    let mut gbuffer = orthographic_sphere(48);
    let width = gbuffer.width as usize;
    let ramp = (0..gbuffer.pixel_count()).map(|i| (i % width) as f32 / width as f32).collect();
    gbuffer.maps.insert("rough".into(), ramp);
    let mapped_text = SPHERE.replacen(
        "[[object.layer]]\npreset = \"gold\"",
        "[object.layer.map]\nroughness = \"rough\"\n[[object.layer]]\npreset = \"gold\"",
        1,
    );
    let (plain, mapped) = (pack(&look(SPHERE), &gbuffer), pack(&look(&mapped_text), &gbuffer));
    assert!(!plain.binds_maps() && mapped.binds_maps());
    let resolved = |r: &Renderer| r.read_resolved().unwrap();

    let mut r = renderer(&ctx, &gbuffer, &env, &plain);
    let first = bits(&resolved(&r));
    r.set_stacks(&mapped).unwrap();
    let with_map = resolved(&r);
    assert!(bits(&with_map) != first, "the map changes the material");
    assert!(bits(&with_map) == bits(&resolved(&renderer(&ctx, &gbuffer, &env, &mapped))), "as a fresh renderer");
    let pixels = gbuffer.pixel_count();
    for i in (0..pixels).filter(|&i| gbuffer.coverage[i] > 0.0) {
        let cpu = mapped.resolve_gbuffer_pixel(&gbuffer, i).to_gpu();
        for (k, &want) in cpu.iter().enumerate() {
            let got = with_map[(k / 4) * pixels + i][k % 4];
            assert!(
                (got - want).abs() <= 1e-6 * want.abs().max(1.0),
                "pixel {i}, value {k}: {got} against the CPU's {want}"
            );
        }
    }
    r.set_stacks(&plain).unwrap();
    assert!(bits(&resolved(&r)) == first, "unbound, the first material");
    drop(r);
    common::gpu::finish(ctx);
}
