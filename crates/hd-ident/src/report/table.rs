//! The terminal table of a fit report.

use super::FitReport;
use std::fmt::Write;

/// A fitted value in the column's fixed width: six significant digits, as every hdw table.
fn sci(v: f64) -> String {
    if v == 0.0 { "0".to_string() } else { hd_text::sci_fixed(v, 6) }
}

impl FitReport {
    /// A plain-text table: parameters with errors and intervals, the fit quality, the
    /// optimiser's work, the notes and the correlation matrix.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{} fit: {} samples, RMS residual {:.4e} N·m, R² {:.6}, noise estimate {:.4e} N·m",
            self.fit, self.samples, self.rms, self.r2, self.noise_std
        );
        let _ = writeln!(
            s,
            "  {:<7} {:>13} {:>12} {:>29}  {:<10} determined",
            "name", "value", "std error", "95 % interval", "unit"
        );
        for (name, e) in &self.parameters.0 {
            let se = e.std_error.map_or("-".to_string(), |v| format!("{v:.3e}"));
            let ci =
                e.ci95.map_or("-".to_string(), |[lo, hi]| format!("[{}, {}]", sci(lo), sci(hi)));
            let det = if e.fixed {
                "fixed"
            } else if e.determined {
                "yes"
            } else {
                "NO"
            };
            let _ = writeln!(
                s,
                "  {name:<7} {:>13} {se:>12} {ci:>29}  {:<10} {det}",
                sci(e.value),
                e.unit
            );
        }
        let notes: Vec<_> =
            self.parameters.0.iter().filter_map(|(n, e)| e.note.as_ref().map(|t| (n, t))).collect();
        if !notes.is_empty() {
            let _ = writeln!(s, "notes:");
            for (n, t) in notes {
                let _ = writeln!(s, "  {n}: {t}");
            }
        }
        let c = &self.correlation;
        if c.names.len() > 1 {
            let _ = write!(s, "correlation:\n  {:<7}", "");
            for n in &c.names {
                let _ = write!(s, " {n:>7}");
            }
            let _ = writeln!(s);
            for (n, row) in c.names.iter().zip(&c.matrix) {
                let _ = write!(s, "  {n:<7}");
                for v in row {
                    let _ = match v {
                        Some(v) => write!(s, " {v:>7.3}"),
                        None => write!(s, " {:>7}", "-"),
                    };
                }
                let _ = writeln!(s);
            }
        }
        let none = if self.stages.is_empty() {
            "no search (nonlinear parameter fixed)"
        } else {
            "staged fit (each stage below)"
        };
        let search = self.search.as_ref().map_or(none.to_string(), |sr| {
            format!(
                "grid of {} points over {} in [{:.3e}, {:.3e}], Brent from {} start(s)",
                sr.grid_points, sr.parameter, sr.range[0], sr.range[1], sr.starts
            )
        });
        let _ = writeln!(
            s,
            "optimiser: {search}; {} iterations, {} evaluations, {:.3} s: {}",
            self.iterations, self.evaluations, self.wall_time_s, self.termination
        );
        for r in &self.remarks {
            let _ = writeln!(s, "remark: {r}");
        }
        for stage in &self.stages {
            let _ = writeln!(s, "\n-- stage --");
            s.push_str(&stage.table());
        }
        s
    }
}
