//! drift.parquet: the drift stage's table, written per parameter in chunks of fits.parquet's
//! rows, each chunk's rows read back from the spills ([`super::fleet_drift`]).

use super::fleet_drift::{CHUNK_ROWS, Regions, note_text};
use super::fleet_spill::Spill;
use anyhow::{Context, Result};
use hd_io::fleet::{FleetCells, FleetColumn, write_fleet_table_batched};
use hd_io::table::Table;
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

pub(super) fn col(name: &str, cells: FleetCells, unit: &str, doc: &str) -> FleetColumn {
    FleetColumn { name: name.into(), cells, unit: unit.into(), doc: doc.into() }
}

/// drift.parquet: per parameter, its rows in fits.parquet's order (streamed once per
/// parameter; each chunk's rows read back from the spills).
#[allow(clippy::too_many_arguments)]
pub(super) fn write_drift_table(
    dir: &Path,
    fits_path: &Path,
    units: &[String],
    names: &[String],
    regions: &Regions,
    data: &Spill,
    results: &Spill,
    covs: &[String],
) -> Result<()> {
    let unit_of: BTreeMap<&str, usize> =
        units.iter().enumerate().map(|(i, u)| (u.as_str(), i)).collect();
    let out = dir.join("drift.parquet");
    let mut failure: Option<anyhow::Error> = None;
    let res = write_fleet_table_batched(&out, &[], |sink| {
        for (p, name) in names.iter().enumerate() {
            let mut cursor = vec![0usize; units.len()];
            hd_io::fleet::for_each_piece(
                fits_path,
                &["log_index", "file", "status", "parameter", "unit_id", "value"],
                CHUNK_ROWS,
                |t| {
                    let cols = match drift_chunk(
                        t,
                        p,
                        name,
                        &unit_of,
                        &mut cursor,
                        regions,
                        data,
                        results,
                        covs,
                    ) {
                        Ok(c) => c,
                        Err(e) => {
                            failure = Some(e);
                            return Err(hd_io::IoError::format(fits_path, "spill failed"));
                        }
                    };
                    sink(&cols)
                },
            )?;
        }
        Ok(())
    });
    match (res, failure) {
        (_, Some(e)) => Err(e),
        (r, None) => Ok(r?),
    }
}

/// The drift rows of one chunk of fits.parquet for parameter `p`.
#[allow(clippy::too_many_arguments)]
fn drift_chunk(
    t: &Table,
    p: usize,
    name: &str,
    unit_of: &BTreeMap<&str, usize>,
    cursor: &mut [usize],
    regions: &Regions,
    data: &Spill,
    results: &Spill,
    covs: &[String],
) -> Result<Vec<FleetColumn>> {
    let none = Vec::new();
    let (status, param, unit_id, files) = (
        t.text("status").unwrap_or(&none),
        t.text("parameter").unwrap_or(&none),
        t.text("unit_id").unwrap_or(&none),
        t.text("file").unwrap_or(&none),
    );
    let li = t.num("log_index").context("fits.parquet: no log_index")?;
    let values = t.num("value").context("fits.parquet: no value")?;
    // The chunk's rows of the parameter, and each unit's run of records (consecutive).
    let mut picked: Vec<(usize, usize, usize)> = Vec::new();
    let mut span: BTreeMap<usize, (usize, usize)> = BTreeMap::new();
    for r in 0..t.height {
        if status[r].as_deref() != Some("ok") || param[r].as_deref() != Some(name) {
            continue;
        }
        let Some(&u) = unit_id[r].as_deref().and_then(|n| unit_of.get(n)) else { continue };
        let pos = regions.start[p][u] + cursor[u];
        cursor[u] += 1;
        let e = span.entry(u).or_insert((pos, 0));
        e.1 += 1;
        picked.push((r, u, pos));
    }
    let mut got: HashMap<usize, (Vec<f64>, Vec<f64>)> = HashMap::new();
    for (&u, &(first, n)) in &span {
        got.insert(u, (data.get(first, n)?, results.get(first, n)?));
    }
    let (dw, rw) = (data.width(), results.width());
    let mut c: BTreeMap<&str, Vec<f64>> = BTreeMap::new();
    let (mut log_index, mut file, mut unit, mut parameter, mut note, mut flagged) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut cov_vals: Vec<Vec<f64>> = vec![Vec::new(); covs.len()];
    for &(r, u, pos) in &picked {
        let (d, res) = &got[&u];
        let k = pos - span[&u].0;
        let d = &d[k * dw..(k + 1) * dw];
        let x = &res[k * rw..(k + 1) * rw];
        log_index.push(li[r] as u64);
        file.push(files.get(r).cloned().flatten());
        unit.push(Some(units_name(unit_id, r)));
        parameter.push(Some(name.to_string()));
        for (key, v) in [
            ("day", d[1]),
            ("value", values[r]),
            ("std_error", d[3]),
            ("normalised", x[0]),
            ("level", x[1]),
            ("change_pct", x[2]),
            ("z", x[3]),
            ("cusum_upper", x[4]),
            ("cusum_lower", x[5]),
        ] {
            c.entry(key).or_default().push(v);
        }
        flagged.push(x[6] > 0.5);
        note.push(note_text(x[7], x[8], covs));
        for (j, v) in d[4..].iter().enumerate() {
            cov_vals[j].push(*v);
        }
    }
    let mut take = |k: &str| FleetCells::F64(c.remove(k).unwrap_or_default());
    let mut cols = vec![
        col("log_index", FleetCells::U64(log_index), "-", "0-based row of the manifest"),
        col("file", FleetCells::Text(file), "text", "the log file"),
        col("unit_id", FleetCells::Text(unit), "text", "the unit's identifiers joined by '/'"),
        col("parameter", FleetCells::Text(parameter), "text", "registry name of the parameter"),
        col("day", take("day"), "d", "timestamp in days"),
        col("value", take("value"), "param_unit", "the estimate (fits.parquet)"),
        col("std_error", take("std_error"), "param_unit", "its standard error"),
        col(
            "normalised",
            take("normalised"),
            "param_unit",
            "the estimate moved to the reference covariates (the baseline's mean)",
        ),
        col(
            "level",
            take("level"),
            "param_unit",
            "the unit's baseline level at the reference covariates",
        ),
        col(
            "change_pct",
            take("change_pct"),
            "%",
            "normalised residual: change from the unit's baseline level",
        ),
        col(
            "z",
            take("z"),
            "-",
            "residual over its standard deviation (se, unexplained scatter, normalisation)",
        ),
        col("cusum_upper", take("cusum_upper"), "-", "Page's upper CUSUM after this log"),
        col("cusum_lower", take("cusum_lower"), "-", "Page's lower CUSUM after this log"),
        col(
            "flagged",
            FleetCells::Bool(flagged),
            "-",
            "whether the unit's test has alarmed at or before this log",
        ),
        col(
            "note",
            FleetCells::Text(note),
            "text",
            "why the log has no residual (covariate missing, other units, no baseline)",
        ),
    ];
    for (name, v) in covs.iter().zip(cov_vals) {
        cols.push(col(name, FleetCells::F64(v), "-", "covariate (manifest column)"));
    }
    Ok(cols)
}

pub(super) fn units_name(unit_id: &[Option<String>], r: usize) -> String {
    unit_id.get(r).cloned().flatten().unwrap_or_default()
}
