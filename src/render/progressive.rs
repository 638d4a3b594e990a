//! Progressive accumulation to a target sample count, in dispatches sized to the device's speed.

use super::Renderer;
use crate::Result;
use std::time::{Duration, Instant};

/// How long one dispatch may take: long enough to amortise each pass's per-pixel set-up (on a
/// CPU driver that set-up costs as much as a couple of samples), short enough for a responsive
/// progress bar and well below any driver watchdog.
const TARGET_DISPATCH: Duration = Duration::from_millis(500);

/// The slowest speed assumed of a device, in samples a second, to size the first dispatch
/// before the renderer has timed one: about a quarter of lavapipe's on two cores. The first
/// dispatch of a small image then holds several samples, so that a short render takes two
/// dispatches rather than four, each of which pays the per-pixel set-up again.
const MIN_SPEED: f64 = 5e6;

/// Samples per pixel of the first dispatch over `pixels` pixels. With `pace`, the samples a
/// second of the renderer's last timed dispatch (set-up included, which understates its
/// speed): all `spp` when that pace does them within [`TARGET_DISPATCH`], since every pass
/// costs a set-up of a couple of samples on a CPU driver; otherwise what the device does in an
/// eighth of it, at that pace or at [`MIN_SPEED`] before one. At least 1 and at most `spp`.
fn first_batch(pixels: usize, spp: u32, pace: Option<f64>) -> u32 {
    let pixels = pixels.max(1) as f64;
    if pace.is_some_and(|pace| pixels * spp as f64 / pace <= TARGET_DISPATCH.as_secs_f64()) {
        return spp.max(1);
    }
    let samples = pace.unwrap_or(MIN_SPEED) * (TARGET_DISPATCH / 8).as_secs_f64() / pixels;
    (samples as u32).clamp(1, spp.max(1))
}

/// What a progressive render measured.
#[derive(Clone, Copy, Debug, Default)]
pub struct RenderStats {
    pub wall: Duration,
    /// Sum of the relight kernels' GPU time, when the device has timestamps.
    pub gpu_seconds: Option<f64>,
    pub dispatches: u32,
    /// Under a noise threshold, the mean samples per covered pixel.
    pub mean_spp: Option<f64>,
}

/// Accumulates until the renderer holds `spp` samples per pixel, calling `progress(samples)`
/// after each dispatch. The split into dispatches never changes the result: the kernel adds
/// samples in index order whatever the split. Under a noise threshold, `spp` is the most a
/// pixel takes, and the render ends early once every pixel has stopped.
pub fn accumulate(renderer: &mut Renderer, spp: u32, mut progress: impl FnMut(u32)) -> Result<RenderStats> {
    let start = Instant::now();
    let mut stats = RenderStats::default();
    let mut batch = first_batch(renderer.pixels_to_relight(), spp, renderer.pace());
    if let Some(noise) = renderer.noise_threshold() {
        // No pixel stops before its minimum: a render whose pixels all stop there ends there.
        batch = batch.min(noise.min_samples.max(1));
    }
    while renderer.samples() < spp && renderer.active_pixels() != Some(0) {
        let samples = renderer.samples();
        // Under a noise threshold a dispatch ends at the next stop test: a pixel that stops
        // there would otherwise idle in its SIMD group while the others go on.
        let count = renderer.noise_threshold().map_or(spp, |n| samples + n.to_checkpoint(samples)).min(spp) - samples;
        let count = batch.min(count);
        let pixels = renderer.pixels_to_relight();
        let dispatch_start = Instant::now();
        let gpu = renderer.render_samples(count)?;
        let elapsed = dispatch_start.elapsed();
        if !elapsed.is_zero() {
            renderer.set_pace(pixels as f64 * count as f64 / elapsed.as_secs_f64());
        }
        stats.dispatches += 1;
        stats.gpu_seconds = match (stats.gpu_seconds, gpu) {
            (Some(total), Some(t)) => Some(total + t),
            (None, Some(t)) if stats.dispatches == 1 => Some(t),
            _ => None,
        };
        progress(renderer.samples());
        // A pass costs a fixed set-up plus a cost per sample, so the time per sample of a small
        // batch overstates that of a large one: the rest goes in one dispatch once this one's
        // pace says it would take less than the target, and otherwise the batch grows
        // geometrically rather than by extrapolating.
        let remaining = spp.saturating_sub(renderer.samples());
        if elapsed.mul_f64(remaining as f64 / count as f64) < TARGET_DISPATCH {
            batch = remaining.max(1);
        } else if elapsed < TARGET_DISPATCH / 8 {
            batch = batch.saturating_mul(4);
        } else if elapsed < TARGET_DISPATCH / 2 {
            batch = batch.saturating_mul(2);
        } else if elapsed > TARGET_DISPATCH * 2 {
            batch = (batch / 2).max(1);
        }
    }
    stats.wall = start.elapsed();
    if renderer.noise_threshold().is_some() && renderer.covered_pixels() > 0 {
        let counts = renderer.read_sample_counts()?;
        stats.mean_spp = Some(counts.iter().map(|&n| n as f64).sum::<f64>() / renderer.covered_pixels() as f64);
    }
    Ok(stats)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_dispatch_holds_what_the_device_does_in_an_eighth_of_the_target() {
        // The 256² sphere's 42208 covered pixels: 7 samples, 0.3 M in all.
        assert_eq!(first_batch(42_208, 64, None), 7);
        // A 1080p frame mostly covered, or more pixels than a slow device does in that time: 1.
        assert_eq!(first_batch(1_500_000, 64, None), 1);
        assert_eq!(first_batch(400_000, 64, None), 1);
        // Never more than the render asks for, nor less than one.
        assert_eq!(first_batch(100, 16, None), 16);
        assert_eq!(first_batch(0, 4, None), 4);
        assert_eq!(first_batch(100, 0, None), 1);
        // Once the renderer has timed a dispatch, its pace: the ball's 296,856 pixels at
        // 16 M samples a second do 16 samples in 0.30 s, within the target, so in one
        // dispatch; 64 would take 1.19 s, so the first holds the 3 done in 62.5 ms. A slower
        // pace than the assumed least, fewer.
        assert_eq!(first_batch(296_856, 16, Some(16e6)), 16);
        assert_eq!(first_batch(296_856, 64, Some(16e6)), 3);
        assert_eq!(first_batch(42_208, 64, Some(1e6)), 1);
    }
}
