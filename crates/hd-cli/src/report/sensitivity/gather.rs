//! From a study folder's `study.json` and runs table back to tagged design points and
//! metric values, one set per part with a sobol or morris design.
//!
//! `study.json` lists every run of the study (also those of other shards, and those a
//! killed sweep never ran) with its part and index; within a design part, the k-th run
//! is design point k, so a run missing from the table still has a known place (base row
//! or trajectory) and is counted as a failure there. Runs present in the table carry
//! their tag in `design_method`, `design_group`, `design_slot` and their coordinates in
//! `u_<name>`; the two must agree.

use anyhow::{Context, Result, bail};
use hd_io::Table;
use hd_sweep::StudyManifest;
use hd_sweep::sensitivity::{DesignPoint, PointTag, SensitivityMethod};
use std::collections::HashMap;

/// Metrics never analysed by default: bookkeeping rather than behaviour.
const BOOKKEEPING: [&str; 3] = ["cycles_used", "energy_residual", "limit_cycle"];

/// The analysable data of one design part.
pub struct DesignData {
    /// Part name.
    pub part: String,
    /// sobol or morris.
    pub method: SensitivityMethod,
    /// Design parameters, in the order of the unit coordinates.
    pub parameters: Vec<String>,
    /// One point per run of the part, in design order; a missing run has NaN coordinates.
    pub points: Vec<DesignPoint>,
    /// Metric name and one value per point (NaN for a failed or missing run).
    pub metrics: Vec<(String, Vec<f64>)>,
    /// Base rows (sobol) or trajectories (morris) in the design.
    pub groups: usize,
    /// Runs of the part in the table that failed.
    pub failed: usize,
    /// Runs of the part listed in study.json but absent from the table.
    pub missing: usize,
}

/// Collect every design part of the study. `metrics`: the metrics to analyse (`None`:
/// every kept metric with a finite value in the part, except bookkeeping ones).
pub fn design_parts(
    study: &StudyManifest,
    table: &Table,
    metrics: Option<&[String]>,
) -> Result<Vec<DesignData>> {
    let kept: &[String] = &study.metrics;
    if let Some(asked) = metrics
        && let Some(bad) = asked.iter().find(|m| !kept.contains(m))
    {
        bail!("--metrics: '{bad}' is not a metric of this study (it keeps: {})", kept.join(", "));
    }
    // Rows by run index: the part's runs are indices first_run .. first_run + run_count.
    let row_of: HashMap<u64, usize> = table
        .num("run_index")
        .context("runs table has no run_index column")?
        .iter()
        .enumerate()
        .filter(|(_, i)| i.is_finite())
        .map(|(k, &i)| (i as u64, k))
        .collect();
    let mut out = Vec::new();
    for part in &study.parts {
        let name = part.name.as_str();
        let rows: Vec<Option<usize>> = (part.first_run..part.first_run + part.run_count)
            .map(|i| row_of.get(&i).copied())
            .collect();
        let Some(method) = part_method(table, &rows)? else { continue };
        let parameters: Vec<String> = part.swept.clone();
        let wanted: Vec<String> = match metrics {
            Some(m) => m.to_vec(),
            None => kept
                .iter()
                .filter(|m| !BOOKKEEPING.contains(&m.as_str()))
                .filter(|m| {
                    table.num(m).is_some_and(|c| rows.iter().flatten().any(|&i| c[i].is_finite()))
                })
                .cloned()
                .collect(),
        };
        out.push(gather(name, method, parameters, &rows, table, &wanted)?);
    }
    Ok(out)
}

/// The design method of a part's runs, `None` when it has no design (or no run present).
fn part_method(table: &Table, rows: &[Option<usize>]) -> Result<Option<SensitivityMethod>> {
    let Some(col) = table.text("design_method") else { return Ok(None) };
    let mut found = None;
    for m in rows.iter().flatten().filter_map(|&i| col[i].as_deref()) {
        let m = match m {
            "sobol" => SensitivityMethod::Sobol,
            "morris" => SensitivityMethod::Morris,
            other => bail!("runs table: unknown design_method '{other}'"),
        };
        match found {
            None => found = Some(m),
            Some(f) if f != m => bail!("runs table: one part mixes sobol and morris runs"),
            Some(_) => {}
        }
    }
    Ok(found)
}

/// One part's points and metric values; checks the table's tags against the run order.
fn gather(
    part: &str,
    method: SensitivityMethod,
    parameters: Vec<String>,
    rows: &[Option<usize>],
    table: &Table,
    metrics: &[String],
) -> Result<DesignData> {
    let dims = parameters.len();
    let width = match method {
        SensitivityMethod::Sobol => dims + 2,
        SensitivityMethod::Morris => dims + 1,
    };
    if dims == 0 || !rows.len().is_multiple_of(width) {
        bail!(
            "part '{part}': {} runs for a {method} design over {dims} parameters \
             (expected a multiple of {width}); is study.json from the same study as the runs?",
            rows.len()
        );
    }
    let col = |name: &str| {
        table.num(name).with_context(|| format!("runs table has no numeric column '{name}'"))
    };
    let (group, slot) = (col("design_group")?, col("design_slot")?);
    let unit_cols: Vec<&[f64]> =
        parameters.iter().map(|p| col(&format!("u_{p}"))).collect::<Result<_>>()?;
    let status = table.text("status").context("runs table has no status column")?;
    let mut points = Vec::with_capacity(rows.len());
    let (mut failed, mut missing) = (0, 0);
    for (k, row) in rows.iter().enumerate() {
        let tag = PointTag::from_parts(method, k / width, k % width, dims)
            .expect("slot < width fits the design");
        let unit = match *row {
            None => {
                missing += 1;
                vec![f64::NAN; dims]
            }
            Some(i) => {
                let (g, s) = (group[i], slot[i]);
                if g != (k / width) as f64 || s != (k % width) as f64 {
                    bail!(
                        "part '{part}': run {k} is tagged group {g}, slot {s} in the runs table \
                         but is {tag} in study.json"
                    );
                }
                failed += usize::from(status[i].as_deref() != Some("ok"));
                unit_cols.iter().map(|c| c[i]).collect()
            }
        };
        points.push(DesignPoint { tag, unit });
    }
    let metrics = metrics
        .iter()
        .map(|m| {
            let c = col(m)?;
            let ok = |i: usize| status[i].as_deref() == Some("ok");
            let values =
                rows.iter().map(|r| r.filter(|&i| ok(i)).map_or(f64::NAN, |i| c[i])).collect();
            Ok((m.clone(), values))
        })
        .collect::<Result<_>>()?;
    Ok(DesignData {
        part: part.to_string(),
        method,
        parameters,
        points,
        metrics,
        groups: rows.len() / width,
        failed,
        missing,
    })
}
