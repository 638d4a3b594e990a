//! Restarting some pixels alone (`Renderer::restart_pixels`): the others keep their samples bit
//! for bit, the restarted ones are relit alone from sample 0 until they catch up, and the image
//! then equals a fresh render at the same sample count, bit for bit, however the passes split.

mod common;

use common::scenes::renderer;
use lookdev::environment::Environment;
use lookdev::gbuffer::GBuffer;
use lookdev::material::Look;
use lookdev::render::renderer::Accumulate;
use lookdev::render::{Lighting, Renderer};
use lookdev::shading::tonemap::Tonemap;

const SIZE: u32 = 80;

fn bits<const N: usize>(values: &[[f32; N]]) -> Vec<u32> {
    values.iter().flatten().map(|v| v.to_bits()).collect()
}

/// The pixels of object `id`, ascending.
fn object_pixels(gbuffer: &GBuffer, id: u32) -> Vec<u32> {
    (0..gbuffer.object_id.len() as u32)
        .filter(|&p| gbuffer.object_id[p as usize] == id && gbuffer.coverage[p as usize] > 0.0)
        .collect()
}

/// Passes in bands of `band` rows of `count` samples each, as the viewer's sweep does them.
fn sweep(r: &mut Renderer, band: u32, count: u32) {
    let mut first = 0;
    while first < r.height {
        r.render_rows(first, band, count).unwrap();
        r.finalize_rows(first, band, 0.0, Tonemap::Aces).unwrap();
        first += band;
    }
}

/// Brings every pixel to the most-sampled row's count, a sample at a time, as the viewer does
/// before saving.
fn complete(r: &mut Renderer) {
    while let Some((first, rows)) = r.lagging_rows() {
        r.render_rows(first, rows, 1).unwrap();
    }
}

fn fresh(ctx: &lookdev::gpu::Context, gbuffer: &GBuffer, accumulate: Accumulate, spp: u32) -> Renderer {
    let mut r = renderer(ctx, gbuffer, &Environment::studio(), &Look::builtin_default(), Lighting::default());
    r.set_accumulate(accumulate).unwrap();
    r.render_samples(spp).unwrap();
    r
}

/// One object's pixels restarted after 5 spp: while they catch up, the others keep their bits
/// and they hold what a fresh render at their own count holds; after, the whole image (and the
/// AOV sums) is a fresh render's at 5 spp, for catch-ups split in several ways.
#[test]
fn restarted_pixels_catch_up_to_a_fresh_render_and_the_rest_keep_their_bits() {
    let ctx = common::gpu::context();
    let gbuffer = GBuffer::shaderball(SIZE, SIZE);
    let accumulate = Accumulate { lobes: true, variance: true };
    let reference = fresh(&ctx, &gbuffer, accumulate, 5);
    let at_two = fresh(&ctx, &gbuffer, accumulate, 2);
    let (reference_radiance, two_radiance) = (reference.read_radiance().unwrap(), at_two.read_radiance().unwrap());
    let ids: std::collections::BTreeSet<u32> = gbuffer.object_id.iter().copied().collect();
    let id = *ids.iter().find(|&&id| object_pixels(&gbuffer, id).len() > 100).unwrap();
    let chosen = object_pixels(&gbuffer, id);
    let chosen_set: std::collections::HashSet<u32> = chosen.iter().copied().collect();

    for split in [&[9][..], &[1, 1, 1], &[2, 4]] {
        let mut r = fresh(&ctx, &gbuffer, accumulate, 2);
        r.render_samples(3).unwrap();
        let before = r.read_radiance().unwrap();
        r.restart_pixels(&chosen);
        assert_eq!(r.restarted_region(), Some((chosen.len(), 0, 5)));
        assert_eq!(r.samples(), 0);
        r.render_samples(2).unwrap();
        assert_eq!(r.restarted_region(), Some((chosen.len(), 2, 5)));
        assert_eq!(r.samples(), 2);
        let partway = r.read_radiance().unwrap();
        for p in 0..partway.len() {
            let expected = if chosen_set.contains(&(p as u32)) { two_radiance[p] } else { before[p] };
            assert_eq!(bits(&[partway[p]]), bits(&[expected]), "pixel {p} partway, split {split:?}");
        }
        for &count in split {
            r.render_samples(count).unwrap();
        }
        assert_eq!(r.restarted_region(), None, "caught up, split {split:?}");
        assert_eq!(r.samples(), 5, "no further than the rest: split {split:?}");
        assert_eq!(bits(&r.read_radiance().unwrap()), bits(&reference_radiance), "split {split:?}");
        assert_eq!(
            bits(&r.read_lobes(&gbuffer.coverage).unwrap().concat()),
            bits(&reference.read_lobes(&gbuffer.coverage).unwrap().concat())
        );
        let variance = |r: &Renderer| r.read_variance(&gbuffer.coverage).unwrap().iter().map(|v| v.to_bits()).collect();
        let (got, want): (Vec<u32>, Vec<u32>) = (variance(&r), variance(&reference));
        assert_eq!(got, want);
    }
    common::gpu::finish(ctx);
}

/// Restarts in the middle of a banded pass (rows a pass apart), twice over overlapping sets,
/// with uncovered pixels among them, caught up band by band: the same bits as a fresh render.
#[test]
fn restarts_mid_pass_and_over_each_other_catch_up_band_by_band() {
    let ctx = common::gpu::context();
    let gbuffer = GBuffer::shaderball(SIZE, SIZE);
    let mut r = fresh(&ctx, &gbuffer, Accumulate::default(), 2);
    // Rows 0..40 get a third sample; the rest keep two.
    r.render_rows(0, 40, 1).unwrap();
    let first: Vec<u32> = (0..SIZE * SIZE).filter(|p| p % 7 == 0).collect();
    r.restart_pixels(&first);
    let (pixels, theirs, rest) = r.restarted_region().unwrap();
    let covered = first.iter().filter(|&&p| gbuffer.coverage[p as usize] > 0.0).count();
    assert_eq!((pixels, theirs, rest), (covered, 0, 2), "uncovered pixels are left out");
    sweep(&mut r, 13, 1);
    let second: Vec<u32> = (0..SIZE * SIZE).filter(|p| p % 5 == 0).collect();
    r.restart_pixels(&second);
    assert_eq!(r.restarted_region().unwrap().1, 0, "earlier restarted pixels restart with these");
    sweep(&mut r, 11, 2);
    complete(&mut r);
    assert_eq!(r.restarted_region(), None);
    assert_eq!(r.samples(), 3);
    let reference = fresh(&ctx, &gbuffer, Accumulate::default(), 3);
    assert_eq!(bits(&r.read_radiance().unwrap()), bits(&reference.read_radiance().unwrap()));
    // A full restart forgets the restarted pixels.
    r.restart_pixels(&first);
    r.restart();
    assert_eq!(r.restarted_region(), None);
    r.render_samples(3).unwrap();
    assert_eq!(bits(&r.read_radiance().unwrap()), bits(&reference.read_radiance().unwrap()));
    common::gpu::finish(ctx);
}
