//! The parameter registry: one name, unit, default and valid range per parameter, shared
//! by params files, study files, Parquet columns, fit outputs and error messages.

use crate::error::ParamError;
use crate::params::Params;

/// Description of one registry parameter.
#[derive(Clone, Copy, Debug)]
pub struct ParamInfo {
    /// Canonical name, e.g. `"sigma0"`: unique among all parameters, metrics and run-table
    /// columns even when case is folded (SQL engines fold case), so `mem_A`, not `A`.
    pub name: &'static str,
    /// Other names a person may type for it (the seed paper's letters, e.g. `A`); accepted
    /// wherever a name is read, never written.
    pub aliases: &'static [&'static str],
    /// SI unit, e.g. `"N·m/rad"`.
    pub unit: &'static str,
    /// One-line description.
    pub doc: &'static str,
    /// Smallest valid value.
    pub min: f64,
    /// Largest valid value.
    pub max: f64,
    /// Whether `min` itself is allowed.
    pub min_inclusive: bool,
    pub(crate) get: fn(&Params) -> f64,
    pub(crate) set: fn(&mut Params, f64),
}

impl ParamInfo {
    /// Value of this parameter in `p`.
    pub fn get(&self, p: &Params) -> f64 {
        (self.get)(p)
    }

    /// Set this parameter in `p` without checking the range (see [`ParamInfo::check`]).
    pub fn set_unchecked(&self, p: &mut Params, v: f64) {
        (self.set)(p, v)
    }

    /// Default value (the seed's tables).
    pub fn default_value(&self) -> f64 {
        self.get(&Params::default())
    }

    /// Human-readable valid range, e.g. `"> 0"` or `"in [1, 1e5]"`.
    pub fn range_text(&self) -> String {
        let lo = if self.min_inclusive { "[" } else { "(" };
        match (self.min.is_finite(), self.max.is_finite()) {
            (true, false) => {
                format!("{} {}", if self.min_inclusive { ">=" } else { ">" }, self.min)
            }
            (true, true) => format!("in {lo}{}, {}]", self.min, self.max),
            (false, true) => format!("<= {}", self.max),
            (false, false) => "finite".to_string(),
        }
    }

    /// Check that `v` is a finite value inside the valid range.
    pub fn check(&self, v: f64) -> Result<(), ParamError> {
        let below = if self.min_inclusive { v < self.min } else { v <= self.min };
        if !v.is_finite() || below || v > self.max {
            return Err(ParamError::OutOfRange {
                name: self.name.to_string(),
                value: v,
                expected: format!("a finite value {} [{}]", self.range_text(), self.unit),
            });
        }
        Ok(())
    }
}

macro_rules! p {
    ($name:literal, $field:ident, $unit:literal, $min:expr, $incl:expr, $max:expr, $doc:literal) => {
        p!($name, [], $field, $unit, $min, $incl, $max, $doc)
    };
    ($name:literal, [$($alias:literal),*], $field:ident, $unit:literal, $min:expr, $incl:expr, $max:expr, $doc:literal) => {
        ParamInfo {
            name: $name,
            aliases: &[$($alias),*],
            unit: $unit,
            doc: $doc,
            min: $min,
            max: $max,
            min_inclusive: $incl,
            get: |p| p.$field,
            set: |p, v| p.$field = v,
        }
    };
}

/// A negative side's level: its own once set, its positive side's (`$follows`) until then.
macro_rules! p_neg {
    ($name:literal, $field:ident, $follows:ident, $incl:expr, $doc:literal) => {
        ParamInfo {
            name: $name,
            aliases: &[],
            unit: "N·m",
            doc: $doc,
            min: 0.0,
            max: INF,
            min_inclusive: $incl,
            get: |p| p.$field.unwrap_or(p.$follows),
            set: |p, v| p.$field = Some(v),
        }
    };
}

const INF: f64 = f64::INFINITY;

/// All registry parameters, in a fixed order (the column order of outputs).
pub static REGISTRY: &[ParamInfo] = &[
    p!("a", a, "N·m/rad³", -INF, false, INF, "cubic stiffness coefficient"),
    p!("b", b, "N·m/rad²", -INF, false, INF, "quadratic stiffness coefficient"),
    p!("c", c, "N·m/rad", 0.0, false, INF, "linear stiffness coefficient"),
    p!("mem_A", ["A"], mem_a, "N·m/rad", 0.0, true, INF, "memory intensity (seed: A)"),
    p!("mem_B", ["B"], mem_b, "1/s", 0.0, true, INF, "memory decay rate (seed: B)"),
    p!("sigma0", sigma0, "N·m/rad", 0.0, false, INF, "LuGre bristle stiffness"),
    p!("sigma1", sigma1, "N·m·s/rad", 0.0, true, INF, "LuGre bristle damping"),
    p!("sigma2", sigma2, "N·m·s/rad", 0.0, true, INF, "LuGre viscous friction"),
    p!("Tc", tc, "N·m", 0.0, true, INF, "Coulomb friction torque"),
    p!("Ts", ts, "N·m", 0.0, false, INF, "static friction torque"),
    p!("ws", ws, "rad/s", 0.0, false, INF, "Stribeck velocity"),
    // The negative-side levels follow Tc and Ts until they are set.
    p_neg!("Tc_neg", tc_neg, tc, true, "Coulomb friction torque for negative speeds (default: Tc)"),
    p_neg!("Ts_neg", ts_neg, ts, false, "static friction torque for negative speeds (default: Ts)"),
    p!("mu_c_fwd", mu_c_fwd, "-", 0.0, true, INF, "Coulomb level growth per |Tb|, forward"),
    p!("mu_s_fwd", mu_s_fwd, "-", 0.0, true, INF, "static level growth per |Tb|, forward"),
    p!("mu_c_back", mu_c_back, "-", 0.0, true, INF, "Coulomb level growth per |Tb|, back-driven"),
    p!("mu_s_back", mu_s_back, "-", 0.0, true, INF, "static level growth per |Tb|, back-driven"),
    p!("R", r, "Ω", 0.0, false, INF, "armature resistance"),
    p!("Km", km, "N·m/A", 0.0, false, INF, "motor torque constant"),
    p!("Ke", ke, "V·s/rad", 0.0, true, INF, "back-EMF constant"),
    p!("L", l, "H", 0.0, true, INF, "armature inductance (0: algebraic current)"),
    p!("Jj", jj, "kg·m²", 0.0, false, INF, "motor-side inertia"),
    p!("Jz", jz, "kg·m²", 0.0, false, INF, "load inertia"),
    p!("Cj", cj, "N·m·s/rad", 0.0, true, INF, "motor viscous damping"),
    p!("Cz", cz, "N·m·s/rad", 0.0, true, INF, "load viscous damping"),
    p!("TL", tl, "N·m", -INF, false, INF, "constant load torque against positive load motion"),
    p!("Tc_load", tc_load, "N·m", 0.0, true, INF, "load-side LuGre Coulomb torque (0: none)"),
    p!("Ts_load", ts_load, "N·m", 0.0, true, INF, "load-side LuGre static torque"),
    // The load-side law's negative-side levels follow Tc_load and Ts_load until they are set.
    p_neg!(
        "Tc_neg_load",
        tc_neg_load,
        tc_load,
        true,
        "load-side LuGre Coulomb torque for negative load speeds (default: Tc_load)"
    ),
    p_neg!(
        "Ts_neg_load",
        ts_neg_load,
        ts_load,
        true,
        "load-side LuGre static torque for negative load speeds (default: Ts_load)"
    ),
    p!("ws_load", ws_load, "rad/s", 0.0, true, INF, "load-side LuGre Stribeck velocity"),
    p!("sigma0_load", sigma0_load, "N·m/rad", 0.0, true, INF, "load-side LuGre bristle stiffness"),
    p!("sigma1_load", sigma1_load, "N·m·s/rad", 0.0, true, INF, "load-side LuGre bristle damping"),
    p!("sigma2_load", sigma2_load, "N·m·s/rad", 0.0, true, INF, "load-side LuGre viscous friction"),
    p!("N", n, "-", 1.0, true, INF, "gear ratio"),
    p!("Kbar", kbar, "N·m/rad", 0.0, false, INF, "nominal gear stiffness (linear, damped)"),
    p!("C0bar", c0bar, "N·m·s/rad", 0.0, true, INF, "nominal viscous friction (damped)"),
    p!("ms_n", ms_n, "-", 1.0, true, 12.0, "Maxwell-slip element count (whole number)"),
    p!("ms_k", ms_k, "N·m/rad", 0.0, true, INF, "Maxwell-slip elements' total stiffness"),
    p!("ms_delta", ms_delta, "rad", 0.0, false, INF, "Maxwell-slip largest yield deflection"),
    p!("bw_alpha", bw_alpha, "N·m/rad", 0.0, true, INF, "Bouc–Wen hysteretic stiffness α"),
    p!("bw_A", bw_a, "-", 0.0, true, INF, "Bouc–Wen rate gain A"),
    p!("bw_beta", bw_beta, "rad^-n", -INF, false, INF, "Bouc–Wen shape constant β"),
    p!("bw_gamma", bw_gamma, "rad^-n", -INF, false, INF, "Bouc–Wen shape constant γ"),
    p!("bw_n", bw_n, "-", 0.0, false, INF, "Bouc–Wen smoothness exponent n"),
    p!("cat_K1", cat_k1, "N·m/rad", 0.0, false, INF, "catalogue spring rate below T1"),
    p!("cat_K2", cat_k2, "N·m/rad", 0.0, false, INF, "catalogue spring rate from T1 to T2"),
    p!("cat_K3", cat_k3, "N·m/rad", 0.0, false, INF, "catalogue spring rate above T2"),
    p!("cat_T1", cat_t1, "N·m", 0.0, false, INF, "catalogue corner torque T1"),
    p!("cat_T2", cat_t2, "N·m", 0.0, false, INF, "catalogue corner torque T2"),
    p!("cat_loss", cat_loss, "rad", 0.0, true, INF, "catalogue hysteresis loss (loop width)"),
    p!("cat_rated", ["rated_torque"], cat_rated, "N·m", 0.0, false, INF, "catalogue rated torque"),
];

/// Look a parameter up by its canonical name or an alias (`A` finds `mem_A`); the error
/// suggests the nearest valid name.
pub fn lookup(name: &str) -> Result<&'static ParamInfo, ParamError> {
    find(name).ok_or_else(|| ParamError::Unknown {
        name: name.to_string(),
        suggestion: nearest_name(name).map(str::to_string),
    })
}

/// [`lookup`] without the error: `None` for a name that is not a parameter. For callers
/// that ask about names which need not be parameters (the suggestion's edit distances
/// cost as much as writing a Parquet column's metadata).
pub fn find(name: &str) -> Option<&'static ParamInfo> {
    let found = REGISTRY.iter().find(|p| p.name == name || p.aliases.contains(&name));
    found.or_else(|| crate::registry_slip::find(name))
}

/// The registry name closest to `name` (edit distance, case-insensitive), if any is close.
pub fn nearest_name(name: &str) -> Option<&'static str> {
    nearest_of(name, REGISTRY.iter().map(|p| p.name))
}

/// The canonical name of a parameter typed as `name` (itself when it is not an alias).
pub fn canonical(name: &str) -> &str {
    lookup(name).map_or(name, |p| p.name)
}

/// The candidate closest to `name` by case-insensitive edit distance, when it is within
/// a third of the name's length (at least 2 edits).
pub fn nearest_of<'a>(name: &str, candidates: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    let lower = name.to_lowercase();
    let limit = (name.chars().count() / 3).max(2);
    candidates
        .map(|c| (edit_distance(&lower, &c.to_lowercase()), c))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

/// Levenshtein distance between two strings.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != *cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

/// Parse one `NAME=VALUE` assignment (`--set`, `--fix`): the parameter (by canonical name
/// or alias) and the number. The range is not checked here.
pub fn parse_assignment(text: &str) -> Result<(&'static ParamInfo, f64), ParamError> {
    let (name, value) = text.split_once('=').ok_or_else(|| ParamError::Syntax {
        text: text.to_string(),
        expected: "NAME=VALUE, e.g. sigma0=2e5".to_string(),
    })?;
    let info = lookup(name.trim())?;
    let value: f64 = value.trim().parse().map_err(|_| ParamError::Syntax {
        text: text.to_string(),
        expected: format!("a number after '{}='", name.trim()),
    })?;
    Ok((info, value))
}

impl Params {
    /// Set a parameter by registry name, checking name and range.
    pub fn set(&mut self, name: &str, value: f64) -> Result<(), ParamError> {
        let info = lookup(name)?;
        info.check(value)?;
        info.set_unchecked(self, value);
        Ok(())
    }

    /// Get a parameter by registry name.
    pub fn get(&self, name: &str) -> Result<f64, ParamError> {
        Ok(lookup(name)?.get(self))
    }

    /// Check every parameter against its range, and the cross-parameter rules.
    pub fn validate(&self) -> Result<(), ParamError> {
        for info in REGISTRY {
            info.check(info.get(self))?;
        }
        Ok(())
    }

    /// Parse `NAME=VALUE` (as given to `--set`) and apply it.
    pub fn apply_assignment(&mut self, text: &str) -> Result<(), ParamError> {
        let (info, value) = parse_assignment(text)?;
        info.check(value)?;
        info.set_unchecked(self, value);
        Ok(())
    }

    /// All parameters as `(name, value)` pairs in registry order.
    pub fn to_pairs(&self) -> Vec<(&'static str, f64)> {
        REGISTRY.iter().map(|p| (p.name, p.get(self))).collect()
    }
}
