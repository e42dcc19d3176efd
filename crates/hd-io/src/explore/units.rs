//! Units of every column the workbench writes, from the one schema source
//! ([`hd_model::schema`]).

use hd_model::METRICS;

/// The unit of a column the workbench writes, or `None` for an unknown column. Text
/// columns have the empty unit.
pub fn unit_of(name: &str) -> Option<&'static str> {
    hd_model::schema::unit_of(name)
}

/// Whether `name` is one of the run metrics of [`METRICS`].
pub fn is_metric(name: &str) -> bool {
    METRICS.iter().any(|m| m.name == name)
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
    fn labels_carry_the_schema_unit() {
        assert_eq!(label("freq"), "freq [Hz]");
        assert_eq!(label("mem_A"), "mem_A [N·m/rad]");
        assert_eq!(label("variant"), "variant");
        assert!(is_metric("thz_amp") && !is_metric("Tb"));
    }
}
