//! How many runs go into each committed part of a study.
//!
//! A part is run in parallel and then committed by one thread while the others wait, so
//! each commit (a few milliseconds: a Parquet file with its statistics and metadata) and
//! each part's tail, where the last run finishes alone, cost wall time. The first part is
//! a twentieth of the study (so an interruption early on loses little); after that each
//! part is sized from the measured rate to take about [`PART_SECONDS`]. On Table 4's
//! `full-sine` part (1 600 runs) that is 3 parts instead of 20.

/// Wall time a part should take once the rate is known [s]: long enough that committing
/// it costs well under 1 % of the sweep, short enough that an interruption loses little.
pub const PART_SECONDS: f64 = 1.0;
/// Most rows in a part when the study keeps traces (each row holds its samples) [–].
pub const MAX_ROWS_WITH_TRACES: usize = 512;
/// Most rows in a part otherwise (a row is under a kilobyte; the memory of a sweep must
/// not grow with its run count, only with this) [–].
pub const MAX_ROWS: usize = 4096;
/// Most a part may grow over the one before [–], so a part of unusually fast runs does
/// not make the next one huge.
const GROWTH: usize = 8;

/// The size of the next part.
#[derive(Clone, Debug)]
pub struct PartSizer {
    next: usize,
    min: usize,
    max: usize,
}

impl PartSizer {
    /// For `todo` runs on `threads` workers; `traces` when rows keep their traces.
    pub fn new(todo: u64, threads: usize, traces: bool) -> Self {
        let max = if traces { MAX_ROWS_WITH_TRACES } else { MAX_ROWS };
        // At least a few runs per worker, so every worker has something to do.
        let min = (threads * 4).clamp(1, max);
        // A twentieth, at most the traced cap (the rate is not known yet), at least `min`.
        let first = usize::try_from(todo / 20).unwrap_or(usize::MAX).min(MAX_ROWS_WITH_TRACES);
        Self { next: first.max(min), min, max }
    }

    /// Runs in the next part [–].
    pub fn size(&self) -> usize {
        self.next
    }

    /// A part of `rows` runs took `secs` [s] to run: size the next one from that rate.
    pub fn record(&mut self, rows: usize, secs: f64) {
        if rows == 0 {
            return;
        }
        let rate = rows as f64 / secs.max(1e-6);
        let want = (rate * PART_SECONDS).min(self.max as f64) as usize;
        self.next = want.min(self.next.saturating_mul(GROWTH)).clamp(self.min, self.max);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_part_is_a_twentieth_within_bounds() {
        assert_eq!(PartSizer::new(1600, 2, false).size(), 80);
        assert_eq!(PartSizer::new(10, 2, false).size(), 8, "at least four runs a worker");
        assert_eq!(PartSizer::new(1 << 40, 2, false).size(), MAX_ROWS_WITH_TRACES);
        assert_eq!(PartSizer::new(0, 1, true).size(), 4);
        // Many workers: four runs each even above the first part's usual cap.
        assert_eq!(PartSizer::new(1 << 40, 200, false).size(), 800);
        assert_eq!(PartSizer::new(1 << 40, 200, true).size(), MAX_ROWS_WITH_TRACES);
    }

    #[test]
    fn later_parts_take_about_a_second_and_grow_gradually() {
        let mut s = PartSizer::new(1600, 2, false);
        // 80 runs in 0.08 s: 1000 runs a second, but at most eight times the last part.
        s.record(80, 0.08);
        assert_eq!(s.size(), 640);
        s.record(640, 0.64);
        assert_eq!(s.size(), 1000);
        // Slow runs: never fewer than four a worker.
        s.record(8, 100.0);
        assert_eq!(s.size(), 8);
        // Very fast runs: capped, tighter when traces are kept.
        let mut fast = PartSizer::new(1 << 30, 2, false);
        for _ in 0..5 {
            fast.record(fast.size(), 1e-3);
        }
        assert_eq!(fast.size(), MAX_ROWS);
        let mut traced = PartSizer::new(1 << 30, 2, true);
        traced.record(traced.size(), 1e-3);
        assert_eq!(traced.size(), MAX_ROWS_WITH_TRACES);
        // An empty part changes nothing.
        let before = traced.size();
        traced.record(0, 0.0);
        assert_eq!(traced.size(), before);
    }
}
