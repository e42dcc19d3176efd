//! The rows of a sweep as plain columns ([`OutTable`]) for the I/O crate to write:
//! `runs.parquet`, the long-format `traces.parquet` and `sensitivity.parquet`. Column names,
//! units and descriptions are those of [`hd_model::schema`].
//!
//! Runs tables: identity, every registry parameter, input and swept settings, the kept
//! metrics, solver work; studies with a sobol or morris design add `design_method`,
//! `design_group`, `design_slot` and one `u_<name>` column per design parameter (null for
//! runs outside a design).

use crate::RunRow;
use crate::axis::Value;
use crate::sensitivity::SensitivityRow;
use hd_model::registry::{REGISTRY, lookup};
use hd_model::schema::{DESIGN_UNIT_PREFIX, RUN_CONTROL_COLUMNS};
use hd_model::{Cells, ControllerConfig, METRICS, OutTable, TRACE_COLUMNS};

/// The runs table of `rows`, given the study's swept names and kept metrics.
pub fn runs_table(rows: &[RunRow], swept: &[&str], metrics: &[&str]) -> OutTable {
    let mut t = OutTable::default();
    let text = |f: &dyn Fn(&RunRow) -> String| Cells::Text(rows.iter().map(f).collect());
    let num = |f: &dyn Fn(&RunRow) -> f64| Cells::F64(rows.iter().map(f).collect());
    let count = |f: &dyn Fn(&RunRow) -> u64| Cells::U64(rows.iter().map(f).collect());
    t.push("run_id", text(&|r| r.run_id.clone()));
    t.push("run_index", count(&|r| r.run_index as u64));
    t.push("part", text(&|r| r.part.to_string()));
    t.push("variant", text(&|r| r.variant.name().to_string()));
    t.push("stiffness", text(&|r| r.stiffness.name().to_string()));
    t.push("status", text(&|r| r.status.as_str().to_string()));
    t.push("error", Cells::OptText(rows.iter().map(|r| r.error.clone()).collect()));
    for p in REGISTRY {
        t.push(p.name, num(&|r| p.get(&r.params)));
    }
    t.push("voltage", num(&|r| r.voltage));
    t.push("freq", num(&|r| r.freq));
    // Swept settings that are not parameters or input columns (e.g. friction_scale).
    let control: Vec<&str> = RUN_CONTROL_COLUMNS.iter().map(|c| c.name).collect();
    for name in swept.iter().filter(|n| {
        lookup(n).is_err()
            && !["voltage", "freq", "variant", "stiffness"].contains(n)
            && !control.contains(n)
    }) {
        t.push(*name, num(&|r| swept_value(r, name)));
    }
    if rows.iter().any(|r| r.controller.is_some()) {
        let ctl = |f: &dyn Fn(&ControllerConfig) -> f64| {
            Cells::F64(rows.iter().map(|r| r.controller.as_ref().map_or(f64::NAN, f)).collect())
        };
        let name = |f: &dyn Fn(&ControllerConfig) -> String| {
            Cells::OptText(rows.iter().map(|r| r.controller.as_ref().map(f)).collect())
        };
        t.push("compensation", name(&|c| c.compensation.name().to_string()));
        t.push("feedback", name(&|c| format!("{:?}", c.feedback).to_lowercase()));
        t.push("ctl_kp", ctl(&|c| c.kp));
        t.push("ctl_ki", ctl(&|c| c.ki));
        t.push("ctl_kd", ctl(&|c| c.kd));
        t.push("ctl_period", ctl(&|c| c.period));
        t.push("ctl_model_scale", ctl(&|c| c.model_scale));
    }
    for m in metrics {
        let col = METRICS.iter().find(|c| c.name == *m);
        t.push(*m, num(&|r| col.map_or(f64::NAN, |c| c.get(&r.metrics))));
    }
    t.push("method", text(&|r| r.stats.method.name().to_string()));
    t.push("steps", count(&|r| r.stats.steps));
    t.push("rejected_steps", count(&|r| r.stats.rejected));
    t.push("rhs_evals", count(&|r| r.stats.rhs_evals));
    t.push("jac_evals", count(&|r| r.stats.jac_evals));
    t.push("wall_time", num(&|r| r.wall_time));
    push_design_columns(&mut t, rows);
    t
}

/// The design columns (see the module docs); none when the study has no sobol or morris
/// design. Every row of a study carries the same `design_names`, so every part file of a
/// sweep gets the same columns.
fn push_design_columns(t: &mut OutTable, rows: &[RunRow]) {
    let Some(names) = rows.first().map(|r| r.design_names.clone()) else { return };
    if names.is_empty() {
        return;
    }
    let parts = |r: &RunRow| r.design.as_ref().map(|d| d.tag.to_parts(d.unit.len()));
    let method = rows.iter().map(|r| parts(r).map(|p| p.0.as_str().to_string())).collect();
    t.push("design_method", Cells::OptText(method));
    t.push(
        "design_group",
        Cells::OptU64(rows.iter().map(|r| parts(r).map(|p| p.1 as u64)).collect()),
    );
    t.push(
        "design_slot",
        Cells::OptU64(rows.iter().map(|r| parts(r).map(|p| p.2 as u64)).collect()),
    );
    for name in names.iter() {
        let unit = rows.iter().map(|r| r.design.as_ref().and_then(|d| d.unit_of(name)));
        t.push(
            format!("{DESIGN_UNIT_PREFIX}{name}"),
            Cells::F64(unit.map(|u| u.unwrap_or(f64::NAN)).collect()),
        );
    }
}

fn swept_value(r: &RunRow, name: &str) -> f64 {
    r.swept.iter().find(|(n, _)| *n == name).map_or(f64::NAN, |(_, v)| match v {
        Value::Num(x) => *x,
        _ => f64::NAN,
    })
}

/// Long-format traces of the rows that kept one: `run_id, t, u, …, C0`.
pub fn traces_table(rows: &[RunRow]) -> OutTable {
    let mut ids = Vec::new();
    let mut data: Vec<Vec<f64>> = vec![Vec::new(); TRACE_COLUMNS.len()];
    for (r, tr) in rows.iter().filter_map(|r| r.trace.as_ref().map(|tr| (r, tr))) {
        ids.extend(std::iter::repeat_n(r.run_id.clone(), tr.len()));
        for (k, c) in tr.columns().enumerate() {
            data[k].extend_from_slice(c);
        }
    }
    let mut t = OutTable::default();
    t.push("run_id", Cells::Text(ids));
    for (c, d) in TRACE_COLUMNS.iter().zip(data) {
        t.push(c.name, Cells::F64(d));
    }
    t
}

/// The sensitivity results as a table (columns of
/// [`hd_model::schema::SENSITIVITY_COLUMNS`]); `rows` pairs each result with its study part.
pub fn sensitivity_table(rows: &[(String, SensitivityRow)]) -> OutTable {
    let mut t = OutTable::default();
    let text = |f: &dyn Fn(&SensitivityRow) -> String| {
        Cells::Text(rows.iter().map(|(_, r)| f(r)).collect())
    };
    let num =
        |f: &dyn Fn(&SensitivityRow) -> f64| Cells::F64(rows.iter().map(|(_, r)| f(r)).collect());
    let count = |f: &dyn Fn(&SensitivityRow) -> usize| {
        Cells::U64(rows.iter().map(|(_, r)| f(r) as u64).collect())
    };
    t.push("part", Cells::Text(rows.iter().map(|(p, _)| p.clone()).collect()));
    t.push("method", text(&|r| r.method.as_str().to_string()));
    t.push("parameter", text(&|r| r.parameter.clone()));
    t.push("metric", text(&|r| r.metric.clone()));
    t.push("S1", num(&|r| r.s1));
    t.push("S1_lo", num(&|r| r.s1_lo));
    t.push("S1_hi", num(&|r| r.s1_hi));
    t.push("ST", num(&|r| r.st));
    t.push("ST_lo", num(&|r| r.st_lo));
    t.push("ST_hi", num(&|r| r.st_hi));
    t.push("mu", num(&|r| r.mu));
    t.push("mu_star", num(&|r| r.mu_star));
    t.push("sigma", num(&|r| r.sigma));
    t.push("n_used", count(&|r| r.n_used));
    t.push("n_dropped", count(&|r| r.n_dropped));
    t.push("note", Cells::OptText(rows.iter().map(|(_, r)| r.note.clone()).collect()));
    t
}
