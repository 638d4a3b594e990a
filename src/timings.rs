//! Phase timings on stderr, for seeing where a process spends its time: with
//! `LOOKDEV_TIMINGS=1`, each timed phase prints one line as it ends,
//! `lookdev: timing: NAME 12.3 ms (at 45.6 ms)`, the second figure counted from the first phase
//! that started. Phases may nest (the inner one prints first). Off, a phase costs one load.

use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// 0: not read yet, 1: off, 2: on.
static ENABLED: AtomicU8 = AtomicU8::new(0);

/// When the first phase began, the origin of the "at" figures.
static ORIGIN: OnceLock<Instant> = OnceLock::new();

/// Whether `LOOKDEV_TIMINGS=1` is set (read once).
pub fn enabled() -> bool {
    match ENABLED.load(Ordering::Relaxed) {
        0 => {
            let on = std::env::var("LOOKDEV_TIMINGS").is_ok_and(|v| v == "1");
            ENABLED.store(if on { 2 } else { 1 }, Ordering::Relaxed);
            on
        }
        state => state == 2,
    }
}

/// A phase being timed: prints its line when dropped.
pub struct Phase {
    /// None when timings are off.
    started: Option<(String, Instant)>,
}

/// Starts timing a phase named `name` (formatted only when timings are on).
pub fn phase(name: impl std::fmt::Display) -> Phase {
    if !enabled() {
        return Phase { started: None };
    }
    let now = Instant::now();
    ORIGIN.get_or_init(|| now);
    Phase { started: Some((name.to_string(), now)) }
}

/// Prints a line for an event rather than a span (what came from a cache).
pub fn note(text: impl FnOnce() -> String) {
    if enabled() {
        eprintln!("lookdev: timing: {}", text());
    }
}

/// The process's peak resident memory, VmHWM (Linux; None elsewhere): on a CPU driver it holds
/// the device memory too.
pub fn host_peak_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let kib: u64 =
        status.lines().find_map(|l| l.strip_prefix("VmHWM:"))?.trim().trim_end_matches(" kB").parse().ok()?;
    Some(kib * 1024)
}

fn milliseconds(duration: Duration) -> f64 {
    duration.as_secs_f64() * 1e3
}

impl Drop for Phase {
    fn drop(&mut self) {
        if let Some((name, started)) = self.started.take() {
            let origin = *ORIGIN.get().unwrap_or(&started);
            eprintln!(
                "lookdev: timing: {name} {:.1} ms (at {:.1} ms)",
                milliseconds(started.elapsed()),
                milliseconds(origin.elapsed())
            );
        }
    }
}
