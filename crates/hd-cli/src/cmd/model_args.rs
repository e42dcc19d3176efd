//! The options that pick and tune the drive model, shared by every command that builds
//! one from the command line (`hdw simulate`, `hdw export fmu`): parameters, variant,
//! stiffness law, friction speed and solver.

use clap::{Args, ValueEnum};
use hd_model::{FrictionVelocity, HystLaw, Method, Variant};
use std::path::PathBuf;

/// The drive model and its solver, from the command line.
#[derive(Args, Debug, Clone)]
pub struct ModelArgs {
    /// Parameter file (TOML, registry names as keys, e.g. `c = 6e4`; a `stiffness = "…"`
    /// and a `[controller]` table in it are honoured).
    #[arg(long, value_name = "FILE.toml")]
    pub params: Option<PathBuf>,
    /// Override one parameter, e.g. `--set sigma0=2e5` (repeatable; applied after --params).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Model variant.
    #[arg(long, default_value = "full")]
    pub variant: VariantArg,
    /// Hysteretic stiffness law of the full variant (parameters: memory mem_A, mem_B;
    /// maxwell-slip ms_n, ms_k, ms_delta or ms_k<i>, ms_f<i>; bouc-wen bw_*; catalogue cat_*)
    /// [default: the params file's `stiffness = "…"`, else memory].
    #[arg(long)]
    pub stiffness: Option<StiffnessArg>,
    /// Where the friction acts and the speed it sees: motor (ωj/N, the seed's), deflection
    /// (θ̇, across the gear) or load (ωz, on the load alone) [default: the params file's
    /// `friction_velocity = "…"`, else motor].
    #[arg(long)]
    pub friction_velocity: Option<FrictionVelocityArg>,
    /// Relative tolerance.
    #[arg(long, default_value_t = 1e-6)]
    pub rtol: f64,
    /// Absolute tolerance (angles in rad, speeds in rad/s, torques in N·m, current in A;
    /// the deflection is held to atol/stiffness).
    #[arg(long, default_value_t = 1e-9)]
    pub atol: f64,
    /// Integration method.
    #[arg(long, default_value = "auto")]
    pub method: MethodArg,
}

/// Variant names on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum VariantArg {
    /// Linear stiffness K̄, no friction.
    Linear,
    /// Linear stiffness K̄, viscous friction C̄0.
    Damped,
    /// Hysteretic stiffness, LuGre friction.
    Full,
}

impl From<VariantArg> for Variant {
    fn from(v: VariantArg) -> Self {
        match v {
            VariantArg::Linear => Variant::Linear,
            VariantArg::Damped => Variant::Damped,
            VariantArg::Full => Variant::Full,
        }
    }
}

/// Stiffness-law names on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum StiffnessArg {
    /// Cubic spring plus fading memory (the seed's law; its loop vanishes at slow rates).
    Memory,
    /// Cubic spring plus elastoplastic elements (rate-independent).
    MaxwellSlip,
    /// Cubic spring plus a Bouc–Wen element (rate-independent).
    BoucWen,
    /// The catalogue's three spring rates, with slip elements for its hysteresis loss.
    Catalogue,
}

impl From<StiffnessArg> for HystLaw {
    fn from(s: StiffnessArg) -> Self {
        match s {
            StiffnessArg::Memory => HystLaw::Memory,
            StiffnessArg::MaxwellSlip => HystLaw::MaxwellSlip,
            StiffnessArg::BoucWen => HystLaw::BoucWen,
            StiffnessArg::Catalogue => HystLaw::Catalogue,
        }
    }
}

/// Method names on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum MethodArg {
    /// Dopri5, switching to a stiff method (and back) while Dopri5's stiffness estimate
    /// says its steps would cost less overall: the implicit–explicit pair when the bristle
    /// is the only stiff state, Rodas4 with an inductance or a friction observer; the
    /// switches are counted in metrics.json.
    Auto,
    /// Explicit Dormand–Prince 5(4).
    Dopri5,
    /// Explicit Dormand–Prince 8(5,3) (DOP853), for tight tolerances.
    Dop853,
    /// Rosenbrock Rodas4.
    Rodas4,
    /// Additive Runge–Kutta 4(3): the LuGre bristle state implicit, the rest explicit.
    Imex,
    /// Additive Runge–Kutta 5(4) with the same split: fewer steps at tight tolerances.
    Imex5,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Self {
        match m {
            MethodArg::Auto => Method::Auto,
            MethodArg::Dopri5 => Method::Dopri5,
            MethodArg::Dop853 => Method::Dop853,
            MethodArg::Rodas4 => Method::Rodas4,
            MethodArg::Imex => Method::Imex,
            MethodArg::Imex5 => Method::Imex5,
        }
    }
}

/// Friction-velocity names on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum FrictionVelocityArg {
    /// v = ωj/N.
    Motor,
    /// v = θ̇.
    Deflection,
    /// v = ωz.
    Load,
}

impl From<FrictionVelocityArg> for FrictionVelocity {
    fn from(v: FrictionVelocityArg) -> Self {
        match v {
            FrictionVelocityArg::Motor => FrictionVelocity::Motor,
            FrictionVelocityArg::Deflection => FrictionVelocity::Deflection,
            FrictionVelocityArg::Load => FrictionVelocity::Load,
        }
    }
}
