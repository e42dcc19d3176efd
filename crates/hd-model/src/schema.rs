//! The one source of every output schema: each column the workbench writes, with its unit
//! and description, is listed once — parameters in [`crate::registry::REGISTRY`], metrics
//! in [`crate::metrics::METRICS`], trace signals in [`crate::TRACE_COLUMNS`], and the other
//! columns of the run and sensitivity tables here. Writers put these units and
//! descriptions into each Parquet file's field metadata; `hdw explore` prints them;
//! docs/columns.md is checked against them by a test.
//!
//! Names are unique under case folding within each file, because SQL engines (DuckDB,
//! Spark) fold case: a test checks it.

use crate::TRACE_COLUMNS;
use crate::metrics::METRICS;
use crate::registry::REGISTRY;

/// Name, unit and description of one column. The unit is `-` for a ratio or a count and
/// empty for text.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColumnDoc {
    /// Column name.
    pub name: &'static str,
    /// SI unit.
    pub unit: &'static str,
    /// One-line description.
    pub doc: &'static str,
}

const fn col(name: &'static str, unit: &'static str, doc: &'static str) -> ColumnDoc {
    ColumnDoc { name, unit, doc }
}

/// Columns of `runs.parquet` before the parameters: identity and status.
pub static RUN_ID_COLUMNS: &[ColumnDoc] = &[
    col("run_id", "", "stable run identifier, 16 hex digits"),
    col("run_index", "-", "position of the run in the expanded study"),
    col("part", "", "study part the run belongs to"),
    col("variant", "", "model variant: linear, damped or full"),
    col(
        "stiffness",
        "",
        "hysteretic stiffness law of the full variant: memory, maxwell-slip, bouc-wen or catalogue",
    ),
    col("status", "", "ok or failed"),
    col("error", "", "error message of a failed run, null otherwise"),
];

/// Columns of `runs.parquet` after the parameters: input and swept settings.
pub static RUN_INPUT_COLUMNS: &[ColumnDoc] = &[
    col("voltage", "V", "input amplitude or level (null for recorded inputs)"),
    col("freq", "Hz", "drive frequency (null for non-periodic inputs)"),
    col("friction_scale", "-", "factor on the friction torques Tc and Ts, when swept"),
    col("load_torque", "N·m", "constant external load torque T_L, when swept"),
];

/// Columns of `runs.parquet` of studies with a `[controller]`, after the input columns.
pub static RUN_CONTROL_COLUMNS: &[ColumnDoc] = &[
    col("compensation", "", "closed loop: none, friction or friction+compliance"),
    col("feedback", "", "closed loop: fed-back angle, load or motor"),
    col("ctl_kp", "V/rad", "closed loop: proportional gain"),
    col("ctl_ki", "V/(rad·s)", "closed loop: integral gain"),
    col("ctl_kd", "V·s/rad", "closed loop: derivative gain"),
    col("ctl_period", "s", "closed loop: sampling period (0: continuous)"),
    col(
        "ctl_model_scale",
        "-",
        "closed loop: factor on the controller model's friction and stiffness parameters",
    ),
];

/// Columns of `runs.parquet` after the metrics: solver work.
pub static RUN_SOLVER_COLUMNS: &[ColumnDoc] = &[
    col("method", "", "integration method: auto, dopri5, dop853, rodas4, imex or imex5"),
    col("steps", "-", "accepted solver steps"),
    col("rejected_steps", "-", "rejected solver steps"),
    col("rhs_evals", "-", "right-hand-side evaluations"),
    col("jac_evals", "-", "Jacobian evaluations"),
    col("wall_time", "s", "wall time of the integration"),
];

/// Columns of `runs.parquet` of a sobol or morris design; each design parameter adds a
/// `u_<name>` column (see [`DESIGN_UNIT_PREFIX`]).
pub static RUN_DESIGN_COLUMNS: &[ColumnDoc] = &[
    col("design_method", "", "sobol or morris, null outside a design"),
    col("design_group", "-", "Saltelli base row or Morris trajectory"),
    col(
        "design_slot",
        "-",
        "position in the base row (A = 0, AB(i) = i + 1, B = d + 1) or Morris step",
    ),
];

/// Prefix of a design parameter's unit-cube coordinate column, `u_<name>` [-] in [0, 1].
pub const DESIGN_UNIT_PREFIX: &str = "u_";

/// Columns of `sensitivity.parquet`. The Morris statistics take the unit of the metric
/// per parameter range, so their unit is left empty here.
pub static SENSITIVITY_COLUMNS: &[ColumnDoc] = &[
    col("part", "", "study part"),
    col("method", "", "design: sobol or morris"),
    col("parameter", "", "the parameter varied"),
    col("metric", "", "the metric analysed"),
    col("S1", "-", "first-order Sobol' index"),
    col("S1_lo", "-", "lower end of the 95 % bootstrap interval of S1"),
    col("S1_hi", "-", "upper end of that interval"),
    col("ST", "-", "total Sobol' index"),
    col("ST_lo", "-", "lower end of the 95 % bootstrap interval of ST"),
    col("ST_hi", "-", "upper end of that interval"),
    col("mu", "metric unit", "Morris mean elementary effect (metric unit per parameter range)"),
    col(
        "mu_star",
        "metric unit",
        "Morris mean absolute elementary effect (metric unit per parameter range)",
    ),
    col(
        "sigma",
        "metric unit",
        "standard deviation of the elementary effects (metric unit per parameter range)",
    ),
    col("n_used", "-", "base rows or trajectories used"),
    col("n_dropped", "-", "base rows or trajectories dropped (failed runs)"),
    col("note", "", "why an index is missing, if it is"),
];

/// Columns of the `fitted.parquet` a hysteresis fit writes (one row per input sample).
pub static FIT_COLUMNS: &[ColumnDoc] = &[
    col("t", "s", "time of the input sample"),
    col("theta", "rad", "gear deflection of the input sample"),
    col("torque", "N·m", "measured transmitted torque"),
    col("fitted", "N·m", "torque of the fitted law along the measured deflection"),
    col("residual", "N·m", "measured minus fitted torque"),
];

/// Parameters of the rate-independent stiffness laws (Maxwell-slip, Bouc–Wen, catalogue),
/// as they appear in params files, fit.json and comparison.json: the explicit elements
/// (`<i>` stands for an element number) and the laws' registry entries.
pub fn law_params() -> Vec<ColumnDoc> {
    let registry = REGISTRY
        .iter()
        .filter(|p| ["ms_", "bw_", "cat_"].iter().any(|pre| p.name.starts_with(pre)))
        .map(|p| col(p.name, p.unit, p.doc));
    crate::laws::maxwell_slip::PARAMS.iter().copied().chain(registry).collect()
}

/// The kinds of file whose columns this module describes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    /// `runs.parquet` and its shards.
    Runs,
    /// `trace.parquet` (and `traces.parquet`, which adds `run_id`).
    Trace,
    /// `sensitivity.parquet`.
    Sensitivity,
    /// `fitted.parquet` of a hysteresis fit.
    Fit,
}

/// Every column a file of `kind` may hold (design `u_` columns excepted), in order.
pub fn columns(kind: FileKind) -> Vec<ColumnDoc> {
    match kind {
        FileKind::Runs => RUN_ID_COLUMNS
            .iter()
            .copied()
            .chain(REGISTRY.iter().map(|p| col(p.name, p.unit, p.doc)))
            .chain(RUN_INPUT_COLUMNS.iter().copied())
            .chain(RUN_CONTROL_COLUMNS.iter().copied())
            .chain(METRICS.iter().map(|m| col(m.name, m.unit, m.doc)))
            .chain(RUN_SOLVER_COLUMNS.iter().copied())
            .chain(RUN_DESIGN_COLUMNS.iter().copied())
            .collect(),
        FileKind::Trace => std::iter::once(RUN_ID_COLUMNS[0])
            .chain(TRACE_COLUMNS.iter().map(|c| col(c.name, c.unit, c.doc)))
            .collect(),
        FileKind::Sensitivity => SENSITIVITY_COLUMNS.to_vec(),
        FileKind::Fit => FIT_COLUMNS.to_vec(),
    }
}

/// The description of a column the workbench writes, looked up across every schema
/// (parameters by canonical name or alias). `u_<name>` columns are described from their
/// parameter.
pub fn describe(name: &str) -> Option<ColumnDoc> {
    if let Some(p) = crate::registry::find(name) {
        return Some(col(p.name, p.unit, p.doc));
    }
    if let Some(rest) = name.strip_prefix(DESIGN_UNIT_PREFIX)
        && crate::registry::find(rest).is_some()
    {
        return Some(col("u_", "-", "unit-cube coordinate of a design parameter, in [0, 1]"));
    }
    [FileKind::Runs, FileKind::Trace, FileKind::Sensitivity, FileKind::Fit]
        .into_iter()
        .flat_map(columns)
        .find(|c| c.name == name)
}

/// The unit of a column the workbench writes, or `None` for an unknown column.
pub fn unit_of(name: &str) -> Option<&'static str> {
    describe(name).map(|c| c.unit)
}

/// The sections of docs/columns.md generated from this module, by marker name.
pub fn doc_sections() -> Vec<(&'static str, String)> {
    let params: Vec<ColumnDoc> = REGISTRY.iter().map(|p| col(p.name, p.unit, p.doc)).collect();
    let seed = |name: &str| {
        crate::registry::lookup(name).map(|p| p.aliases.join(", ")).unwrap_or_default()
    };
    let mut param_table =
        String::from("| column | seed symbol | unit | meaning |\n|---|---|---|---|\n");
    for c in &params {
        let alias = seed(c.name);
        let alias = if alias.is_empty() { String::new() } else { format!("`{alias}`") };
        param_table += &format!("| `{}` | {alias} | {} | {} |\n", c.name, unit_text(c.unit), c.doc);
    }
    let metrics: Vec<ColumnDoc> = METRICS.iter().map(|m| col(m.name, m.unit, m.doc)).collect();
    let trace: Vec<ColumnDoc> = TRACE_COLUMNS.iter().map(|c| col(c.name, c.unit, c.doc)).collect();
    vec![
        ("run-identity", markdown_table(RUN_ID_COLUMNS)),
        ("parameters", param_table),
        ("run-input", markdown_table(RUN_INPUT_COLUMNS)),
        ("run-control", markdown_table(RUN_CONTROL_COLUMNS)),
        ("metrics", markdown_table(&metrics)),
        ("run-solver", markdown_table(RUN_SOLVER_COLUMNS)),
        ("run-design", markdown_table(RUN_DESIGN_COLUMNS)),
        ("trace", markdown_table(&trace)),
        ("sensitivity", markdown_table(SENSITIVITY_COLUMNS)),
        ("fitted", markdown_table(FIT_COLUMNS)),
        ("law-parameters", markdown_table(&law_params())),
    ]
}

/// `columns` as a Markdown table `| column | unit | meaning |`.
pub fn markdown_table(columns: &[ColumnDoc]) -> String {
    let mut out = String::from("| column | unit | meaning |\n|---|---|---|\n");
    for c in columns {
        out +=
            &format!("| `{}` | {} | {} |\n", c.name, unit_text(c.unit), c.doc.replace('|', "\\|"));
    }
    out
}

fn unit_text(unit: &str) -> &str {
    if unit.is_empty() { "text" } else { unit }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_file_has_two_names_equal_under_case_folding() {
        for kind in [FileKind::Runs, FileKind::Trace, FileKind::Sensitivity, FileKind::Fit] {
            let cols = columns(kind);
            for (i, a) in cols.iter().enumerate() {
                for b in &cols[i + 1..] {
                    assert!(
                        !a.name.eq_ignore_ascii_case(b.name),
                        "{kind:?}: '{}' and '{}' differ only by case",
                        a.name,
                        b.name
                    );
                }
            }
        }
    }

    #[test]
    fn every_column_is_described_once_with_a_unit_field() {
        for kind in [FileKind::Runs, FileKind::Trace, FileKind::Sensitivity] {
            for c in columns(kind) {
                assert!(!c.doc.is_empty(), "{}", c.name);
            }
        }
        assert_eq!(unit_of("mem_A"), Some("N·m/rad"));
        assert_eq!(unit_of("A"), Some("N·m/rad"));
        assert_eq!(unit_of("thz_amp"), Some("rad"));
        assert_eq!(unit_of("Tb"), Some("N·m"));
        assert_eq!(unit_of("wall_time"), Some("s"));
        assert_eq!(unit_of("u_sigma0"), Some("-"));
        assert_eq!(unit_of("status"), Some(""));
        assert_eq!(unit_of("nonsense"), None);
        assert_eq!(unit_of("fitted"), Some("N·m"));
    }

    #[test]
    fn law_parameters_are_unique_under_case_folding_with_the_registry() {
        let laws = law_params();
        let elements = crate::registry_slip::SLIP_ELEMENT_PARAMS.iter().flatten();
        let names: Vec<&str> =
            REGISTRY.iter().map(|p| p.name).chain(elements.map(|p| p.name)).collect();
        for (i, a) in names.iter().enumerate() {
            for b in &names[i + 1..] {
                assert!(!a.eq_ignore_ascii_case(b), "'{a}' and '{b}' differ only by case");
            }
        }
        assert!(laws.iter().all(|c| !c.unit.is_empty() && !c.doc.is_empty()));
    }
}
