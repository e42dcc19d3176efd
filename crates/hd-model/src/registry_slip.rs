//! Registry entries of the explicit Maxwell-slip elements, `ms_k1`…`ms_k12` [N·m/rad] and
//! `ms_f1`…`ms_f12` [N·m]: accepted wherever a parameter name is read (params files,
//! `--set`, study axes), stored in [`Params::ms_elements`], and not run-table columns (a
//! study with explicit elements records them in its study.json).

use crate::laws::maxwell_slip::SlipElement;
use crate::params::Params;
use crate::registry::ParamInfo;

/// Element `i` (from 0) of the explicit set, created (with k = F = 0) if missing.
fn element_mut(p: &mut Params, i: usize) -> &mut SlipElement {
    if p.ms_elements.len() <= i {
        p.ms_elements.resize(i + 1, SlipElement { k: 0.0, f: 0.0 });
    }
    &mut p.ms_elements[i]
}

macro_rules! element {
    ($k:literal, $f:literal, $i:literal) => {
        [
            ParamInfo {
                name: $k,
                aliases: &[],
                unit: "N·m/rad",
                doc: "stiffness of an explicit Maxwell-slip element",
                min: 0.0,
                max: f64::INFINITY,
                min_inclusive: true,
                get: |p| p.ms_elements.get($i).map_or(0.0, |e| e.k),
                set: |p, v| element_mut(p, $i).k = v,
            },
            ParamInfo {
                name: $f,
                aliases: &[],
                unit: "N·m",
                doc: "slip torque of an explicit Maxwell-slip element",
                min: 0.0,
                max: f64::INFINITY,
                min_inclusive: true,
                get: |p| p.ms_elements.get($i).map_or(0.0, |e| e.f),
                set: |p, v| element_mut(p, $i).f = v,
            },
        ]
    };
}

/// The element entries, by element.
pub static SLIP_ELEMENT_PARAMS: [[ParamInfo; 2]; crate::laws::slip_set::MAX_SLIP] = [
    element!("ms_k1", "ms_f1", 0),
    element!("ms_k2", "ms_f2", 1),
    element!("ms_k3", "ms_f3", 2),
    element!("ms_k4", "ms_f4", 3),
    element!("ms_k5", "ms_f5", 4),
    element!("ms_k6", "ms_f6", 5),
    element!("ms_k7", "ms_f7", 6),
    element!("ms_k8", "ms_f8", 7),
    element!("ms_k9", "ms_f9", 8),
    element!("ms_k10", "ms_f10", 9),
    element!("ms_k11", "ms_f11", 10),
    element!("ms_k12", "ms_f12", 11),
];

/// The element entry called `name`, if any.
pub fn find(name: &str) -> Option<&'static ParamInfo> {
    SLIP_ELEMENT_PARAMS.iter().flatten().find(|p| p.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn element_names_set_and_read_the_explicit_set() {
        let mut p = Params::default();
        p.set("ms_k3", 2e4).unwrap();
        p.set("ms_f3", 0.5).unwrap();
        assert_eq!(p.ms_elements.len(), 3);
        assert_eq!(p.ms_elements[2], SlipElement { k: 2e4, f: 0.5 });
        assert_eq!(p.get("ms_k3").unwrap(), 2e4);
        assert_eq!(p.get("ms_f1").unwrap(), 0.0);
        assert!(p.set("ms_k13", 1.0).is_err());
        assert!(p.set("ms_k2", -1.0).is_err());
    }
}
