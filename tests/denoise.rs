//! The viewer's display filter (`denoise.comp`, `Renderer::denoise`): it brings a few samples
//! nearer the converged image, keeps each object's colour at the objects' edges, and leaves
//! the accumulation, and so every saved image, untouched.

mod common;

use common::scenes::{look, renderer};
use lookdev::environment::Environment;
use lookdev::gbuffer::GBuffer;
use lookdev::material::Look;
use lookdev::render::Lighting;
use lookdev::shading::tonemap::Tonemap;

const SIZE: u32 = 128;

/// Root-mean-square difference of two RGBA8 images over the covered pixels' colour, in 8-bit steps.
fn rmse(a: &[u8], b: &[u8], coverage: &[f32]) -> f64 {
    let (mut sum, mut count) = (0.0, 0);
    for (i, &c) in coverage.iter().enumerate() {
        if c > 0.0 {
            for k in 0..3 {
                let d = a[i * 4 + k] as f64 - b[i * 4 + k] as f64;
                sum += d * d;
                count += 1;
            }
        }
    }
    (sum / count as f64).sqrt()
}

/// On the built-in ball with its default look, 4 samples filtered are nearer 256 samples than
/// 4 samples as they are.
#[test]
fn the_filter_brings_a_few_samples_nearer_the_converged_image() {
    let ctx = common::gpu::context();
    let gbuffer = GBuffer::shaderball(SIZE, SIZE);
    let env = Environment::studio();
    let look = Look::builtin_default();
    let lighting = Lighting::default();
    let mut converged = renderer(&ctx, &gbuffer, &env, &look, lighting);
    converged.render_samples(256).unwrap();
    let reference = converged.read_display(0.0, Tonemap::Aces).unwrap();

    let mut r = renderer(&ctx, &gbuffer, &env, &look, lighting);
    r.render_samples(4).unwrap();
    let raw = r.read_display(0.0, Tonemap::Aces).unwrap();
    let radiance = r.read_radiance().unwrap();
    r.denoise(0.0, Tonemap::Aces).unwrap();
    let filtered = r.read_denoised().unwrap();
    let (before, after) = (rmse(&raw, &reference, &gbuffer.coverage), rmse(&filtered, &reference, &gbuffer.coverage));
    eprintln!("RMSE against 256 spp, 8-bit steps: 4 spp {before:.2}, filtered {after:.2}");
    assert!(after < 0.75 * before, "the filter should bring 4 spp nearer 256 spp: {before:.2} -> {after:.2}");

    // The filter only shows: the sums, the radiance and the display pixels saved are as they were.
    assert_eq!(r.read_display(0.0, Tonemap::Aces).unwrap(), raw);
    let bits = |v: &[[f32; 4]]| v.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&r.read_radiance().unwrap()), bits(&radiance));
    common::gpu::finish(ctx);
}

/// Each object shows only its own emission: every fully covered pixel beside another object
/// keeps its own object's colour through the filter.
#[test]
fn the_filter_does_not_blur_across_objects() {
    let ctx = common::gpu::context();
    let gbuffer = GBuffer::shaderball(SIZE, SIZE);
    let look = look(common::scenes::TWO_EMITTERS);
    let dark = Lighting { rotation_degrees: 0.0, intensity: 0.0, background: false };
    let mut r = renderer(&ctx, &gbuffer, &Environment::studio(), &look, dark);
    r.render_samples(1).unwrap();
    let raw = r.read_display(0.0, Tonemap::Aces).unwrap();
    r.denoise(0.0, Tonemap::Aces).unwrap();
    let filtered = r.read_denoised().unwrap();
    let size = SIZE as i64;
    let mut edge_pixels = 0;
    for y in 0..size {
        for x in 0..size {
            let i = (y * size + x) as usize;
            if gbuffer.coverage[i] < 1.0 {
                continue;
            }
            let id = gbuffer.object_id[i];
            let beside_another = [(-1, 0), (1, 0), (0, -1), (0, 1)].iter().any(|(dx, dy)| {
                let (nx, ny) = (x + dx, y + dy);
                (0..size).contains(&nx) && (0..size).contains(&ny) && {
                    let n = (ny * size + nx) as usize;
                    gbuffer.coverage[n] > 0.0 && gbuffer.object_id[n] != id
                }
            });
            if !beside_another {
                continue;
            }
            edge_pixels += 1;
            for k in 0..4 {
                let (a, b) = (filtered[i * 4 + k], raw[i * 4 + k]);
                assert!(
                    a.abs_diff(b) <= 1,
                    "pixel {x},{y} of object {id}: filtered {a}, its own colour {b} (channel {k})"
                );
            }
        }
    }
    assert!(edge_pixels > 20, "the ball meets the pedestal along {edge_pixels} pixels");
    common::gpu::finish(ctx);
}
