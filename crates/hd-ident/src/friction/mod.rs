//! The friction fits: the static stage (Tc, Ts, ωs, σ2 from a steady-state sweep), the
//! dynamic stage (σ0, σ1 from a time series, static parameters held) and the two in order.

pub mod bristle;
mod combined;
pub mod joint;
mod propagate;
pub mod quasi_steady;
mod steady;
mod transient;

pub use combined::{
    ASYMMETRIC_PARAMS, FRICTION_PARAMS, FrictionFit, fit_friction, fit_friction_settings,
    fit_friction_with,
};
pub use joint::{FrictionOptions, JointSettings, OFFSET, fit_joint, fit_joint_with};
pub use steady::{STATIC_PARAMS, SteadyOptions, SteadyProblem};
pub use transient::{DYNAMIC_PARAMS, TransientProblem, bristle_states};
