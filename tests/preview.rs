//! The viewer's preview after a change (`Renderer::render_preview`), on the renderer alone: it
//! is a whole frame at the new state, exact where it relit, interpolated within each object,
//! and it changes no bits of the accumulation the passes then make.

mod common;

use common::scenes::{look, renderer};
use lookdev::environment::Environment;
use lookdev::gbuffer::GBuffer;
use lookdev::material::Look;
use lookdev::render::renderer::Accumulate;
use lookdev::render::{Lighting, Renderer};
use lookdev::shading::tonemap::Tonemap;

const SIZE: u32 = 96;

fn ball() -> GBuffer {
    GBuffer::shaderball(SIZE, SIZE)
}

/// The rows of `height` in bands of `band`, each relit with `count` samples, as the viewer's
/// sweep does them.
fn sweep(r: &mut Renderer, band: u32, count: u32) {
    let mut first = 0;
    while first < r.height {
        r.render_rows(first, band, count).unwrap();
        r.finalize_rows(first, band, 0.0, Tonemap::Aces).unwrap();
        first += band;
    }
}

fn bits<const N: usize>(radiance: &[[f32; N]]) -> Vec<u32> {
    radiance.iter().flatten().map(|v| v.to_bits()).collect()
}

/// A preview, made after an earlier accumulation and a change, then passes in bands: the same
/// bits as the passes alone from a fresh renderer, for the beauty and the AOV sums beside it.
#[test]
fn a_preview_changes_no_bits_of_the_render() {
    let ctx = common::gpu::context();
    let gbuffer = ball();
    let env = Environment::studio();
    let look = Look::builtin_default();
    let before = Lighting::default();
    let after = Lighting { rotation_degrees: 120.0, intensity: 2.0, background: true };
    for accumulate in [Accumulate::default(), Accumulate { lobes: true, variance: true }] {
        for block in [2, 4, 8] {
            let mut previewed = renderer(&ctx, &gbuffer, &env, &look, before);
            previewed.set_accumulate(accumulate).unwrap();
            previewed.render_samples(2).unwrap();
            previewed.set_lighting(after);
            previewed.render_preview(block).unwrap();
            previewed.finalize_rows(0, SIZE, 0.0, Tonemap::Aces).unwrap();
            sweep(&mut previewed, 17, 1);
            sweep(&mut previewed, 29, 2);

            let mut plain = renderer(&ctx, &gbuffer, &env, &look, after);
            plain.set_accumulate(accumulate).unwrap();
            plain.render_samples(3).unwrap();
            let what = format!("block {block}, {accumulate:?}");
            assert_eq!(bits(&previewed.read_radiance().unwrap()), bits(&plain.read_radiance().unwrap()), "{what}");
            assert_eq!(
                previewed.read_display(0.0, Tonemap::Aces).unwrap(),
                plain.read_display(0.0, Tonemap::Aces).unwrap()
            );
            if accumulate.lobes {
                assert_eq!(
                    bits(&previewed.read_lobes(&gbuffer.coverage).unwrap().concat()),
                    bits(&plain.read_lobes(&gbuffer.coverage).unwrap().concat()),
                    "{what}"
                );
            }
        }
    }
    common::gpu::finish(ctx);
}

/// The preview's surface radiance at every pixel, worked out on the CPU from the first pass's
/// surface radiance `first` as `finalize.comp` documents it: bilinear between the covered block
/// corners of the pixel's own object, else those within two blocks, else any covered corner
/// within two blocks, else 0.
fn cpu_preview(gbuffer: &GBuffer, first: &[[f32; 3]], block: i64) -> Vec<[f32; 3]> {
    let (width, height) = (gbuffer.width as i64, gbuffer.height as i64);
    let index = |x: i64, y: i64| (y * width + x) as usize;
    let mut out = vec![[0.0f32; 3]; first.len()];
    for y in 0..height {
        for x in 0..width {
            let i = index(x, y);
            if gbuffer.coverage[i] <= 0.0 {
                continue;
            }
            for (reach, same_object) in [(block, true), (2 * block, true), (2 * block, false)] {
                let (mut total, mut weight) = ([0.0f64; 3], 0.0f64);
                for cy in (0..height).step_by(block as usize).filter(|cy| (cy - y).abs() < reach) {
                    for cx in (0..width).step_by(block as usize).filter(|cx| (cx - x).abs() < reach) {
                        let c = index(cx, cy);
                        if gbuffer.coverage[c] <= 0.0 || (same_object && gbuffer.object_id[c] != gbuffer.object_id[i]) {
                            continue;
                        }
                        let w =
                            (1.0 - (cx - x).abs() as f64 / reach as f64) * (1.0 - (cy - y).abs() as f64 / reach as f64);
                        (0..3).for_each(|k| total[k] += w * first[c][k] as f64);
                        weight += w;
                    }
                }
                if weight > 0.0 {
                    out[i] = total.map(|t| (t / weight) as f32);
                    break;
                }
            }
        }
    }
    out
}

/// After a change of the whole image (the light turned and three times as bright), before any
/// pass, the preview is the new state everywhere: every pixel is what the CPU makes of the
/// first pass's samples at the blocks' corners (so no row is left from the old state), the
/// corners are the first pass's exactly, and the background is the new one, exactly. A band of
/// the first pass then replaces its rows with the pass's own.
#[test]
fn the_preview_is_a_whole_frame_at_the_new_state() {
    let ctx = common::gpu::context();
    let gbuffer = ball();
    let env = Environment::studio();
    let look = Look::builtin_default();
    let before = Lighting::default();
    for background in [false, true] {
        let after = Lighting { rotation_degrees: 150.0, intensity: 3.0, background };
        let mut first_pass = renderer(&ctx, &gbuffer, &env, &look, after);
        first_pass.render_samples(1).unwrap();
        let one_sample = first_pass.read_radiance().unwrap();

        let mut r = renderer(&ctx, &gbuffer, &env, &look, before);
        r.render_samples(4).unwrap();
        r.finalize_rows(0, SIZE, 0.0, Tonemap::Aces).unwrap();
        let old = r.read_shown_radiance().unwrap();
        r.set_lighting(after);
        for block in [2i64, 4, 8] {
            if block > 2 {
                r.restart();
            }
            r.render_preview(block as u32).unwrap();
            r.finalize_rows(0, SIZE, 0.0, Tonemap::Aces).unwrap();
            let shown = r.read_shown_radiance().unwrap();
            let changed = shown.iter().zip(&old).filter(|(a, b)| a != b).count();
            assert!(changed > shown.len() * 9 / 10, "the preview replaces the old image: {changed} pixels changed");
            for (i, pixel) in shown.iter().enumerate() {
                let (x, y) = (i as i64 % SIZE as i64, i as i64 / SIZE as i64);
                let coverage = gbuffer.coverage[i];
                if coverage <= 0.0 || (x % block == 0 && y % block == 0) {
                    assert_eq!(bits(&[*pixel]), bits(&one_sample[i..=i]), "pixel {x},{y}, block {block}");
                }
            }
            if !background {
                // Radiance is the surface's times coverage: the first pass's surface radiance is
                // its radiance over coverage.
                let first: Vec<[f32; 3]> = one_sample
                    .iter()
                    .zip(&gbuffer.coverage)
                    .map(|(p, &a)| if a > 0.0 { [p[0] / a, p[1] / a, p[2] / a] } else { [0.0; 3] })
                    .collect();
                let expected = cpu_preview(&gbuffer, &first, block);
                for (i, pixel) in shown.iter().enumerate() {
                    let a = gbuffer.coverage[i];
                    for k in 0..3 {
                        let want = a * expected[i][k];
                        let close = (pixel[k] - want).abs() <= 1e-5 * want.abs().max(1e-3);
                        assert!(close, "pixel {i}, block {block}: {} against the CPU's {want}", pixel[k]);
                    }
                    assert_eq!(pixel[3], a);
                }
            }
        }
        // A band of the first pass replaces the preview's rows with the pass's own.
        r.render_rows(0, 40, 1).unwrap();
        r.finalize_rows(0, 40, 0.0, Tonemap::Aces).unwrap();
        let radiance = r.read_shown_radiance().unwrap();
        let band = (SIZE * 40) as usize;
        assert_eq!(bits(&radiance[..band]), bits(&one_sample[..band]));
        // A preview would overwrite samples the passes made, so it comes first or not at all.
        assert!(r.render_preview(4).is_err());
    }
    common::gpu::finish(ctx);
}

/// Lit by nothing, each object shows only its emission: every fully covered pixel of the
/// preview that has a relit corner of its own object within reach shows exactly its own
/// object's emission, however near another object it lies.
#[test]
fn the_preview_keeps_each_object_to_its_own_colour() {
    let ctx = common::gpu::context();
    let gbuffer = ball();
    let env = Environment::studio();
    let look = look(common::scenes::TWO_EMITTERS);
    let dark = Lighting { rotation_degrees: 0.0, intensity: 0.0, background: false };
    let emission = |id: u32| if id == 1 { [0.9f32, 0.05, 0.0] } else { [0.0, 0.8, 0.1] };
    let block = 4i64;
    let mut r = renderer(&ctx, &gbuffer, &env, &look, dark);
    r.render_preview(block as u32).unwrap();
    r.finalize_rows(0, SIZE, 0.0, Tonemap::Aces).unwrap();
    let radiance = r.read_shown_radiance().unwrap();
    let size = SIZE as i64;
    let index = |x: i64, y: i64| (y * size + x) as usize;
    let mut edge_pixels = 0;
    for y in 0..size {
        for x in 0..size {
            let i = index(x, y);
            let id = gbuffer.object_id[i];
            if gbuffer.coverage[i] < 1.0 {
                continue;
            }
            // A corner of the same object within the bilinear reach.
            let has_own_corner = (0..size).step_by(block as usize).any(|cy| {
                (0..size).step_by(block as usize).any(|cx| {
                    let c = index(cx, cy);
                    (cx - x).abs() < block
                        && (cy - y).abs() < block
                        && gbuffer.object_id[c] == id
                        && gbuffer.coverage[c] > 0.0
                })
            });
            if !has_own_corner {
                continue;
            }
            let near_other = [(-1, 0), (1, 0), (0, -1), (0, 1)].iter().any(|(dx, dy)| {
                let (nx, ny) = (x + dx, y + dy);
                (0..size).contains(&nx) && (0..size).contains(&ny) && {
                    let n = index(nx, ny);
                    gbuffer.coverage[n] > 0.0 && gbuffer.object_id[n] != id
                }
            });
            edge_pixels += near_other as u32;
            let [red, green, blue, alpha] = radiance[i];
            let expected = emission(id);
            let close = |a: f32, b: f32| (a - b).abs() < 1e-5;
            assert!(
                close(red, expected[0]) && close(green, expected[1]) && close(blue, expected[2]) && alpha == 1.0,
                "pixel {x},{y} of object {id} shows {:?}, not its emission {expected:?}",
                radiance[i]
            );
        }
    }
    assert!(edge_pixels > 20, "the ball meets the pedestal along {edge_pixels} pixels");
    common::gpu::finish(ctx);
}

/// A preview block outside 2..=8 is refused with the range named.
#[test]
fn a_preview_block_out_of_range_is_refused() {
    let ctx = common::gpu::context();
    let gbuffer = ball();
    let mut r = renderer(&ctx, &gbuffer, &Environment::studio(), &Look::builtin_default(), Lighting::default());
    for block in [0, 1, 9] {
        let e = r.render_preview(block).unwrap_err().to_string();
        assert!(e.contains("2 to 8"), "{e}");
    }
    common::gpu::finish(ctx);
}
