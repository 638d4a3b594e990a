//! Progressive rendering bounded by a time budget: each step relights a band of rows, sized from
//! the measured speed so that it fits the budget it is given; a pass is done when the bands have
//! swept the image. The frame scheduler ([`super::schedule`]) gives a short budget while the
//! artist interacts, so that frames stay responsive, and long ones while nobody does, so that
//! the image converges as fast as `lookdev render` makes it: a band is then the whole image, and
//! it takes as many samples as fit.
//!
//! The first step after a change is a preview: one sample per 2×2, 4×4 (or, on a very slow
//! device, 8×8) block, the smallest block that fits the interactive budget, interpolated to every
//! pixel. So the whole image shows the new state at once, and the passes replace the preview
//! band by band: no row ever shows the state before the change.
//!
//! An edit of the materials alone restarts only the pixels it changed, with no preview: the
//! bands relight those pixels alone, the first sweep one sample each, the next up to
//! [`CATCH_UP_SAMPLES`], until they have caught up with the rest
//! (docs/commands.md#edit-local-re-convergence).
//!
//! Steps only relight; the display pixels of the rows they changed are made once, before the
//! window is drawn ([`Renderer::finalize_stale`]).

use crate::render::Renderer;
use crate::Result;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// Relighting time allowed per frame while the artist interacts, shared by the renderers on
/// screen (two in an A/B split).
pub const FRAME_BUDGET: Duration = Duration::from_millis(25);
/// `LOOKDEV_FRAME_BUDGET_MS`: another budget, in milliseconds, so that a test can make any
/// device sweep a pass over many frames, as a slow one does.
const BUDGET_VARIABLE: &str = "LOOKDEV_FRAME_BUDGET_MS";
static BUDGET: OnceLock<Duration> = OnceLock::new();

/// Reads `LOOKDEV_FRAME_BUDGET_MS` (1 to 1000) once, before the window opens; a bad value is
/// an error naming the variable.
pub fn configure_budget() -> Result<()> {
    let budget = match std::env::var(BUDGET_VARIABLE) {
        Err(std::env::VarError::NotPresent) => FRAME_BUDGET,
        Ok(text) => match text.trim().parse::<u64>() {
            Ok(ms @ 1..=1000) => Duration::from_millis(ms),
            _ => return Err(crate::Error::input(format!("{BUDGET_VARIABLE}={text}: expected 1 to 1000 milliseconds"))),
        },
        Err(e) => return Err(crate::Error::input(format!("{BUDGET_VARIABLE}: {e}"))),
    };
    let _ = BUDGET.set(budget);
    Ok(())
}

/// The relighting time per interactive frame: [`FRAME_BUDGET`] unless [`configure_budget`]
/// read another.
pub fn frame_budget() -> Duration {
    BUDGET.get().copied().unwrap_or(FRAME_BUDGET)
}
/// The smallest band, so a slow device still makes progress each frame.
const MIN_BAND_ROWS: u32 = 8;

/// Whether what was read back at `shown` samples should be read again at `now`: the count has
/// reached the next power of two (1, 2, 4, …) since, or the target, or accumulation restarted.
/// Passes after the first add several samples each, so the count steps over most powers of two
/// (1, 5, 9, 13, …) rather than landing on them.
pub fn read_again(shown: u32, now: u32, target: u32) -> bool {
    now != shown && (now < shown || now >= target || now.checked_ilog2() > shown.checked_ilog2())
}
/// Samples per band once the first pass has landed: fewer, longer dispatches amortise each
/// pass's per-pixel set-up, which on a CPU driver costs about as much as a couple of samples.
const SAMPLES_PER_BAND: u32 = 4;
/// Samples per band of the pixels an edit restarted alone, once they have all had one (and per
/// dispatch when a save catches them up): more than [`SAMPLES_PER_BAND`], since they are a
/// share of the image and each pass's set-up costs a couple of samples on a CPU driver. So they
/// catch up in one more sweep, at the rest's count, band by band.
pub const CATCH_UP_SAMPLES: u32 = 16;
/// What a pixel's background costs in the preview, as a share of a relit sample.
const PREVIEW_BACKGROUND_SHARE: f64 = 0.1;

/// Where the sweep is, how fast rows relight, and the figures the status bar shows.
pub struct Progressive {
    cursor: u32,
    /// Seconds to relight one row with one sample (a running average).
    row_seconds: f64,
    /// When the current accumulation started, and when its first full pass landed.
    started: Instant,
    pub first_pass: Option<Duration>,
    /// Pixel samples relit, and the time spent, over the current accumulation.
    pixel_samples: f64,
    busy: Duration,
    /// When the current accumulation's preview was shown, and its block size.
    pub preview: Option<(Duration, u32)>,
    /// Seconds to relight one row's restarted pixels with one sample while they catch up (a
    /// running average): the rows of a local restart hold few of their pixels.
    region_row_seconds: f64,
    /// Whether the restarted pixels have had their first sample: the sweep before it takes one
    /// sample a band, so they show their new material soonest.
    region_swept: bool,
    /// Where the sweep over the restarted pixels' rows is. The pass's own `cursor` stays where
    /// the edit found it: the rows from there on have one count and those above it one more
    /// band's, which the restarted pixels catch up with.
    region_cursor: u32,
}

impl Progressive {
    pub fn new() -> Progressive {
        Progressive {
            cursor: 0,
            row_seconds: 0.0,
            started: Instant::now(),
            first_pass: None,
            pixel_samples: 0.0,
            busy: Duration::ZERO,
            preview: None,
            region_row_seconds: 0.0,
            region_swept: false,
            region_cursor: 0,
        }
    }

    /// Starts over after an edit: the renderer has restarted its accumulation.
    pub fn restart(&mut self) {
        self.cursor = 0;
        self.started = Instant::now();
        self.first_pass = None;
        self.pixel_samples = 0.0;
        self.busy = Duration::ZERO;
        self.preview = None;
    }

    /// Starts over after an edit that restarted some pixels only
    /// ([`Renderer::set_stacks_local`]): the rest keep their samples and the first pass's time.
    pub fn restart_local(&mut self) {
        self.region_cursor = 0;
        self.region_row_seconds = 0.0;
        self.region_swept = false;
    }

    /// The preview's block: the smallest whose one sample per block is expected to fit the
    /// budget at the measured speed, or 4 before anything is measured. Blocks of b × b relight
    /// a b²-th of the pixels; every pixel's background costs about a tenth of a sample.
    fn preview_block(&self, height: u32, budget: Duration) -> u32 {
        if self.row_seconds <= 0.0 {
            return 4;
        }
        let fits = |block: u32| {
            let rows = height as f64 / (block * block) as f64 + height as f64 * PREVIEW_BACKGROUND_SHARE;
            rows * self.row_seconds <= budget.as_secs_f64()
        };
        [2, 4].into_iter().find(|&b| fits(b)).unwrap_or(crate::render::renderer::MAX_PREVIEW_BLOCK)
    }

    /// Relights the next band if the image has fewer than `target` samples, within about
    /// `budget`. The first step after a change is the preview instead (sized to the interactive
    /// budget, however long this one is: it is what an edit shows first); the first pass takes
    /// one sample per band, so the preview is replaced soonest; later bands take a few, or,
    /// where the budget covers the rest of the pass, as many as fit. Returns whether anything
    /// was rendered.
    pub fn step(&mut self, renderer: &mut Renderer, target: u32, budget: Duration) -> Result<bool> {
        // Under a noise threshold, accumulation also stops once every pixel has stopped.
        if renderer.samples() >= target || renderer.active_pixels() == Some(0) {
            return Ok(false);
        }
        if let Some((_, theirs, _)) = renderer.restarted_region() {
            return self.step_region(renderer, theirs, target, budget);
        }
        let height = renderer.height;
        if renderer.preview_block().is_none() && (0..height).all(|row| renderer.row_samples(row) == 0) {
            let block = self.preview_block(height, budget.min(frame_budget()));
            renderer.render_preview(block)?;
            self.preview = Some((self.started.elapsed(), block));
            return Ok(true);
        }
        // Bands may take different counts, so rows differ by more than a band: the sweep goes
        // on at the first row short of the target, over the rows short of it from there, and
        // takes no more samples than the most-sampled of them lacks, so that no row passes it.
        let short = |row: u32| renderer.row_samples(row) < target;
        if !short(self.cursor) {
            match (0..height).find(|&row| short(row)) {
                Some(row) => self.cursor = row,
                None => return Ok(false),
            }
        }
        let run_end = (self.cursor..height).find(|&row| !short(row)).unwrap_or(height);
        let most = (self.cursor..run_end).map(|row| renderer.row_samples(row)).max().unwrap_or(0);
        // Under a noise threshold a band ends at the next stop test, so that pixels stopping
        // there cost nothing after it.
        let lacking = renderer.noise_threshold().map_or(target - most, |n| n.to_checkpoint(most).min(target - most));
        let (rows, count) =
            band(self.first_pass.is_some(), run_end - self.cursor, height, lacking, self.row_seconds, budget);
        let start = Instant::now();
        renderer.render_rows(self.cursor, rows, count)?;
        let elapsed = start.elapsed();
        self.busy += elapsed;
        let row_samples = rows as f64 * count as f64;
        self.pixel_samples += row_samples * renderer.width as f64;
        let per_row = elapsed.as_secs_f64() / row_samples;
        self.row_seconds = if self.row_seconds == 0.0 { per_row } else { 0.7 * self.row_seconds + 0.3 * per_row };
        self.cursor += rows;
        if self.cursor >= height {
            self.cursor = 0;
            if self.first_pass.is_none() {
                self.first_pass = Some(self.started.elapsed());
            }
        }
        Ok(true)
    }

    /// Relights the next band of the restarted pixels ([`Renderer::restart_pixels`]), which
    /// have `theirs` samples: one sample a band until they have all had one, then up to
    /// [`CATCH_UP_SAMPLES`], never past the rest's count or `target`.
    fn step_region(&mut self, renderer: &mut Renderer, theirs: u32, target: u32, budget: Duration) -> Result<bool> {
        let Some((first, rows)) = renderer.lagging_rows() else { return Ok(false) };
        let end = first + rows;
        if !(first..end).contains(&self.region_cursor) {
            if self.region_cursor >= end {
                self.region_swept = true;
            }
            self.region_cursor = first;
        }
        let count = if self.region_swept { CATCH_UP_SAMPLES.min(target.saturating_sub(theirs)).max(1) } else { 1 };
        let per_row = if self.region_row_seconds > 0.0 { self.region_row_seconds } else { self.row_seconds };
        let wanted =
            if per_row > 0.0 { (budget.as_secs_f64() / (per_row * count as f64)) as u32 } else { MIN_BAND_ROWS };
        let band = wanted.max(MIN_BAND_ROWS).min(end - self.region_cursor);
        let start = Instant::now();
        renderer.render_rows(self.region_cursor, band, count)?;
        // Not counted in the samples per second, which are of whole rows.
        let measured = start.elapsed().as_secs_f64() / (band as f64 * count as f64);
        self.region_row_seconds =
            if self.region_row_seconds == 0.0 { measured } else { 0.7 * self.region_row_seconds + 0.3 * measured };
        self.region_cursor += band;
        Ok(true)
    }

    /// Pixel samples per second while relighting, over the current accumulation, of this and
    /// `other` together (an A/B split's two renderers,
    /// which relight in turn): all their samples over all their relighting time.
    pub fn samples_per_second_with(&self, other: Option<&Progressive>) -> f64 {
        let (samples, busy) = other
            .map_or((self.pixel_samples, self.busy), |b| (self.pixel_samples + b.pixel_samples, self.busy + b.busy));
        if busy.is_zero() {
            0.0
        } else {
            samples / busy.as_secs_f64()
        }
    }
}

/// The next band of a pass, as (rows, samples), for the `rows_left` rows to the end of the pass
/// of an image `height` rows tall, which lack `remaining` samples, at `row_seconds` a row and
/// sample (0 before a measurement). The first pass takes one sample a band, so that the preview
/// is replaced soonest. Later passes take as many samples as fit `budget` over a quarter of the
/// image (or the rows left, if fewer), and at least [`SAMPLES_PER_BAND`]: each dispatch pays a
/// set-up per pixel, so that more samples a pixel waste less, while bands of a quarter still
/// show the image refining as a whole. Never fewer rows than [`MIN_BAND_ROWS`] (nor more than
/// are left), nor more samples than `remaining`.
fn band(
    first_pass_done: bool,
    rows_left: u32,
    height: u32,
    remaining: u32,
    row_seconds: f64,
    budget: Duration,
) -> (u32, u32) {
    if row_seconds <= 0.0 {
        return (MIN_BAND_ROWS.min(rows_left), 1); // the first band measures the device
    }
    let budget = budget.as_secs_f64();
    let count = if first_pass_done {
        let quarter = (height / 4).max(MIN_BAND_ROWS).min(rows_left);
        let fits = (budget / (row_seconds * quarter as f64)) as u32;
        fits.max(SAMPLES_PER_BAND).min(remaining)
    } else {
        1
    };
    let rows = (budget / (row_seconds * count as f64)) as u32;
    (rows.max(MIN_BAND_ROWS).min(rows_left), count)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn readings_follow_each_doubling_even_when_passes_step_over_it() {
        assert!(read_again(0, 1, 16));
        assert!(!read_again(1, 1, 16));
        assert!(read_again(1, 5, 16), "5 passed 2 and 4");
        assert!(!read_again(5, 7, 16));
        assert!(read_again(5, 9, 16), "9 passed 8");
        assert!(!read_again(9, 13, 16));
        assert!(read_again(13, 16, 16), "the target");
        assert!(read_again(16, 1, 16), "a restart");
    }

    #[test]
    fn the_preview_block_is_the_smallest_that_fits_the_budget() {
        let mut progressive = Progressive::new();
        let budget = Duration::from_millis(25);
        assert_eq!(progressive.preview_block(1000, budget), 4, "before any measurement");
        // 1000 rows: 2×2 costs 250 + 100 row-samples, 4×4 62.5 + 100.
        for (row_seconds, block) in [(50e-6, 2), (100e-6, 4), (1e-3, 8)] {
            progressive.row_seconds = row_seconds;
            assert_eq!(progressive.preview_block(1000, budget), block, "{row_seconds} s a row");
        }
    }

    #[test]
    fn a_long_budget_takes_more_samples_a_band_rather_than_more_rows() {
        let ms = Duration::from_millis;
        // Before a measurement: a small band of one sample.
        assert_eq!(band(false, 1024, 1024, 64, 0.0, ms(25)), (MIN_BAND_ROWS, 1));
        // The first pass: one sample a band, as many rows as fit (26 ms at 0.1 ms a row).
        assert_eq!(band(false, 1024, 1024, 64, 1e-4, ms(26)), (260, 1));
        assert_eq!(band(false, 1024, 1024, 64, 1e-4, ms(500)), (1024, 1), "even when more would fit");
        // Later passes: four samples a band where fewer would fit a quarter of the image...
        assert_eq!(band(true, 1024, 1024, 60, 1e-4, ms(26)), (65, 4));
        // ... and as many as fit over a quarter where that is more: 210 ms at 0.1 ms a row
        // and sample over 256 rows is 8.
        assert_eq!(band(true, 1024, 1024, 60, 1e-4, ms(210)), (262, 8));
        // Near the end of a pass, a quarter is what is left: 215 ms over 100 rows is 21.
        assert_eq!(band(true, 100, 1024, 60, 1e-4, ms(215)), (100, 21));
        // Never more samples than are missing, never fewer rows than the least band.
        assert_eq!(band(true, 1024, 1024, 3, 1e-4, ms(26)), (86, 3));
        assert_eq!(band(true, 1024, 1024, 60, 1e-4, ms(21_000)), (1024, 60));
        assert_eq!(band(true, 1024, 1024, 60, 1.0, ms(25)), (MIN_BAND_ROWS, 4));
        assert_eq!(band(true, 5, 1024, 60, 1.0, ms(25)), (5, 4));
    }
}
