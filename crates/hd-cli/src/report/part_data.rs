//! The rows of one study part, pulled out of the runs table.

use hd_io::Table;
use hd_sweep::study::Part;

/// One part's rows: swept values, variant, status and metrics.
pub struct PartData<'a> {
    /// The part.
    pub part: &'a Part,
    /// Row indices into the runs table.
    pub rows: Vec<usize>,
    /// Numeric swept axes (name, is log-spaced), grid axes first.
    pub numeric_axes: Vec<(String, bool)>,
    /// Swept axes whose values are names (`stiffness`, `compensation`): shown by value in
    /// tables and drawn as separate curves, never as numbers.
    pub text_axes: Vec<String>,
    /// Whether the variant is swept.
    pub variant_swept: bool,
    /// Metrics with at least one finite value in this part.
    pub metrics: Vec<&'static str>,
    /// Number of failed runs.
    pub failed: usize,
    /// The runs table.
    pub table: &'a Table,
}

impl<'a> PartData<'a> {
    /// Collect the part's rows from the runs table.
    pub fn new(part: &'a Part, table: &'a Table, keep: &[&'static str]) -> Self {
        let names = table.text("part").unwrap_or(&[]);
        let rows: Vec<usize> = (0..table.height)
            .filter(|&i| names[i].as_deref() == Some(part.name.as_str()))
            .collect();
        let status = table.text("status").unwrap_or(&[]);
        let failed = rows.iter().filter(|&&i| status[i].as_deref() != Some("ok")).count();
        let mut numeric_axes = Vec::new();
        let mut text_axes = Vec::new();
        let mut variant_swept = false;
        for a in &part.axes {
            let named = !a.values.iter().any(|v| matches!(v, hd_sweep::axis::Value::Num(_)));
            match a.knob {
                hd_sweep::axis::Knob::Variant => variant_swept = true,
                k if named => text_axes.push(k.name().to_string()),
                k => {
                    let xs: Vec<f64> = a
                        .values
                        .iter()
                        .filter_map(|v| match v {
                            hd_sweep::axis::Value::Num(x) => Some(*x),
                            _ => None,
                        })
                        .collect();
                    numeric_axes.push((k.name().to_string(), is_log_spaced(&xs)));
                }
            }
        }
        if let Some(s) = &part.sample {
            numeric_axes.extend(s.bounds.iter().map(|b| (b.knob.name().to_string(), b.log)));
        }
        let metrics = keep
            .iter()
            .copied()
            .filter(|m| table.num(m).is_some_and(|c| rows.iter().any(|&i| c[i].is_finite())))
            .collect();
        PartData { part, rows, numeric_axes, text_axes, variant_swept, metrics, failed, table }
    }

    /// Value of a numeric column at a row.
    pub fn num(&self, col: &str, row: usize) -> f64 {
        self.table.num(col).map_or(f64::NAN, |c| c[row])
    }

    /// Text of a column at a row.
    pub fn text(&self, col: &str, row: usize) -> String {
        self.table.text(col).and_then(|c| c[row].clone()).unwrap_or_default()
    }

    /// Distinct values of a numeric column over the part, sorted.
    pub fn distinct(&self, col: &str) -> Vec<f64> {
        let mut v: Vec<f64> =
            self.rows.iter().map(|&i| self.num(col, i)).filter(|x| x.is_finite()).collect();
        v.sort_by(f64::total_cmp);
        v.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * b.abs().max(1e-300));
        v
    }

    /// The curve a row belongs to: its variant, then the value of each text axis
    /// (`full, stiffness = bouc-wen`).
    pub fn curve(&self, row: usize) -> String {
        let mut name = self.text("variant", row);
        for a in &self.text_axes {
            name.push_str(&format!(", {a} = {}", self.text(a, row)));
        }
        name
    }

    /// Distinct curves ([`Self::curve`]) over the part, in order of appearance.
    pub fn variants(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for &i in &self.rows {
            let v = self.curve(i);
            if !out.contains(&v) {
                out.push(v);
            }
        }
        out
    }
}

/// Whether positive values are closer to geometric than to arithmetic spacing.
pub fn is_log_spaced(xs: &[f64]) -> bool {
    if xs.len() < 3 || xs.iter().any(|x| *x <= 0.0) {
        return false;
    }
    let mut s = xs.to_vec();
    s.sort_by(f64::total_cmp);
    let ratios: Vec<f64> = s.windows(2).map(|w| w[1] / w[0]).collect();
    let diffs: Vec<f64> = s.windows(2).map(|w| w[1] - w[0]).collect();
    let spread = |v: &[f64]| {
        let (lo, hi) =
            v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
        hi / lo
    };
    spread(&ratios) < spread(&diffs)
}
