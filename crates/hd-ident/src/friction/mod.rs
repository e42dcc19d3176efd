//! The friction fits: the static stage (Tc, Ts, ωs, σ2 from a steady-state sweep), the
//! dynamic stage (σ0, σ1 from a time series, static parameters held) and the two in order.

mod combined;
mod propagate;
mod steady;
mod transient;

pub use combined::{FRICTION_PARAMS, FrictionFit, fit_friction};
pub use steady::{STATIC_PARAMS, SteadyProblem};
pub use transient::{DYNAMIC_PARAMS, TransientProblem, bristle_states, solver_options};
