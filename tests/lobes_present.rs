//! The relight kernel is specialised for the lobes a scene's stacks have
//! (`PackedStacks::lobes`): the kernel without the diffuse or clearcoat lobes renders what the
//! kernel with every lobe renders, up to float rounding. Each scene is rendered twice: as it
//! is, and with a layer of opacity 0 on top that has every lobe, which leaves every pixel's
//! material the same, bit for bit, but gives the stacks every lobe.

mod common;

use common::scenes::{look, orthographic_sphere, renderer};
use lookdev::environment::Environment;
use lookdev::gpu::inject::{fail_at, Step};
use lookdev::material::stack::{LobesPresent, PackedStacks};
use lookdev::render::{Lighting, Renderer};
use std::path::Path;

/// A layer that changes no pixel and has every lobe.
const HIDDEN_LAYER: &str = "[[object.layer]]\nopacity = 0.0\n[object.layer.set]\nmetallic = 0.0\nclearcoat = 1.0\n";

fn render(r: &mut Renderer, spp: u32) -> Vec<[f32; 4]> {
    r.set_seed(3);
    lookdev::render::progressive::accumulate(r, spp, |_| {}).unwrap();
    r.read_radiance().unwrap()
}

#[test]
fn a_kernel_without_absent_lobes_renders_what_one_with_every_lobe_renders() {
    let ctx = common::gpu::context();
    let env = Environment::default_builtin();
    let gbuffer = orthographic_sphere(40);
    let lighting = Lighting { rotation_degrees: 75.0, ..Lighting::default() };
    let cases = [
        ("preset = \"gold\"\n", LobesPresent { diffuse: false, clearcoat: false }),
        (
            "preset = \"brushed-steel\"\n[object.layer.set]\nclearcoat = 0.8\n",
            LobesPresent { diffuse: false, clearcoat: true },
        ),
        (
            "preset = \"red-plastic\"\n[object.layer.set]\nclearcoat = 0.0\n",
            LobesPresent { diffuse: true, clearcoat: false },
        ),
    ];
    for (material, lobes) in cases {
        let text = format!("[[object]]\n[[object.layer]]\n{material}");
        let mut specialised = renderer(&ctx, &gbuffer, &env, &look(&text), lighting);
        let mut general = renderer(&ctx, &gbuffer, &env, &look(&format!("{text}{HIDDEN_LAYER}")), lighting);
        assert_eq!(specialised.lobes(), lobes, "{material}");
        assert_eq!(general.lobes(), LobesPresent::default(), "{material}");
        let bits = |r: &Renderer| r.read_resolved().unwrap().iter().map(|p| p.map(f32::to_bits)).collect::<Vec<_>>();
        assert!(bits(&specialised) == bits(&general), "{material}: the hidden layer changes no material");

        let (a, b) = (render(&mut specialised, 16), render(&mut general, 16));
        let mut lit = 0;
        for (x, y) in a.iter().zip(&b) {
            for c in 0..3 {
                let scale = x[c].abs().max(y[c].abs()).max(1e-3);
                assert!((x[c] - y[c]).abs() <= 1e-5 * scale, "{material}: {x:?} against {y:?}");
            }
            lit += (x[0] > 0.0) as usize;
        }
        assert!(lit > 100, "{material}: the sphere is lit ({lit} pixels)");
    }
    common::gpu::finish(ctx);
}

/// New stacks that need another specialisation, which the driver refuses, leave the renderer
/// as it was: the same kernel, lobes and stacks, rendering the same image.
#[test]
fn a_refused_respecialisation_leaves_the_renderer_as_it_was() {
    let ctx = common::gpu::context();
    let env = Environment::default_builtin();
    let gbuffer = orthographic_sphere(24);
    let gold = "[[object]]\n[[object.layer]]\npreset = \"gold\"\n";
    let mut r = renderer(&ctx, &gbuffer, &env, &look(gold), Lighting::default());
    let before = render(&mut r, 4);
    // A rougher gold under a coat: the stacks change what every pixel shows, beside the lobes.
    let coated = look(&format!("{gold}[object.layer.set]\nclearcoat = 1.0\nroughness = 0.6\n"));
    let ids = lookdev::render::scene::covered_object_ids(&gbuffer);
    let coated = PackedStacks::pack(&coated, ids, &gbuffer, Path::new("test g-buffer")).unwrap();
    {
        let fail = fail_at(Step::Pipeline);
        assert!(r.set_stacks(&coated).is_err(), "the refused pipeline is an error");
        assert!(fail.reached());
    }
    assert_eq!(r.lobes(), LobesPresent { diffuse: false, clearcoat: false });
    r.restart();
    let after = render(&mut r, 4);
    let bits = |p: &[[f32; 4]]| p.iter().map(|v| v.map(f32::to_bits)).collect::<Vec<_>>();
    assert!(bits(&after) == bits(&before), "the same image, bit for bit");
    drop(r);
    common::gpu::finish(ctx);
}
