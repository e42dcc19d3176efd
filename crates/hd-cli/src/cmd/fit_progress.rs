//! Progress of a fit: a spinner with the elapsed time that appears on stderr only once
//! the fit has run for more than [`SHOW_AFTER`] (short fits print nothing, and nothing
//! is drawn when stderr is not a terminal).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How long a fit runs before its spinner shows.
pub const SHOW_AFTER: Duration = Duration::from_secs(2);

/// The spinner of one fit; [`FitProgress::finish`] removes it.
pub struct FitProgress {
    bar: ProgressBar,
    done: Arc<AtomicBool>,
    watcher: Option<JoinHandle<()>>,
}

impl FitProgress {
    /// Start timing a fit described by `what` (e.g. "fitting friction to 42 579 samples").
    pub fn start(what: impl Into<String>) -> Self {
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        let style = ProgressStyle::with_template("{spinner} {msg} · {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner());
        bar.set_style(style);
        bar.set_message(what.into());
        let done = Arc::new(AtomicBool::new(false));
        let (b, d) = (bar.clone(), done.clone());
        let watcher = std::thread::spawn(move || {
            let start = Instant::now();
            while !d.load(Ordering::Relaxed) {
                if start.elapsed() >= SHOW_AFTER {
                    b.set_draw_target(ProgressDrawTarget::stderr());
                    b.enable_steady_tick(Duration::from_millis(120));
                    return;
                }
                std::thread::park_timeout(Duration::from_millis(50));
            }
        });
        Self { bar, done, watcher: Some(watcher) }
    }

    /// Remove the spinner.
    pub fn finish(mut self) {
        self.done.store(true, Ordering::Relaxed);
        if let Some(w) = self.watcher.take() {
            w.thread().unpark();
            let _ = w.join();
        }
        self.bar.finish_and_clear();
    }
}
