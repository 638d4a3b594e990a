//! A progress bar on stderr for work that takes more than about a second.

use indicatif::{ProgressBar, ProgressStyle};
use std::time::{Duration, Instant};

const SHOW_AFTER: Duration = Duration::from_secs(1);

pub struct Progress {
    total: u64,
    label: String,
    /// What is counted, e.g. "spp".
    unit: &'static str,
    quiet: bool,
    start: Instant,
    bar: Option<ProgressBar>,
}

impl Progress {
    /// A bar counting samples per pixel.
    pub fn new(total: u64, label: impl Into<String>, quiet: bool) -> Progress {
        Progress::counting(total, label, "spp", quiet)
    }

    /// A bar counting `unit`s.
    pub fn counting(total: u64, label: impl Into<String>, unit: &'static str, quiet: bool) -> Progress {
        Progress { total, label: label.into(), unit, quiet, start: Instant::now(), bar: None }
    }

    /// Sets the total, for work whose size is known only once it starts.
    pub fn set_total(&mut self, total: u64) {
        self.total = total;
        if let Some(bar) = &self.bar {
            bar.set_length(total);
        }
    }

    /// Reports `done` of `total`; the bar appears once the work has run for a second.
    pub fn update(&mut self, done: u64) {
        if self.quiet {
            return;
        }
        if self.bar.is_none() && self.start.elapsed() >= SHOW_AFTER && done < self.total {
            let bar = ProgressBar::new(self.total);
            bar.set_style(
                ProgressStyle::with_template(&format!(
                    "{{msg}} [{{bar:40}}] {{pos}}/{{len}} {}, {{elapsed}} elapsed, eta {{eta}}",
                    self.unit
                ))
                .expect("the template is valid")
                .progress_chars("=> "),
            );
            bar.set_message(self.label.clone());
            self.bar = Some(bar);
        }
        if let Some(bar) = &self.bar {
            bar.set_position(done);
        }
    }

    pub fn finish(self) {
        if let Some(bar) = self.bar {
            bar.finish_and_clear();
        }
    }
}
