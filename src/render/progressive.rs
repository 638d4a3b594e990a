//! Progressive accumulation to a target sample count, in dispatches sized to the device's speed.

use super::Renderer;
use crate::Result;
use std::time::{Duration, Instant};

/// How long one dispatch may take: long enough to amortise each pass's per-pixel set-up (on a
/// CPU driver that set-up costs as much as a couple of samples), short enough for a responsive
/// progress bar and well below any driver watchdog.
const TARGET_DISPATCH: Duration = Duration::from_millis(500);

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
    let mut batch = 1u32;
    while renderer.samples() < spp && renderer.active_pixels() != Some(0) {
        let count = batch.min(spp - renderer.samples());
        let dispatch_start = Instant::now();
        let gpu = renderer.render_samples(count)?;
        let elapsed = dispatch_start.elapsed();
        stats.dispatches += 1;
        stats.gpu_seconds = match (stats.gpu_seconds, gpu) {
            (Some(total), Some(t)) => Some(total + t),
            (None, Some(t)) if stats.dispatches == 1 => Some(t),
            _ => None,
        };
        progress(renderer.samples());
        // Grow the batch while dispatches stay under the target. A pass costs a fixed set-up
        // plus a cost per sample, so the time per sample of a small batch overstates that of a
        // large one: growing geometrically, rather than by extrapolating, still gets there.
        if elapsed < TARGET_DISPATCH / 8 {
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
