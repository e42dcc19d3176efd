//! Model variants: named combinations of a stiffness law and a friction law
//! (docs/model.md §2.7). The laws are separate components; a variant only picks them.

use crate::laws::friction::{Friction, LuGre, NoFriction, Viscous};
use crate::laws::stiffness::{CubicSpring, FadingMemory, Hysteretic, LinearSpring, Stiffness};
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
    /// Cubic plus fading memory (`A`, `B`).
    Hysteretic,
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

/// Build the stiffness law of the given kind from the parameters.
pub fn stiffness_law(kind: StiffnessKind, p: &Params) -> Stiffness {
    let spring = CubicSpring { a: p.a, b: p.b, c: p.c };
    match kind {
        StiffnessKind::Linear => Stiffness::Linear(LinearSpring { k: p.kbar }),
        StiffnessKind::Cubic => Stiffness::Cubic(spring),
        StiffnessKind::Hysteretic => Stiffness::Hysteretic(Hysteretic {
            spring,
            memory: FadingMemory { a: p.mem_a, b: p.mem_b },
        }),
    }
}

/// Build the friction law of the given kind from the parameters.
pub fn friction_law(kind: FrictionKind, p: &Params) -> Friction {
    match kind {
        FrictionKind::None => Friction::None(NoFriction),
        FrictionKind::Viscous => Friction::Viscous(Viscous { c0: p.c0bar }),
        FrictionKind::Lugre => Friction::LuGre(LuGre::from_params(p)),
    }
}
