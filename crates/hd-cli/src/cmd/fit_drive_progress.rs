//! Progress of `hdw fit drive`: on a terminal, a spinner with the elapsed time and what the
//! fit is doing; otherwise (a log file, a pipe, a batch job) plain lines on stderr, the
//! first once the run has taken [`QUIET_FOR`], then one every [`EVERY`], each with the
//! elapsed time and the current step. Runs shorter than [`QUIET_FOR`] print nothing.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::{IsTerminal, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How long a run goes before its first plain progress line.
pub const QUIET_FOR: Duration = Duration::from_secs(2);

/// Interval between plain progress lines.
pub const EVERY: Duration = Duration::from_secs(10);

/// The line of one step of a compliant fit: its stage (the motor pass, a load-pass start,
/// a full fit, a refit of the checks), and the optimiser's iteration and cost [–] where it
/// has them (a stage that announces itself has no cost yet).
pub fn step_message(stage: &str, iteration: usize, cost: f64) -> String {
    if cost.is_finite() {
        format!("compliant drive: {stage}: iteration {iteration}, cost {cost:.6e}")
    } else {
        format!("compliant drive: {stage}")
    }
}

/// A fit's progress display: [`Progress::set_message`] from any thread, then
/// [`Progress::finish_and_clear`].
pub struct Progress {
    bar: Option<ProgressBar>,
    message: Arc<Mutex<String>>,
    done: Arc<AtomicBool>,
    printer: Option<JoinHandle<()>>,
}

impl Progress {
    /// Start showing `message`: a spinner when stderr is a terminal, plain lines otherwise.
    pub fn start(message: String) -> Self {
        if std::io::stderr().is_terminal() {
            let bar = ProgressBar::new_spinner();
            bar.set_style(
                ProgressStyle::with_template("{spinner} {elapsed_precise} {msg}")
                    .unwrap_or_else(|_| ProgressStyle::default_spinner()),
            );
            bar.enable_steady_tick(Duration::from_millis(200));
            bar.set_message(message);
            return Progress {
                bar: Some(bar),
                message: Arc::default(),
                done: Arc::default(),
                printer: None,
            };
        }
        Self::lines(message, QUIET_FOR, EVERY, |line| {
            let _ = writeln!(std::io::stderr().lock(), "{line}");
        })
    }

    /// Plain lines through `print`: the first after `quiet`, then one every `every`.
    fn lines(
        message: String,
        quiet: Duration,
        every: Duration,
        print: impl Fn(&str) + Send + 'static,
    ) -> Self {
        let message = Arc::new(Mutex::new(message));
        let done = Arc::new(AtomicBool::new(false));
        let (m, d) = (message.clone(), done.clone());
        let printer = std::thread::Builder::new()
            .name("hdw-progress".into())
            .spawn(move || {
                let start = Instant::now();
                let mut next = quiet;
                while !d.load(Ordering::Relaxed) {
                    let now = start.elapsed();
                    if now >= next {
                        let text = m.lock().map(|s| s.clone()).unwrap_or_default();
                        print(&format!("hdw fit drive: {:.0} s: {text}", now.as_secs_f64()));
                        next = now + every;
                    }
                    std::thread::park_timeout(
                        (next - now.min(next)).min(Duration::from_millis(200)),
                    );
                }
            })
            .ok();
        Progress { bar: None, message, done, printer }
    }

    /// What the run is doing now.
    pub fn set_message(&self, message: String) {
        match &self.bar {
            Some(bar) => bar.set_message(message),
            None => {
                if let Ok(mut m) = self.message.lock() {
                    *m = message;
                }
            }
        }
    }

    /// Stop (the spinner is removed; no further line is printed).
    pub fn finish_and_clear(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
        self.done.store(true, Ordering::Relaxed);
        if let Some(p) = &self.printer {
            p.thread().unpark();
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.finish_and_clear();
        if let Some(p) = self.printer.take() {
            let _ = p.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Off a terminal: nothing before the quiet time, then a line with the current step at
    /// each interval; nothing once finished.
    #[test]
    fn plain_lines_after_the_quiet_time() {
        let got = Arc::new(Mutex::new(Vec::<String>::new()));
        let g = got.clone();
        let p = Progress::lines(
            "fitting 1 law(s)".into(),
            Duration::from_millis(300),
            Duration::from_millis(200),
            move |l| g.lock().unwrap().push(l.to_string()),
        );
        std::thread::sleep(Duration::from_millis(150));
        assert!(got.lock().unwrap().is_empty());
        std::thread::sleep(Duration::from_millis(300));
        p.set_message("writing series.parquet".into());
        std::thread::sleep(Duration::from_millis(300));
        p.finish_and_clear();
        let n = got.lock().unwrap().len();
        std::thread::sleep(Duration::from_millis(300));
        let lines = got.lock().unwrap().clone();
        assert_eq!(lines.len(), n);
        assert!(lines.len() >= 2, "{lines:?}");
        assert!(lines[0].starts_with("hdw fit drive: 0 s: fitting 1 law(s)"), "{lines:?}");
        assert!(lines.last().unwrap().ends_with("writing series.parquet"), "{lines:?}");
    }
}
