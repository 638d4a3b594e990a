//! Progressive rendering bounded per frame: each frame relights a band of rows, sized from the
//! measured speed so the frame stays responsive; a pass is done when the bands have swept the
//! image. On a fast device a band is the whole image, so a change shows within one frame.

use crate::render::Renderer;
use crate::shading::tonemap::Tonemap;
use crate::Result;
use std::time::{Duration, Instant};

/// Relighting time allowed per frame, shared by the renderers on screen (two in an A/B split).
pub const FRAME_BUDGET: Duration = Duration::from_millis(25);
/// The smallest band, so a slow device still makes progress each frame.
const MIN_BAND_ROWS: u32 = 8;
/// Samples per band once the first pass has landed: fewer, longer dispatches amortise each
/// pass's per-pixel set-up, which on a CPU driver costs about as much as a sample.
const SAMPLES_PER_BAND: u32 = 4;

/// Where the sweep is, how fast rows relight, and the figures the status bar shows.
pub struct Progressive {
    /// This renderer's share of [`FRAME_BUDGET`].
    budget: Duration,
    cursor: u32,
    /// Seconds to relight one row with one sample (a running average).
    row_seconds: f64,
    /// When the current accumulation started, and when its first full pass landed.
    started: Instant,
    pub first_pass: Option<Duration>,
    /// Pixel samples relit, and the time spent, over the current accumulation.
    pixel_samples: f64,
    busy: Duration,
}

impl Progressive {
    pub fn new() -> Progressive {
        Progressive {
            budget: FRAME_BUDGET,
            cursor: 0,
            row_seconds: 0.0,
            started: Instant::now(),
            first_pass: None,
            pixel_samples: 0.0,
            busy: Duration::ZERO,
        }
    }

    /// Sets this renderer's share of the frame's relighting time.
    pub fn set_budget(&mut self, budget: Duration) {
        self.budget = budget;
    }

    /// Starts over after an edit: the renderer has restarted its accumulation.
    pub fn restart(&mut self) {
        self.cursor = 0;
        self.started = Instant::now();
        self.first_pass = None;
        self.pixel_samples = 0.0;
        self.busy = Duration::ZERO;
    }

    /// Relights the next band if the image has fewer than `target` samples, then makes its
    /// display pixels. The first pass after a change takes one sample per band, so the whole
    /// image changes soonest; later bands take a few. Returns whether anything was rendered.
    pub fn step(&mut self, renderer: &mut Renderer, target: u32, exposure: f32, tonemap: Tonemap) -> Result<bool> {
        if renderer.samples() >= target {
            return Ok(false);
        }
        let height = renderer.height;
        if renderer.row_samples(self.cursor) >= target {
            // The rows from here on are done (a completed pass caught them up): start over.
            self.cursor = 0;
        }
        let count = match self.first_pass {
            None => 1,
            Some(_) => SAMPLES_PER_BAND.min(target - renderer.row_samples(self.cursor)),
        };
        let wanted = if self.row_seconds > 0.0 {
            (self.budget.as_secs_f64() / (self.row_seconds * count as f64)) as u32
        } else {
            MIN_BAND_ROWS // the first band measures the device
        };
        let rows = wanted.max(MIN_BAND_ROWS).min(height - self.cursor);
        let start = Instant::now();
        renderer.render_rows(self.cursor, rows, count)?;
        renderer.finalize_rows(self.cursor, rows, exposure, tonemap)?;
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
