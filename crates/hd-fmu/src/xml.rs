//! `modelDescription.xml` for FMI 2.0 and 3.0 co-simulation, generated from the variable
//! table ([`crate::variables`]), which takes every name, unit and description from
//! hd-model's schema source.

use crate::config::MODEL_IDENTIFIER;
use crate::variables::{Role, VR_TIME, Variable, variables};
use hd_model::SimConfig;
use std::fmt::Write;

/// The FMI standard an FMU follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FmiVersion {
    /// FMI 2.0 (Simulink's FMU Import block, every Modelica tool).
    Fmi2,
    /// FMI 3.0.
    Fmi3,
}

impl FmiVersion {
    /// The folder of the linux x86-64 binary inside the FMU.
    pub fn binary_dir(self) -> &'static str {
        match self {
            FmiVersion::Fmi2 => "binaries/linux64",
            FmiVersion::Fmi3 => "binaries/x86_64-linux",
        }
    }
}

/// Text with the five XML special characters escaped, for an attribute value.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&apos;")
}

/// A unit worth declaring: not empty (text) and not `-` (a ratio or count).
fn unit_of(v: &Variable) -> Option<&'static str> {
    (!v.unit.is_empty() && v.unit != "-").then_some(v.unit)
}

fn causality(v: &Variable) -> &'static str {
    match v.role {
        Role::Input => "input",
        Role::Output(_) => "output",
        Role::Parameter(_) => "parameter",
    }
}

fn variability(v: &Variable) -> &'static str {
    match v.role {
        Role::Parameter(_) => "tunable",
        _ => "continuous",
    }
}

/// `modelDescription.xml` of the FMU of `cfg`; `token` is the FMI 2 guid or FMI 3
/// instantiation token of its `resources/model.toml`.
pub fn model_description(cfg: &SimConfig, version: FmiVersion, token: &str) -> String {
    let vars = variables(cfg);
    let mut units: Vec<&str> = vars.iter().filter_map(unit_of).collect();
    if version == FmiVersion::Fmi3 {
        units.push("s"); // the independent variable's
    }
    units.sort_unstable();
    units.dedup();
    let loop_kind = match &cfg.controller {
        Some(c) => format!(
            "closed loop (PID, {} compensation; the reference is the exported one)",
            c.compensation
        ),
        None => "open loop, driven by the voltage input u".to_string(),
    };
    let description = format!(
        "Motor, harmonic drive and load of hdw: {} variant, {} stiffness, {}",
        cfg.variant,
        cfg.stiffness.name(),
        loop_kind
    );
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let (version_attr, token_attr) = match version {
        FmiVersion::Fmi2 => ("2.0", "guid"),
        FmiVersion::Fmi3 => ("3.0", "instantiationToken"),
    };
    let _ = writeln!(
        x,
        "<fmiModelDescription fmiVersion=\"{version_attr}\" modelName=\"harmonic_drive\" {token_attr}=\"{token}\" description=\"{}\" generationTool=\"hdw {}\" variableNamingConvention=\"flat\"{}>",
        esc(&description),
        env!("CARGO_PKG_VERSION"),
        if version == FmiVersion::Fmi2 { " numberOfEventIndicators=\"0\"" } else { "" }
    );
    let common = "canHandleVariableCommunicationStepSize=\"true\" canGetAndSetFMUstate=\"false\" canSerializeFMUstate=\"false\" providesDirectionalDerivative=\"false\"";
    let _ = match version {
        FmiVersion::Fmi2 => writeln!(
            x,
            "  <CoSimulation modelIdentifier=\"{MODEL_IDENTIFIER}\" {common} canInterpolateInputs=\"true\" maxOutputDerivativeOrder=\"0\"/>"
        ),
        FmiVersion::Fmi3 => writeln!(
            x,
            "  <CoSimulation modelIdentifier=\"{MODEL_IDENTIFIER}\" {} hasEventMode=\"false\"/>",
            common
                .replace("FMUstate", "FMUState")
                .replace("providesDirectionalDerivative=", "providesDirectionalDerivatives=")
        ),
    };
    x += "  <UnitDefinitions>\n";
    for u in &units {
        let _ = writeln!(x, "    <Unit name=\"{}\"/>", esc(u));
    }
    x += "  </UnitDefinitions>\n";
    let _ = writeln!(
        x,
        "  <DefaultExperiment startTime=\"0\" stopTime=\"{:?}\" stepSize=\"{:?}\"/>",
        cfg.t_end,
        cfg.output_interval()
    );
    x += "  <ModelVariables>\n";
    match version {
        FmiVersion::Fmi2 => fmi2_variables(&mut x, &vars),
        FmiVersion::Fmi3 => fmi3_variables(&mut x, &vars),
    }
    x += "  </ModelVariables>\n  <ModelStructure>\n";
    let outputs: Vec<(usize, &Variable)> =
        vars.iter().enumerate().filter(|(_, v)| matches!(v.role, Role::Output(_))).collect();
    match version {
        FmiVersion::Fmi2 => {
            // Indices count from 1 in ModelVariables order.
            for list in ["Outputs", "InitialUnknowns"] {
                let _ = writeln!(x, "    <{list}>");
                for (i, _) in &outputs {
                    let _ = writeln!(x, "      <Unknown index=\"{}\"/>", i + 1);
                }
                let _ = writeln!(x, "    </{list}>");
            }
        }
        FmiVersion::Fmi3 => {
            for element in ["Output", "InitialUnknown"] {
                for (_, v) in &outputs {
                    let _ = writeln!(x, "    <{element} valueReference=\"{}\"/>", v.vr);
                }
            }
        }
    }
    x += "  </ModelStructure>\n</fmiModelDescription>\n";
    x
}

fn fmi2_variables(x: &mut String, vars: &[Variable]) {
    for v in vars {
        let _ = writeln!(
            x,
            "    <ScalarVariable name=\"{}\" valueReference=\"{}\" description=\"{}\" causality=\"{}\" variability=\"{}\">",
            esc(v.name),
            v.vr,
            esc(&v.doc),
            causality(v),
            variability(v)
        );
        let unit = unit_of(v).map(|u| format!(" unit=\"{}\"", esc(u))).unwrap_or_default();
        let start = v.start.map(|s| format!(" start=\"{s:?}\"")).unwrap_or_default();
        let _ = writeln!(x, "      <Real{unit}{start}/>\n    </ScalarVariable>");
    }
}

fn fmi3_variables(x: &mut String, vars: &[Variable]) {
    let _ = writeln!(
        x,
        "    <Float64 name=\"time\" valueReference=\"{VR_TIME}\" description=\"simulation time\" causality=\"independent\" variability=\"continuous\" unit=\"s\"/>"
    );
    for v in vars {
        let unit = unit_of(v).map(|u| format!(" unit=\"{}\"", esc(u))).unwrap_or_default();
        let start = v.start.map(|s| format!(" start=\"{s:?}\"")).unwrap_or_default();
        let _ = writeln!(
            x,
            "    <Float64 name=\"{}\" valueReference=\"{}\" description=\"{}\" causality=\"{}\" variability=\"{}\"{unit}{start}/>",
            esc(v.name),
            v.vr,
            esc(&v.doc),
            causality(v),
            variability(v)
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_unit_used_is_declared_and_outputs_are_listed() {
        for version in [FmiVersion::Fmi2, FmiVersion::Fmi3] {
            let xml = model_description(&SimConfig::default(), version, "{x}");
            for piece in xml.split("unit=\"").skip(1) {
                let unit = &piece[..piece.find('"').unwrap()];
                assert!(xml.contains(&format!("<Unit name=\"{unit}\"/>")), "{unit}");
            }
            assert!(xml.contains("name=\"theta_z\""));
            assert!(xml.contains("name=\"sigma0\""));
        }
        let two = model_description(&SimConfig::default(), FmiVersion::Fmi2, "{x}");
        let outputs = two.matches("causality=\"output\"").count();
        assert_eq!(two.matches("<Unknown index=").count(), 2 * outputs);
    }
}
