//! Progress over the stages of a long job that is not a simulation (a report's parts, a
//! datasheet's matches): a bar on stderr that appears once the job has run past a second,
//! on a terminal only, and disappears when done. Short jobs and logs print nothing.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::time::{Duration, Instant};

/// A job of a known number of stages.
pub struct Stages {
    bar: ProgressBar,
    start: Instant,
    shown: bool,
}

impl Stages {
    /// A hidden bar over `len` stages of the job `what` (e.g. `report`).
    pub fn new(len: usize, what: &str) -> Self {
        let bar = ProgressBar::with_draw_target(Some(len as u64), ProgressDrawTarget::hidden());
        let style =
            ProgressStyle::with_template("{prefix} {elapsed_precise} [{bar:30}] {pos}/{len} {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> ");
        bar.set_style(style);
        bar.set_prefix(what.to_string());
        Self { bar, start: Instant::now(), shown: false }
    }

    /// Starting stage `msg` (e.g. the part's name); the bar shows from here on once the
    /// job has taken more than a second.
    pub fn stage(&mut self, msg: &str) {
        if !self.shown && self.start.elapsed() > Duration::from_secs(1) {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
            self.shown = true;
        }
        self.bar.set_message(msg.to_string());
    }

    /// The current stage is done.
    pub fn done(&self) {
        self.bar.inc(1);
    }

    /// The job is done: the bar is cleared.
    pub fn finish(self) {
        self.bar.finish_and_clear();
    }
}
