//! Units of every column the workbench writes, looked up in one place: registry
//! parameters, metrics and trace signals from `hd-model`, the rest from [`OTHER_COLUMNS`].

use hd_model::{Metrics, TRACE_COLUMNS};

/// Columns of `runs.parquet` that are neither parameters, metrics nor trace signals:
/// name, unit (`-` for a count or a ratio, empty for text) and a one-line description.
pub const OTHER_COLUMNS: [(&str, &str, &str); 15] = [
    ("run_id", "", "stable run identifier (text)"),
    ("run_index", "-", "position of the run in the expanded study"),
    ("part", "", "study part the run belongs to (text)"),
    ("variant", "", "model variant: linear, damped or full (text)"),
    ("status", "", "ok or failed (text)"),
    ("error", "", "error message of a failed run, null otherwise (text)"),
    ("voltage", "V", "input amplitude or level (null for recorded inputs)"),
    ("freq", "Hz", "drive frequency (null for non-periodic inputs)"),
    ("friction_scale", "-", "factor on the friction torques Tc and Ts, when swept"),
    ("method", "", "integration method used: dopri5 or rodas4 (text)"),
    ("steps", "-", "accepted solver steps"),
    ("rejected_steps", "-", "rejected solver steps"),
    ("rhs_evals", "-", "right-hand-side evaluations"),
    ("jac_evals", "-", "Jacobian evaluations"),
    ("wall_time", "s", "wall time of the integration"),
];

/// Columns of `sensitivity.parquet` with a fixed unit (the Morris statistics `mu`,
/// `mu_star` and `sigma` take the metric's unit and have none here).
pub const SENSITIVITY_COLUMNS: [(&str, &str, &str); 12] = [
    ("method", "", "design: sobol or morris (text)"),
    ("parameter", "", "the parameter varied (text)"),
    ("metric", "", "the metric analysed (text)"),
    ("S1", "-", "first-order Sobol' index"),
    ("S1_lo", "-", "lower end of the 95 % bootstrap interval of S1"),
    ("S1_hi", "-", "upper end of that interval"),
    ("ST", "-", "total Sobol' index"),
    ("ST_lo", "-", "lower end of the 95 % bootstrap interval of ST"),
    ("ST_hi", "-", "upper end of that interval"),
    ("n_used", "-", "base rows or trajectories used"),
    ("n_dropped", "-", "base rows or trajectories dropped (failed runs)"),
    ("note", "", "why an index is missing, if it is (text)"),
];

/// The unit of a column the workbench writes, or `None` for an unknown column. Text
/// columns have the empty unit.
pub fn unit_of(name: &str) -> Option<&'static str> {
    if let Ok(p) = hd_model::registry::lookup(name) {
        return Some(p.unit);
    }
    Metrics::UNITS
        .iter()
        .map(|(n, u)| (*n, *u))
        .chain(TRACE_COLUMNS.iter().map(|(n, u)| (*n, *u)))
        .chain(OTHER_COLUMNS.iter().chain(&SENSITIVITY_COLUMNS).map(|(n, u, _)| (*n, *u)))
        .find(|(n, _)| *n == name)
        .map(|(_, u)| u)
}

/// Whether `name` is one of the run metrics of [`Metrics::UNITS`].
pub fn is_metric(name: &str) -> bool {
    Metrics::UNITS.iter().any(|(n, _)| *n == name)
}

/// `name [unit]`, or just `name` when the unit is unknown or empty.
pub fn label(name: &str) -> String {
    match unit_of(name) {
        Some(u) if !u.is_empty() => format!("{name} [{u}]"),
        _ => name.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_come_from_each_source() {
        assert_eq!(unit_of("Kbar"), Some("N·m/rad"));
        assert_eq!(unit_of("thz_amp"), Some("rad"));
        assert_eq!(unit_of("Tb"), Some("N·m"));
        assert_eq!(unit_of("wall_time"), Some("s"));
        assert_eq!(unit_of("status"), Some(""));
        assert_eq!(unit_of("nonsense"), None);
        assert_eq!(label("freq"), "freq [Hz]");
        assert_eq!(label("variant"), "variant");
    }
}
