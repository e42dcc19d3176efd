//! The configuration of a compliant-drive fit (`transmission = "compliant"` in the fit
//! configuration of `hdw fit drive`; docs/fit-drive.md). Unknown keys are errors; every
//! check names the file and the key.

use super::fit::Signal;
use super::model::{LOAD_LAW, NAMES, P, hysteresis_of, in_law, ix};
use super::record::Between;
use crate::drive::error::DriveError;
use hd_model::HystLaw;
use serde::Deserialize;
use std::collections::BTreeMap;

/// One voltage test: its file and the column of each signal.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VoltageExperimentConfig {
    /// Name in reports.
    pub name: String,
    /// CSV, Parquet or MAT v5 file, relative to the configuration file.
    pub file: String,
    /// Time column [s].
    pub time: String,
    /// Applied voltage column [V] (a voltage test; absent in closed loop).
    pub voltage: Option<String>,
    /// Closed loop: the recorded controller output column [V or A].
    pub command: Option<String>,
    /// Closed loop: the position reference column [rad, on the fed-back encoder's side].
    pub reference: Option<String>,
    /// Motor encoder column (motor angle θj).
    pub motor: String,
    /// Load encoder column (load angle θz).
    pub load: String,
    /// Armature current column, if logged.
    pub current: Option<String>,
    /// Factor to rad of the motor encoder column (e.g. 2π/4096 for counts); default 1.
    #[serde(default = "one")]
    pub motor_scale: f64,
    /// Factor to rad (m on a linear axis) of the load encoder column; default 1.
    #[serde(default = "one")]
    pub load_scale: f64,
    /// Factor to A of the current column; default 1.
    #[serde(default = "one")]
    pub current_scale: f64,
    /// Factor to V of the voltage column; default 1.
    #[serde(default = "one")]
    pub voltage_scale: f64,
    /// Factor to V or A of the command column; default 1.
    #[serde(default = "one")]
    pub command_scale: f64,
    /// Factor to rad of the reference column; default 1.
    #[serde(default = "one")]
    pub reference_scale: f64,
}

fn one() -> f64 {
    1.0
}

/// `[fit]` of a compliant fit.
#[derive(Clone, Debug, PartialEq, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct CompliantFitConfig {
    /// Outputs compared: `motor`, `load`, `current`; default all the records carry.
    pub outputs: Option<Vec<String>>,
    /// Noise level per output [rad or A]; estimated from each record where absent.
    #[serde(default)]
    pub noise: BTreeMap<String, f64>,
    /// The free parameters; default all but a, b, sigma2, bw_A, bw_n, ms_n and TL, and the
    /// other gear laws' (Km follows Ke unless `km_equals_ke = false`).
    pub free: Option<Vec<String>>,
    /// Parameters removed from the free ones.
    pub fix: Option<Vec<String>>,
    /// Iteration budget of each Levenberg–Marquardt pass; default 300.
    pub max_iterations: Option<usize>,
    /// Fit each record's current sensor offset as a constant; default true (`false` takes
    /// the sensor as zeroed, and lets the current's mean inform the fit).
    pub current_offset: Option<bool>,
}

/// The whole configuration of a compliant fit.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompliantConfig {
    /// `"compliant"`.
    pub transmission: String,
    /// A params file of `hdw simulate` (relative to the configuration) holding the start
    /// values and the gear ratio N; default the seed's parameters.
    pub params_file: Option<String>,
    /// How the voltage runs between samples: `hold` (default: a digital amplifier's
    /// zero-order hold), `linear` or `cubic`.
    pub voltage_between: Option<String>,
    /// Which instant the logged current refers to: `after` (default, just after the new
    /// voltage is applied) or `before` (just before it); [`super::sampling`].
    pub current_sampled: Option<String>,
    /// Whether Km equals Ke (SI units); default true.
    pub km_equals_ke: Option<bool>,
    /// Whether the friction levels differ by direction (Tc_neg, Ts_neg their own
    /// parameters); default: whether the params file or `[params]` sets Tc_neg or Ts_neg.
    pub directional_friction: Option<bool>,
    /// Whether the load-side law's levels differ by direction (Tc_neg_load, Ts_neg_load
    /// their own parameters); default: whether the params file or `[params]` sets either.
    pub directional_load_friction: Option<bool>,
    /// `rotary` (default) or `linear` (a ball screw, a belt: the load's position in m, its
    /// forces in N, its mass in kg, N in rad/m; only the units of the outputs change).
    pub axis: Option<String>,
    /// Where the friction acts: `motor` (on the wave generator, v = ωj/N) or `load` (on the
    /// load alone, v = ωz); default the params file's `friction_velocity`, else `motor`.
    pub friction_velocity: Option<String>,
    /// Runge–Kutta substeps per sample; default from the start's fastest rate.
    pub substeps: Option<usize>,
    /// The records fitted jointly (voltage tests, or closed-loop records with a
    /// `[controller]`).
    pub experiment: Vec<VoltageExperimentConfig>,
    /// The discrete controller of closed-loop records; absent for voltage tests.
    pub controller: Option<super::loop_config::LoopControllerConfig>,
    /// The fit.
    #[serde(default)]
    pub fit: CompliantFitConfig,
    /// Start values by parameter name (override the params file).
    #[serde(default)]
    pub params: BTreeMap<String, f64>,
    /// Bounds `[lower, upper]` by parameter name; default start/1000 to start·1000 for a
    /// positive start.
    #[serde(default)]
    pub bounds: BTreeMap<String, [f64; 2]>,
}

/// Index of parameter `name` in [`NAMES`].
fn index(name: &str, file: &str, key: &str) -> Result<usize, DriveError> {
    NAMES.iter().position(|n| *n == name).ok_or_else(|| {
        DriveError::config(
            format!("{file}, {key} '{name}'"),
            format!("unknown parameter; expected one of {}", NAMES.join(", ")),
        )
    })
}

/// An error naming `key` when parameter `k` belongs to the other gear law than `law`.
fn not_of_law(k: usize, law: HystLaw, file: &str, key: &str) -> Result<(), DriveError> {
    if in_law(k, law) {
        return Ok(());
    }
    let own: Vec<&str> = hysteresis_of(law).iter().map(|&j| NAMES[j]).collect();
    Err(DriveError::config(
        format!("{file}, {key} '{}'", NAMES[k]),
        format!(
            "the params file's gear law is {}, which has no {}; use that law's parameters ({}) or set `stiffness` in the params file",
            law.name(),
            NAMES[k],
            own.join(", ")
        ),
    ))
}

impl CompliantConfig {
    /// Every parameter name typed in `[params]`, `[bounds]` and `[fit] free`/`fix` in its
    /// canonical form (the seed's `A` and `B` are `mem_A` and `mem_B`, as everywhere a name
    /// is typed); an error where two keys of one table name the same parameter.
    fn canonical_names(&mut self, file: &str) -> Result<(), DriveError> {
        use hd_model::registry::canonical;
        fn table<V>(
            map: &mut BTreeMap<String, V>,
            file: &str,
            key: &str,
        ) -> Result<(), DriveError> {
            let typed = std::mem::take(map);
            let mut seen: BTreeMap<String, String> = BTreeMap::new();
            for (name, v) in typed {
                let canon = canonical(&name).to_string();
                if let Some(first) = seen.insert(canon.clone(), name.clone()) {
                    return Err(DriveError::config(
                        format!("{file}, {key} '{name}'"),
                        format!(
                            "two names for one parameter: '{first}' and '{name}' are both {canon}; give it once"
                        ),
                    ));
                }
                map.insert(canon, v);
            }
            Ok(())
        }
        table(&mut self.params, file, "[params]")?;
        table(&mut self.bounds, file, "[bounds]")?;
        for list in [self.fit.free.as_mut(), self.fit.fix.as_mut()].into_iter().flatten() {
            for name in list.iter_mut() {
                *name = canonical(name).to_string();
            }
        }
        Ok(())
    }

    /// Parse and check `text` of file `file`.
    pub fn parse(text: &str, file: &str) -> Result<CompliantConfig, DriveError> {
        use crate::drive::config::{toml_error, validate_compliant};
        let table: toml::Table = toml::from_str(text).map_err(|e| toml_error(file, &e))?;
        validate_compliant::raw(&table, file)?;
        let mut c: CompliantConfig = toml::from_str(text).map_err(|e| toml_error(file, &e))?;
        c.canonical_names(file)?;
        if c.transmission != "compliant" {
            return Err(DriveError::config(
                format!("{file}, transmission"),
                format!("'{}'; expected \"compliant\" or \"rigid\"", c.transmission),
            ));
        }
        if c.experiment.is_empty() {
            return Err(DriveError::config(file, "no [[experiment]]; expected at least one"));
        }
        c.between(file)?;
        super::sampling::current_sampled(&c, file)?;
        c.outputs(file)?;
        super::loop_config::check(&c, file)?;
        c.free(file, None, true, true, true)?;
        for k in c.params.keys() {
            index(k, file, "[params]")?;
        }
        for (k, [lo, hi]) in &c.bounds {
            index(k, file, "[bounds]")?;
            if lo.partial_cmp(hi) != Some(std::cmp::Ordering::Less) {
                return Err(DriveError::config(
                    format!("{file}, [bounds] {k}"),
                    format!("[{lo}, {hi}]; expected lower < upper"),
                ));
            }
        }
        for (k, v) in &c.fit.noise {
            if Signal::parse(k).is_none() || !(*v > 0.0 && v.is_finite()) {
                return Err(DriveError::config(
                    format!("{file}, [fit] noise.{k}"),
                    "expected a positive noise level for `motor`, `load`, `current` or `command`",
                ));
            }
        }
        c.friction_velocity(file, None)?;
        c.axis(file)?;
        validate_compliant::compliant(&c, file)?;
        Ok(c)
    }

    /// Where the gear's friction law acts: the configuration's `friction_velocity`, else
    /// the params file's (`in_params`), else on the wave generator (`motor`).
    pub fn friction_velocity(
        &self,
        file: &str,
        in_params: Option<hd_model::FrictionVelocity>,
    ) -> Result<hd_model::FrictionVelocity, DriveError> {
        match &self.friction_velocity {
            Some(s) => s
                .parse()
                .map_err(|e: String| DriveError::config(format!("{file}, friction_velocity"), e)),
            None => Ok(in_params.unwrap_or_default()),
        }
    }

    /// The axis: rotary unless `axis = "linear"`.
    pub fn axis(&self, file: &str) -> Result<crate::drive::model::Axis, DriveError> {
        use crate::drive::model::Axis;
        match self.axis.as_deref() {
            None => Ok(Axis::Rotary),
            Some(s) => Axis::parse(s).ok_or_else(|| {
                DriveError::config(
                    format!("{file}, axis"),
                    format!("'{s}'; expected \"rotary\" or \"linear\""),
                )
            }),
        }
    }

    /// How the voltage runs between samples.
    pub fn between(&self, file: &str) -> Result<Between, DriveError> {
        match &self.voltage_between {
            None => Ok(super::sampling::DEFAULT_BETWEEN),
            Some(s) => Between::parse(s).ok_or_else(|| {
                DriveError::config(
                    format!("{file}, voltage_between"),
                    format!("'{s}'; expected \"hold\", \"linear\" or \"cubic\""),
                )
            }),
        }
    }

    /// The outputs asked for (None: all the records carry).
    pub fn outputs(&self, file: &str) -> Result<Option<Vec<Signal>>, DriveError> {
        let Some(list) = &self.fit.outputs else { return Ok(None) };
        let mut out = Vec::new();
        for s in list {
            let o = Signal::parse(s).ok_or_else(|| {
                DriveError::config(
                    format!("{file}, [fit] outputs"),
                    format!("'{s}'; expected motor, load, current or command"),
                )
            })?;
            if !out.contains(&o) {
                out.push(o);
            }
        }
        if out.is_empty() {
            return Err(DriveError::config(format!("{file}, [fit] outputs"), "empty list"));
        }
        Ok(Some(out))
    }

    /// Which parameters are free ([`NAMES`] order) for gear law `law` (None: any law's
    /// parameters may be named; the check of a configuration before its params file is
    /// read). The default frees all but a, b, sigma2, bw_A, bw_n, ms_n and TL (a horizontal
    /// axis has no load torque; a user whose load has one names it), and never the other
    /// laws' hysteretic parameters; naming one of those is an error.
    ///
    /// With `directional` false, Tc_neg and Ts_neg follow Tc and Ts (naming them is an
    /// error); with it true they are free by default. The load-side law's parameters are
    /// free by default (but sigma2_load) when the drive has that law (`load_law`), and
    /// naming one without it is an error; its negative side's levels as the gear law's,
    /// with `directional_load`.
    pub fn free(
        &self,
        file: &str,
        law: Option<HystLaw>,
        directional: bool,
        load_law: bool,
        directional_load: bool,
    ) -> Result<[bool; P], DriveError> {
        let mut free = [false; P];
        let other: Vec<usize> = match law {
            Some(l) => super::model::LAWS
                .into_iter()
                .filter(|&o| o != l)
                .flat_map(|o| hysteresis_of(o).iter().copied())
                .collect(),
            None => Vec::new(),
        };
        match &self.fit.free {
            Some(list) => {
                for n in list {
                    let k = index(n, file, "[fit] free")?;
                    if let Some(l) = law {
                        not_of_law(k, l, file, "[fit] free")?;
                    }
                    if law.is_some() && !directional && (k == ix::TC_NEG || k == ix::TS_NEG) {
                        return Err(DriveError::config(
                            format!("{file}, [fit] free '{n}'"),
                            "the friction is symmetric here, so Tc_neg and Ts_neg follow Tc and Ts; set `directional_friction = true` to fit them apart",
                        ));
                    }
                    if law.is_some()
                        && !directional_load
                        && (k == ix::TC_NEG_L || k == ix::TS_NEG_L)
                    {
                        return Err(DriveError::config(
                            format!("{file}, [fit] free '{n}'"),
                            "the load-side law is symmetric here, so Tc_neg_load and Ts_neg_load follow Tc_load and Ts_load; set `directional_load_friction = true` to fit them apart",
                        ));
                    }
                    if !load_law && LOAD_LAW.contains(&k) {
                        return Err(DriveError::config(
                            format!("{file}, [fit] free '{n}'"),
                            "the drive has no load-side friction law; set Tc_load or Ts_load (with sigma0_load and ws_load) in the params file or [params] to add one",
                        ));
                    }
                    free[k] = true;
                }
            }
            None => {
                free = [true; P];
                for k in [ix::A, ix::B, ix::SIGMA2, ix::BW_A, ix::BW_N, ix::MS_N, ix::TL] {
                    free[k] = false;
                }
                free[ix::SIGMA2_L] = false;
                if !load_law {
                    for k in LOAD_LAW {
                        free[k] = false;
                    }
                }
                for &k in &other {
                    free[k] = false;
                }
                if law == Some(HystLaw::Catalogue) {
                    free[ix::C] = false;
                }
                if law.is_none() {
                    for l in [HystLaw::BoucWen, HystLaw::MaxwellSlip, HystLaw::Catalogue] {
                        for &k in hysteresis_of(l) {
                            free[k] = false;
                        }
                    }
                }
            }
        }
        for n in self.fit.fix.iter().flatten() {
            let k = index(n, file, "[fit] fix")?;
            // One parameter both freed by name and fixed is a contradiction, not a choice.
            if let Some(list) = &self.fit.free
                && let Some(f) = list.iter().find(|f| index(f, file, "[fit] free").ok() == Some(k))
            {
                return Err(DriveError::config(
                    format!("{file}, [fit] fix '{n}'"),
                    format!(
                        "'{f}' is also in [fit] free: expected each parameter in one of the two"
                    ),
                ));
            }
            free[k] = false;
        }
        if free[ix::MS_N] {
            return Err(DriveError::config(
                format!("{file}, [fit] free 'ms_n'"),
                "the number of slip elements is a count, not fitted; set it in the params file",
            ));
        }
        if self.km_equals_ke.unwrap_or(true) {
            free[ix::KM] = free[ix::KE];
        }
        if !directional {
            free[ix::TC_NEG] = free[ix::TC];
            free[ix::TS_NEG] = free[ix::TS];
        }
        if !directional_load {
            free[ix::TC_NEG_L] = free[ix::TC_L];
            free[ix::TS_NEG_L] = free[ix::TS_L];
        }
        Ok(free)
    }

    /// Check that `[params]` sets no parameter of the other gear law than `law`.
    pub fn check_law(&self, file: &str, law: HystLaw) -> Result<(), DriveError> {
        for name in self.params.keys() {
            not_of_law(index(name, file, "[params]")?, law, file, "[params]")?;
        }
        Ok(())
    }

    /// Start values ([`NAMES`] order) from the params file's values `base` and `[params]`,
    /// and the bounds.
    pub fn start_and_bounds(&self, base: &[f64; P]) -> ([f64; P], [f64; P], [f64; P]) {
        let mut start = *base;
        for (k, v) in &self.params {
            if let Some(i) = NAMES.iter().position(|n| n == k) {
                start[i] = *v;
            }
        }
        if self.km_equals_ke.unwrap_or(true) {
            start[ix::KM] = start[ix::KE];
        }
        let mut lower = [f64::NEG_INFINITY; P];
        let mut upper = [f64::INFINITY; P];
        for k in 0..NAMES.len() {
            if start[k] > 0.0 {
                lower[k] = start[k] * 1e-3;
                upper[k] = start[k] * 1e3;
            }
            if let Some([lo, hi]) = self.bounds.get(NAMES[k]) {
                lower[k] = *lo;
                upper[k] = *hi;
            }
        }
        (start, lower, upper)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default bounds: start/1000 to start·1000 for a positive start, none otherwise;
    /// a `[bounds]` entry replaces them (a negative lower bound, for Bouc–Wen's γ, too).
    #[test]
    fn default_and_given_bounds() {
        let text = "transmission = \"compliant\"\n[bounds]\nbw_gamma = [-1e6, 1e6]\n\
                    [[experiment]]\nname = \"a\"\nfile = \"a.csv\"\n\
                    time = \"t\"\nvoltage = \"u\"\nmotor = \"m\"\nload = \"l\"\n";
        let cfg = CompliantConfig::parse(text, "fit.toml").unwrap();
        let mut base = [0.0; P];
        base[ix::R] = 6.0;
        base[ix::BW_GAMMA] = 5e4;
        let (_, lower, upper) = cfg.start_and_bounds(&base);
        assert_eq!((lower[ix::R], upper[ix::R]), (6e-3, 6e3));
        assert_eq!((lower[ix::BW_GAMMA], upper[ix::BW_GAMMA]), (-1e6, 1e6));
        assert!(lower[ix::JZ] == f64::NEG_INFINITY && upper[ix::JZ] == f64::INFINITY);
    }

    /// The seed's names `A` and `B` are accepted wherever a parameter is named, as the
    /// canonical `mem_A` and `mem_B`; one parameter named twice is refused, naming both.
    #[test]
    fn the_seeds_names_are_aliases() {
        let experiment = "[[experiment]]\nname = \"a\"\nfile = \"a.csv\"\n\
                          time = \"t\"\nvoltage = \"u\"\nmotor = \"m\"\nload = \"l\"\n";
        let text = format!(
            "transmission = \"compliant\"\n[params]\nA = 3e4\n[bounds]\nB = [1.0, 1e4]\n\
             [fit]\nfree = [\"R\", \"A\", \"B\"]\n{experiment}"
        );
        let cfg = CompliantConfig::parse(&text, "fit.toml").unwrap();
        assert_eq!(cfg.params.get("mem_A"), Some(&3e4));
        assert_eq!(cfg.bounds.get("mem_B"), Some(&[1.0, 1e4]));
        assert_eq!(
            cfg.fit.free.as_deref(),
            Some(&["R".to_string(), "mem_A".into(), "mem_B".into()][..])
        );
        let (start, lower, _) = cfg.start_and_bounds(&[1.0; P]);
        assert_eq!((start[ix::MEM_A], lower[ix::MEM_B]), (3e4, 1.0));
        let twice =
            format!("transmission = \"compliant\"\n[params]\nA = 3e4\nmem_A = 2e4\n{experiment}");
        let e = CompliantConfig::parse(&twice, "fit.toml").unwrap_err().to_string();
        assert!(e.contains("[params]") && e.contains("'A'") && e.contains("'mem_A'"), "{e}");
    }
}
