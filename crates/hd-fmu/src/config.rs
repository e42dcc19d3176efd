//! The drive an FMU carries: the run configuration of `hdw simulate` (parameters, variant,
//! stiffness law, friction speed, solver settings, controller), written by `hdw export fmu`
//! as `resources/model.toml` and read back by the binary when it is instantiated. The
//! voltage input and the load torque come from the host instead of the file.

use hd_model::laws::load::LoadTorque;
use hd_model::{Input, SimConfig};
use std::path::Path;

/// The FMU's model identifier: the shared library's name in `binaries/<platform>/`.
pub const MODEL_IDENTIFIER: &str = "hd_fmu";

/// Name of the configuration file in the FMU's `resources/` folder.
pub const CONFIG_FILE: &str = "model.toml";

/// `cfg` as the FMU runs it: open loop driven by the host's voltage (held at 0 until the
/// host sets it), no load torque until the host sets one, no trace (the host samples).
pub fn for_fmu(cfg: &SimConfig) -> SimConfig {
    SimConfig {
        input: Input::Constant { amplitude: 0.0 },
        load_torque: LoadTorque::default(),
        record_trace: false,
        ..cfg.clone()
    }
}

/// The text of `resources/model.toml` for `cfg` (see [`for_fmu`]), integrated by the
/// adaptive solver.
pub fn to_toml(cfg: &SimConfig) -> Result<String, String> {
    to_toml_fixed(cfg, None)
}

/// Name of the table of `resources/model.toml` that holds the FMU's own settings (beside
/// hd-model's run configuration).
pub const FMU_TABLE: &str = "fmu";

/// The text of `resources/model.toml` for `cfg`; with `fixed_substeps`, each communication
/// step is integrated in that many fixed Runge–Kutta substeps
/// ([`hd_model::solver::fixed_step`]) instead of by the adaptive solver.
pub fn to_toml_fixed(cfg: &SimConfig, fixed_substeps: Option<u32>) -> Result<String, String> {
    let head = "# The drive of this FMU, as `hdw export fmu` wrote it (hd-model's SimConfig).\n";
    let body = toml::to_string(&for_fmu(cfg))
        .map_err(|e| format!("cannot write the FMU configuration: {e}"))?;
    let tail = fixed_substeps.map_or(String::new(), |m| {
        format!(
            "\n# Each communication step in {m} fixed Runge–Kutta substeps.\n[{FMU_TABLE}]\nfixed_substeps = {m}\n"
        )
    });
    Ok(format!("{head}{body}{tail}"))
}

/// Read a configuration written by [`to_toml`] (or [`to_toml_fixed`]: its FMU table is
/// not hd-model's and is read by [`fixed_substeps`]); `source` names it in errors.
pub fn from_toml(text: &str, source: &str) -> Result<SimConfig, String> {
    let mut table: toml::Table = toml::from_str(text).map_err(|e| format!("{source}: {e}"))?;
    table.remove(FMU_TABLE);
    let cfg: SimConfig = table.try_into().map_err(|e| format!("{source}: {e}"))?;
    cfg.validate().map_err(|e| format!("{source}: {e}"))?;
    Ok(cfg)
}

/// The fixed substeps per communication step that a configuration written by
/// [`to_toml_fixed`] asks for (None: the adaptive solver); `source` names it in errors.
pub fn fixed_substeps(text: &str, source: &str) -> Result<Option<u32>, String> {
    let table: toml::Table = toml::from_str(text).map_err(|e| format!("{source}: {e}"))?;
    let Some(fmu) = table.get(FMU_TABLE) else { return Ok(None) };
    let bad = |what: &str| {
        format!(
            "{source}: [{FMU_TABLE}] {what}: expected fixed_substeps = a whole number from 1 to 100000"
        )
    };
    let fmu = fmu.as_table().ok_or_else(|| bad("is not a table"))?;
    if let Some(k) = fmu.keys().find(|k| k.as_str() != "fixed_substeps") {
        return Err(bad(&format!("has an unknown key `{k}`")));
    }
    match fmu.get("fixed_substeps") {
        None => Ok(None),
        Some(v) => match v.as_integer() {
            Some(m @ 1..=100_000) => Ok(Some(m as u32)),
            _ => Err(bad(&format!("fixed_substeps = {v}"))),
        },
    }
}

/// Read `resources/model.toml` from the FMU's resources folder `dir`.
pub fn load(dir: &Path) -> Result<SimConfig, String> {
    let path = dir.join(CONFIG_FILE);
    let text = std::fs::read_to_string(&path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    from_toml(&text, &path.display().to_string())
}

/// A token that identifies this configuration (the FMI 2 `guid`, the FMI 3
/// `instantiationToken`): two 64-bit FNV-1a hashes of the text, written as a GUID.
pub fn token(text: &str) -> String {
    let fnv = |seed: u64| {
        text.bytes().fold(seed, |h, b| (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3))
    };
    let (a, b) = (fnv(0xcbf2_9ce4_8422_2325), fnv(0x6c62_272e_07bb_0142));
    format!(
        "{{{:08x}-{:04x}-{:04x}-{:04x}-{:012x}}}",
        a >> 32,
        (a >> 16) & 0xffff,
        a & 0xffff,
        b >> 48,
        b & 0xffff_ffff_ffff
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use hd_model::{ControllerConfig, HystLaw};

    #[test]
    fn a_configuration_survives_the_file() {
        let mut cfg = SimConfig { stiffness: HystLaw::MaxwellSlip, ..Default::default() };
        cfg.params.set("c", 6e4).unwrap();
        cfg.params.set("ms_k2", 1e4).unwrap();
        cfg.controller = Some(ControllerConfig { period: 1e-3, ..Default::default() });
        cfg.solver.rtol = 1e-7;
        let text = to_toml(&cfg).unwrap();
        let back = from_toml(&text, "model.toml").unwrap();
        assert_eq!(back, for_fmu(&cfg));
        assert_eq!(fixed_substeps(&text, "model.toml").unwrap(), None);
    }

    #[test]
    fn a_fixed_step_survives_the_file_and_a_bad_one_is_named() {
        let cfg = SimConfig::default();
        let text = to_toml_fixed(&cfg, Some(8)).unwrap();
        assert_eq!(from_toml(&text, "model.toml").unwrap(), for_fmu(&cfg));
        assert_eq!(fixed_substeps(&text, "model.toml").unwrap(), Some(8));
        for (tail, needle) in [
            ("[fmu]\nfixed_substeps = 0\n", "fixed_substeps = 0"),
            ("[fmu]\nfixed_substeps = 2.5\n", "fixed_substeps = 2.5"),
            ("[fmu]\nsubsteps = 4\n", "unknown key `substeps`"),
        ] {
            let text = format!("{}\n{tail}", to_toml(&cfg).unwrap());
            let e = fixed_substeps(&text, "model.toml").unwrap_err();
            assert!(e.starts_with("model.toml: [fmu]") && e.contains(needle), "{e}");
        }
    }

    #[test]
    fn tokens_differ_with_the_text_and_look_like_guids() {
        let (a, b) = (token("c = 1"), token("c = 2"));
        assert_ne!(a, b);
        assert_eq!(a.len(), 38);
        assert_eq!(a, token("c = 1"));
    }
}
