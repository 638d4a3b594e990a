//! Frame scheduling: after each turn of the event loop, whether the viewer draws the window,
//! relights without drawing, or waits, and for how long it relights.
//!
//! Drawing the interface costs a CPU driver tens of milliseconds, and showing the same image
//! again adds nothing, so the window is drawn only when what it shows changes: input, the
//! interface's own repaints, a script's step, and the image at 1, 2, 4, … samples (unless that
//! would spend more than a fifth of the time drawing), at least every [`PROGRESS_INTERVAL`],
//! and at its target. While the artist interacts, each frame
//! relights for the short interactive budget, so the image follows the light as it turns;
//! otherwise the relighting takes slices of [`IDLE_SLICE`] between looks at the event queue,
//! which never waits while there is relighting to do. So a viewer left alone converges as fast
//! as `lookdev render` does, and never stops short of its target.

use super::progressive::read_again;
use std::time::{Duration, Instant};

/// How long one relighting slice runs while nobody interacts: input waits at most this long
/// to be seen, and each slice is long enough to amortise a dispatch's set-up.
pub const IDLE_SLICE: Duration = Duration::from_millis(150);
/// The longest the image goes unshown while it converges with nobody interacting, unless
/// drawing is so slow that this would spend more than a twentieth of the time drawing.
pub const PROGRESS_INTERVAL: Duration = Duration::from_secs(1);
/// How long after the last input the viewer keeps drawing every frame: a drag that pauses
/// still sees the image refine under it.
pub const INTERACTION: Duration = Duration::from_millis(500);

/// What the frame scheduler is told about the viewer at the top of a turn of the event loop.
#[derive(Clone, Copy, Debug)]
pub struct Situation {
    pub now: Instant,
    /// Whether the image is short of its target (on either side of an A/B split).
    pub rendering: bool,
    /// The samples every pixel on screen has, and the target.
    pub samples: u32,
    pub target: u32,
    /// Whether something must be shown or done in a frame: input events, queued actions, a
    /// script line ready to run, a screenshot or the headless run's last frame.
    pub needs_frame: bool,
    /// When the interface asked to be drawn again (an animation, a tooltip), if it did.
    pub repaint_at: Option<Instant>,
}

/// What to do next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Next {
    /// Draw a frame, relighting for `relight` first.
    Draw { relight: Duration },
    /// Relight for this long without drawing, then look at the event queue again.
    Relight(Duration),
    /// Nothing to do until an event comes, or until the instant given.
    Wait(Option<Instant>),
}

/// The scheduler's memory of what it decided and what drawing costs.
#[derive(Debug)]
pub struct FrameScheduler {
    /// Relighting time of an interactive frame.
    interactive: Duration,
    last_input: Option<Instant>,
    /// When the window was last drawn and the samples it showed.
    drawn: Option<(Instant, u32)>,
    /// Time a draw takes (a running average).
    draw_cost: Duration,
}

impl FrameScheduler {
    /// A scheduler whose interactive frames relight for `interactive`.
    pub fn new(interactive: Duration) -> FrameScheduler {
        FrameScheduler { interactive, last_input: None, drawn: None, draw_cost: Duration::ZERO }
    }

    /// The artist did something (an event from the window, or a script's action).
    pub fn input(&mut self, at: Instant) {
        self.last_input = Some(at);
    }

    /// A frame was drawn at `at`, showing `samples`, and drawing it took `cost`.
    pub fn drawn(&mut self, at: Instant, samples: u32, cost: Duration) {
        self.drawn = Some((at, samples));
        self.draw_cost = if self.draw_cost.is_zero() { cost } else { self.draw_cost.mul_f64(0.7) + cost.mul_f64(0.3) };
    }

    /// How long the image may go unshown while it converges: [`PROGRESS_INTERVAL`], or twenty
    /// draws' time where drawing is slower than 50 ms.
    pub fn progress_interval(&self) -> Duration {
        PROGRESS_INTERVAL.max(self.draw_cost * 20)
    }

    /// What to do in `situation`.
    pub fn next(&self, situation: &Situation) -> Next {
        let now = situation.now;
        let relight = if situation.rendering { self.interactive } else { Duration::ZERO };
        let due = situation.repaint_at.is_some_and(|at| at <= now);
        let interacting = self.last_input.is_some_and(|at| now.saturating_duration_since(at) < INTERACTION);
        if situation.needs_frame || due || (interacting && situation.rendering) {
            return Next::Draw { relight };
        }
        let Some((drawn_at, shown)) = self.drawn else {
            return Next::Draw { relight };
        };
        if shown != situation.samples {
            let since = now.saturating_duration_since(drawn_at);
            let doubled = read_again(shown, situation.samples, situation.target) && since >= self.draw_cost * 4;
            if !situation.rendering || doubled || since >= self.progress_interval() {
                return Next::Draw { relight: Duration::ZERO };
            }
        }
        if situation.rendering {
            Next::Relight(IDLE_SLICE)
        } else {
            Next::Wait(situation.repaint_at)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const INTERACTIVE: Duration = Duration::from_millis(25);

    fn situation(now: Instant, samples: u32, target: u32) -> Situation {
        Situation { now, rendering: samples < target, samples, target, needs_frame: false, repaint_at: None }
    }

    /// A scheduler that drew `samples` at `at`, drawing at `cost` a frame.
    fn drew(at: Instant, samples: u32, cost: Duration) -> FrameScheduler {
        let mut scheduler = FrameScheduler::new(INTERACTIVE);
        scheduler.drawn(at, samples, cost);
        scheduler
    }

    #[test]
    fn the_first_frame_is_drawn() {
        let now = Instant::now();
        let scheduler = FrameScheduler::new(INTERACTIVE);
        assert_eq!(scheduler.next(&situation(now, 0, 64)), Next::Draw { relight: INTERACTIVE });
        assert_eq!(scheduler.next(&situation(now, 64, 64)), Next::Draw { relight: Duration::ZERO });
    }

    #[test]
    fn left_alone_it_relights_without_drawing_and_never_waits_short_of_the_target() {
        let t0 = Instant::now();
        let ms = Duration::from_millis;
        let scheduler = drew(t0, 5, ms(40));
        // No events at all: from 5 to 7 samples nothing new is worth a draw, yet it relights.
        for (after, samples) in [(10, 5), (300, 6), (900, 7)] {
            assert_eq!(scheduler.next(&situation(t0 + ms(after), samples, 8)), Next::Relight(IDLE_SLICE));
        }
        // 8 reaches the target (and the next power of two): drawn, then nothing left to do.
        assert_eq!(scheduler.next(&situation(t0 + ms(950), 8, 8)), Next::Draw { relight: Duration::ZERO });
        let scheduler = drew(t0 + ms(1000), 8, ms(40));
        assert_eq!(scheduler.next(&situation(t0 + ms(1100), 8, 8)), Next::Wait(None));
    }

    #[test]
    fn progress_is_drawn_at_each_doubling_and_at_least_every_interval() {
        let t0 = Instant::now();
        let ms = Duration::from_millis;
        let scheduler = drew(t0, 17, ms(40));
        assert_eq!(scheduler.next(&situation(t0 + ms(200), 29, 64)), Next::Relight(IDLE_SLICE));
        assert_eq!(scheduler.next(&situation(t0 + ms(200), 33, 64)), Next::Draw { relight: Duration::ZERO });
        // A doubling soon after a draw waits until drawing would take at most a fifth of the time.
        assert_eq!(scheduler.next(&situation(t0 + ms(150), 33, 64)), Next::Relight(IDLE_SLICE));
        assert_eq!(scheduler.next(&situation(t0 + PROGRESS_INTERVAL, 29, 64)), Next::Draw { relight: Duration::ZERO });
        // With no new samples there is nothing new to show, however long it has been.
        assert_eq!(scheduler.next(&situation(t0 + PROGRESS_INTERVAL * 3, 17, 64)), Next::Relight(IDLE_SLICE));
        // Slow drawing (200 ms a frame) is spread out to a twentieth of the time.
        let slow = drew(t0, 17, ms(200));
        assert_eq!(slow.progress_interval(), ms(4000));
        assert_eq!(slow.next(&situation(t0 + ms(3000), 29, 64)), Next::Relight(IDLE_SLICE));
        assert_eq!(slow.next(&situation(t0 + ms(4000), 29, 64)), Next::Draw { relight: Duration::ZERO });
    }

    #[test]
    fn while_the_artist_interacts_every_frame_is_drawn_with_the_interactive_budget() {
        let t0 = Instant::now();
        let ms = Duration::from_millis;
        let mut scheduler = drew(t0, 3, ms(40));
        scheduler.input(t0 + ms(10));
        assert_eq!(scheduler.next(&situation(t0 + ms(20), 3, 64)), Next::Draw { relight: INTERACTIVE });
        assert_eq!(
            scheduler.next(&situation(t0 + ms(10) + INTERACTION - ms(1), 3, 64)),
            Next::Draw { relight: INTERACTIVE },
            "a drag that pauses"
        );
        assert_eq!(scheduler.next(&situation(t0 + ms(10) + INTERACTION, 3, 64)), Next::Relight(IDLE_SLICE));
        // Converged, recent input alone draws nothing new.
        let mut done = drew(t0, 64, ms(40));
        done.input(t0 + ms(10));
        assert_eq!(done.next(&situation(t0 + ms(20), 64, 64)), Next::Wait(None));
    }

    #[test]
    fn events_scripts_and_the_interfaces_repaints_get_a_frame() {
        let t0 = Instant::now();
        let ms = Duration::from_millis;
        let scheduler = drew(t0, 64, ms(40));
        let needs = Situation { needs_frame: true, ..situation(t0 + ms(5), 64, 64) };
        assert_eq!(scheduler.next(&needs), Next::Draw { relight: Duration::ZERO });
        let later = t0 + ms(300);
        let waiting = Situation { repaint_at: Some(later), ..situation(t0 + ms(5), 64, 64) };
        assert_eq!(scheduler.next(&waiting), Next::Wait(Some(later)));
        let due = Situation { now: later, ..waiting };
        assert_eq!(scheduler.next(&due), Next::Draw { relight: Duration::ZERO });
        let rendering = drew(t0, 8, ms(40));
        let needs = Situation { needs_frame: true, ..situation(t0 + ms(5), 8, 64) };
        assert_eq!(rendering.next(&needs), Next::Draw { relight: INTERACTIVE });
    }
}
