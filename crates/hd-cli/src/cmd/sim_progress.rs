//! Progress of one long simulation: a bar over the simulated time that appears only once
//! the run has taken more than a second (short runs print nothing).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::time::{Duration, Instant};

/// Samples between two updates (keeps the bookkeeping off the hot path).
const EVERY: u64 = 1024;
/// Resolution of the bar [steps over the run].
const STEPS: u64 = 1000;

/// The bar of one run.
pub struct SimProgress {
    bar: ProgressBar,
    start: Instant,
    t_end: f64,
    shown: bool,
    count: u64,
}

impl SimProgress {
    /// A hidden bar for a run of `t_end` [s].
    pub fn new(t_end: f64) -> Self {
        let bar = ProgressBar::with_draw_target(Some(STEPS), ProgressDrawTarget::hidden());
        let style = ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {percent}% of {msg} simulated · ETA {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");
        bar.set_style(style);
        bar.set_message(format!("{t_end} s"));
        Self { bar, start: Instant::now(), t_end, shown: false, count: 0 }
    }

    /// The run has reached simulated time `t` [s].
    pub fn at(&mut self, t: f64) {
        self.count += 1;
        if !self.count.is_multiple_of(EVERY) {
            return;
        }
        if !self.shown && self.start.elapsed() > Duration::from_secs(1) {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
            self.shown = true;
        }
        self.bar.set_position(((t / self.t_end).clamp(0.0, 1.0) * STEPS as f64) as u64);
    }

    /// Remove the bar.
    pub fn finish(self) {
        self.bar.finish_and_clear();
    }
}
