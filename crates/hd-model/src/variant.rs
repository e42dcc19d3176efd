//! Model variants: named combinations of a stiffness law and a friction law
//! (docs/model.md §2.7). The laws are separate components; a variant only picks them.

use crate::error::ConfigError;
use crate::laws::bouc_wen::BoucWen;
use crate::laws::catalogue::{CatalogueCurve, with_loss};
use crate::laws::composed::{Curve, Hyst};
use crate::laws::friction::{Friction, LuGre, NoFriction, Viscous};
use crate::laws::slip_set::SlipSet;
use crate::laws::stiffness::{CubicSpring, FadingMemory, LinearSpring, Stiffness};
use crate::params::Params;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Which stiffness law to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StiffnessKind {
    /// `K̄·θ` (parameter `Kbar`).
    Linear,
    /// `a·θ³ + b·θ² + c·θ`.
    Cubic,
    /// Cubic plus fading memory (`mem_A`, `mem_B`).
    Hysteretic,
    /// Cubic plus Maxwell-slip elements (`ms_*`).
    MaxwellSlip,
    /// Cubic plus a Bouc–Wen element (`bw_*`).
    BoucWen,
    /// The catalogue's three-segment curve, with slip elements for its loss (`cat_*`).
    Catalogue,
}

/// The hysteretic stiffness law of the `full` variant (`--stiffness`, study key
/// `stiffness`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum HystLaw {
    /// Cubic spring plus fading memory: the seed's law (rate-dependent).
    #[default]
    Memory,
    /// Cubic spring plus elastoplastic elements (rate-independent).
    MaxwellSlip,
    /// Cubic spring plus a Bouc–Wen element (rate-independent).
    BoucWen,
    /// The catalogue curve plus slip elements sized to its hysteresis loss.
    Catalogue,
}

impl HystLaw {
    /// Every law.
    pub const ALL: [HystLaw; 4] =
        [HystLaw::Memory, HystLaw::MaxwellSlip, HystLaw::BoucWen, HystLaw::Catalogue];

    /// The law's name on the command line, in study files and outputs.
    pub fn name(self) -> &'static str {
        match self {
            HystLaw::Memory => "memory",
            HystLaw::MaxwellSlip => "maxwell-slip",
            HystLaw::BoucWen => "bouc-wen",
            HystLaw::Catalogue => "catalogue",
        }
    }

    /// The stiffness kind the law stands for.
    pub fn kind(self) -> StiffnessKind {
        match self {
            HystLaw::Memory => StiffnessKind::Hysteretic,
            HystLaw::MaxwellSlip => StiffnessKind::MaxwellSlip,
            HystLaw::BoucWen => StiffnessKind::BoucWen,
            HystLaw::Catalogue => StiffnessKind::Catalogue,
        }
    }
}

impl fmt::Display for HystLaw {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for HystLaw {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        HystLaw::ALL.into_iter().find(|v| v.name() == s).ok_or_else(|| {
            format!(
                "unknown stiffness law '{s}': expected memory, maxwell-slip, bouc-wen or catalogue"
            )
        })
    }
}

/// Which friction law to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FrictionKind {
    /// No friction.
    None,
    /// `C̄0·v` (parameter `C0bar`).
    Viscous,
    /// LuGre (`sigma0, sigma1, sigma2, Tc, Ts, ws`).
    Lugre,
}

/// The three variants the seed study compares.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Variant {
    /// Linear stiffness, no friction.
    Linear,
    /// Linear stiffness, viscous friction.
    Damped,
    /// Hysteretic stiffness, LuGre friction.
    #[default]
    Full,
}

impl Variant {
    /// All variants.
    pub const ALL: [Variant; 3] = [Variant::Linear, Variant::Damped, Variant::Full];

    /// The laws this variant combines.
    pub fn kinds(self) -> (StiffnessKind, FrictionKind) {
        match self {
            Variant::Linear => (StiffnessKind::Linear, FrictionKind::None),
            Variant::Damped => (StiffnessKind::Linear, FrictionKind::Viscous),
            Variant::Full => (StiffnessKind::Hysteretic, FrictionKind::Lugre),
        }
    }

    /// The variant's name as used on the command line and in outputs.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Linear => "linear",
            Variant::Damped => "damped",
            Variant::Full => "full",
        }
    }
}

impl fmt::Display for Variant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Variant {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Variant::ALL
            .into_iter()
            .find(|v| v.name() == s)
            .ok_or_else(|| format!("unknown variant '{s}': expected linear, damped or full"))
    }
}

/// Build the stiffness law of the given kind from the parameters; the error names the
/// parameter and what was expected.
pub fn stiffness_law(kind: StiffnessKind, p: &Params) -> Result<Stiffness, ConfigError> {
    let spring = Curve::Cubic(CubicSpring { a: p.a, b: p.b, c: p.c });
    let with = |hyst| Stiffness { curve: spring, hyst };
    Ok(match kind {
        StiffnessKind::Linear => Stiffness::elastic(Curve::Linear(LinearSpring { k: p.kbar })),
        StiffnessKind::Cubic => Stiffness::elastic(spring),
        StiffnessKind::Hysteretic => with(Hyst::Memory(FadingMemory { a: p.mem_a, b: p.mem_b })),
        StiffnessKind::MaxwellSlip => with(Hyst::Slip(slip_set(p)?)),
        StiffnessKind::BoucWen => with(Hyst::BoucWen(BoucWen {
            alpha: p.bw_alpha,
            a: p.bw_a,
            beta: p.bw_beta,
            gamma: p.bw_gamma,
            n: p.bw_n,
        })),
        StiffnessKind::Catalogue => catalogue(p)?,
    })
}

fn invalid(field: &str, value: impl ToString, expected: impl ToString) -> ConfigError {
    ConfigError::Invalid {
        field: field.to_string(),
        value: value.to_string(),
        expected: expected.to_string(),
    }
}

/// The Maxwell-slip elements: the explicit `ms_k<i>`, `ms_f<i>` when any stiffness is set,
/// otherwise `ms_n` even elements of total stiffness `ms_k` up to `ms_delta`.
fn slip_set(p: &Params) -> Result<SlipSet, ConfigError> {
    if p.ms_elements.iter().any(|e| e.k > 0.0) {
        let used: Vec<_> = p.ms_elements.iter().copied().filter(|e| e.k > 0.0).collect();
        return SlipSet::new(&used).map_err(|e| invalid("ms_k<i>, ms_f<i>", used.len(), e));
    }
    if p.ms_n.fract() != 0.0 {
        return Err(invalid(
            "ms_n",
            crate::error::num(p.ms_n),
            "a whole number of elements in [1, 12]",
        ));
    }
    SlipSet::even(p.ms_n as usize, p.ms_k, p.ms_delta)
        .map_err(|e| invalid("ms_n", crate::error::num(p.ms_n), e))
}

/// The catalogue law: the rounded three-segment curve, less the first-loading torque of
/// the slip elements that realise `cat_loss` at `cat_rated`, plus those elements.
fn catalogue(p: &Params) -> Result<Stiffness, ConfigError> {
    // The curve's message reads "K1 = v: expected …"; name the parameter.
    let curve =
        CatalogueCurve::new(p.cat_k1, p.cat_k2, p.cat_k3, p.cat_t1, p.cat_t2).map_err(|e| {
            let (what, expected) = e.split_once(": expected ").unwrap_or((&e, ""));
            let (name, value) = what.split_once(" = ").unwrap_or((what, ""));
            invalid(&format!("cat_{name}"), value, expected)
        })?;
    let law = with_loss(curve, p.cat_loss, p.cat_rated).map_err(|e| {
        let expected = e.split_once(": expected ").map_or(e.as_str(), |x| x.1);
        invalid("cat_loss", p.cat_loss, expected)
    })?;
    let set = SlipSet::new(&law.elements).map_err(|e| invalid("cat_loss", p.cat_loss, e))?;
    let hyst = if set.is_empty() { Hyst::None } else { Hyst::Slip(set) };
    Ok(Stiffness { curve: Curve::Catalogue(law.spring), hyst })
}

/// Whether `p` has a load-side friction law: a Coulomb or static level of it above 0, in
/// either direction.
pub fn has_load_friction(p: &Params) -> bool {
    let neg = [p.tc_neg_load, p.ts_neg_load].map(|v| v.unwrap_or(0.0));
    p.tc_load > 0.0 || p.ts_load > 0.0 || neg.iter().any(|&v| v > 0.0)
}

/// The load-side LuGre law of `p` (the `*_load` parameters, docs/model.md §2.6): `None`
/// when its Coulomb and static levels (either direction's) are all 0; an error naming the
/// field when the law is present without a bristle stiffness or a Stribeck velocity above
/// 0, or when the gear's own law already acts on the load (`friction_velocity = "load"`).
pub fn load_friction_law(
    p: &Params,
    friction_velocity: crate::system::FrictionVelocity,
) -> Result<Option<LuGre>, ConfigError> {
    if !has_load_friction(p) {
        return Ok(None);
    }
    let invalid = |field: &str, value: String, expected: &str| ConfigError::Invalid {
        field: field.to_string(),
        value,
        expected: expected.to_string(),
    };
    for (name, v) in [("sigma0_load", p.sigma0_load), ("ws_load", p.ws_load)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(invalid(
                name,
                v.to_string(),
                "a value > 0 when the load-side friction law is present (a level Tc_load, Ts_load, Tc_neg_load or Ts_neg_load > 0)",
            ));
        }
    }
    if friction_velocity == crate::system::FrictionVelocity::Load {
        return Err(invalid(
            "friction_velocity",
            "\"load\"".to_string(),
            "\"motor\" or \"deflection\" beside a load-side law (Tc_load, Ts_load): the gear's own law already acts on the load; put its levels in Tc and Ts instead",
        ));
    }
    let law = LuGre::symmetric(
        p.sigma0_load,
        p.sigma1_load,
        p.sigma2_load,
        p.tc_load,
        p.ts_load,
        p.ws_load,
    );
    Ok(Some(LuGre {
        tc_neg: p.tc_neg_load.unwrap_or(p.tc_load),
        ts_neg: p.ts_neg_load.unwrap_or(p.ts_load),
        ..law
    }))
}

/// Build the friction law of the given kind from the parameters.
pub fn friction_law(kind: FrictionKind, p: &Params) -> Friction {
    match kind {
        FrictionKind::None => Friction::None(NoFriction),
        FrictionKind::Viscous => Friction::Viscous(Viscous { c0: p.c0bar }),
        FrictionKind::Lugre => Friction::LuGre(LuGre::from_params(p)),
    }
}
