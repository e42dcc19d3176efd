//! The FMU's variables, all taken from hd-model's schema source: the inputs (the voltage
//! `u`, or nothing but the load torque in closed loop), the outputs (the trace columns of
//! [`hd_model::TRACE_COLUMNS`], with their units and descriptions) and the parameters (the
//! registry, [`hd_model::registry::REGISTRY`], start values from the exported file).

use hd_model::registry::{ParamInfo, REGISTRY};
use hd_model::registry_slip::SLIP_ELEMENT_PARAMS;
use hd_model::{SimConfig, TRACE_COLUMNS, TraceColumn};

/// Value reference of the FMI 3 independent variable `time` [s].
pub const VR_TIME: u32 = 0;
/// Value reference of the voltage input `u` [V].
pub const VR_U: u32 = 1;
/// Value reference of the load-torque input `T_load` [N·m].
pub const VR_T_LOAD: u32 = 2;
/// Value reference of the first output; output k is trace column k.
const VR_OUTPUT: u32 = 100;
/// Value reference of the first parameter; parameter k is registry entry k.
const VR_PARAM: u32 = 1000;
/// Value reference of the first explicit slip element's stiffness; its slip torque follows.
const VR_SLIP: u32 = 2000;

/// What a variable is.
#[derive(Clone, Copy, Debug)]
pub enum Role {
    /// An input the host sets, held over each communication step.
    Input,
    /// A trace signal.
    Output(&'static TraceColumn),
    /// A registry parameter.
    Parameter(&'static ParamInfo),
}

/// One FMU variable.
#[derive(Clone, Debug)]
pub struct Variable {
    /// Name, as in the trace and the registry.
    pub name: &'static str,
    /// Value reference.
    pub vr: u32,
    /// SI unit (`-` for a ratio, as the schema writes it).
    pub unit: &'static str,
    /// One-line description.
    pub doc: String,
    /// Input, output or parameter.
    pub role: Role,
    /// Start value (inputs and parameters).
    pub start: Option<f64>,
}

/// Whether a trace column exists only in closed loop (the schema's descriptions say so).
pub fn closed_loop_only(c: &TraceColumn) -> bool {
    c.doc.starts_with("closed loop:")
}

/// The variables of the FMU of `cfg`, in model-description order: inputs, outputs,
/// parameters.
pub fn variables(cfg: &SimConfig) -> Vec<Variable> {
    let closed = cfg.controller.is_some();
    let mut out = Vec::new();
    let column = |name: &str| TRACE_COLUMNS.iter().find(|c| c.name == name);
    if !closed && let Some(u) = column("u") {
        out.push(Variable {
            name: u.name,
            vr: VR_U,
            unit: u.unit,
            doc: format!("{}, held over each communication step", u.doc),
            role: Role::Input,
            start: Some(0.0),
        });
    }
    out.push(Variable {
        name: "T_load",
        vr: VR_T_LOAD,
        unit: "N·m",
        doc: "external load torque on the load side, opposing positive motion, held over each communication step".to_string(),
        role: Role::Input,
        start: Some(0.0),
    });
    for (k, c) in TRACE_COLUMNS.iter().enumerate() {
        let input = c.name == "u" && !closed;
        if c.name == "t" || input || (closed_loop_only(c) && !closed) {
            continue;
        }
        out.push(Variable {
            name: c.name,
            vr: VR_OUTPUT + k as u32,
            unit: c.unit,
            doc: c.doc.to_string(),
            role: Role::Output(c),
            start: None,
        });
    }
    for (k, p) in REGISTRY.iter().enumerate() {
        out.push(parameter(p, VR_PARAM + k as u32, cfg));
    }
    let explicit = cfg.params.ms_elements.len().min(SLIP_ELEMENT_PARAMS.len());
    for (i, pair) in SLIP_ELEMENT_PARAMS.iter().take(explicit).enumerate() {
        for (j, p) in pair.iter().enumerate() {
            out.push(parameter(p, VR_SLIP + 2 * i as u32 + j as u32, cfg));
        }
    }
    out
}

fn parameter(p: &'static ParamInfo, vr: u32, cfg: &SimConfig) -> Variable {
    Variable {
        name: p.name,
        vr,
        unit: p.unit,
        doc: p.doc.to_string(),
        role: Role::Parameter(p),
        start: Some(p.get(&cfg.params)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_references_are_unique_and_the_loop_decides_the_inputs() {
        let open = variables(&SimConfig::default());
        let closed =
            variables(&SimConfig { controller: Some(Default::default()), ..Default::default() });
        for vars in [&open, &closed] {
            for (i, a) in vars.iter().enumerate() {
                for b in &vars[i + 1..] {
                    assert_ne!(a.name, b.name);
                    assert_ne!(a.vr, b.vr);
                }
            }
        }
        let role_of = |vars: &[Variable], name: &str| {
            vars.iter().find(|v| v.name == name).map(|v| format!("{:?}", v.role))
        };
        assert!(role_of(&open, "u").unwrap().starts_with("Input"));
        assert!(role_of(&closed, "u").unwrap().starts_with("Output"));
        assert!(role_of(&open, "ref").is_none());
        assert!(role_of(&closed, "tb_hat").is_some());
        assert_eq!(
            open.iter().filter(|v| matches!(v.role, Role::Parameter(_))).count(),
            REGISTRY.len()
        );
    }
}
