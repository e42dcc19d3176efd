//! Layout of the integrated state vector.
//!
//! The drive is integrated in coordinates chosen for conditioning: the gear deflection θ
//! is a state (not θz, from which θ would follow by cancellation), and the LuGre bristle
//! state is carried in torque units (`σ0·s`). The reported signals use the coordinates of
//! docs/model.md §1 (`θz = θj/N − θ`, `s = w/σ0`).
//!
//! After the plant's seven states come four controller states (zero and inactive in an
//! open-loop run, when the solver treats them like quadratures) and the load-side friction
//! law's bristle (zero and inactive without that law). The trailing states are running integrals (quadratures) used by the metrics and the
//! energy audit; nothing feeds back from them. Last come the slip elements' offsets, which
//! the solver treats like quadratures with zero rate and the system rewrites at each
//! accepted step (see [`crate::laws::slip_set`]).

use nalgebra::SVector;

/// Motor angle θj [rad].
pub const THETA_J: usize = 0;
/// Motor speed ωj [rad/s].
pub const OMEGA_J: usize = 1;
/// Gear deflection θ = θj/N − θz [rad].
pub const THETA: usize = 2;
/// Load speed ωz [rad/s].
pub const OMEGA_Z: usize = 3;
/// Hysteresis memory torque z [N·m].
pub const Z: usize = 4;
/// Bristle torque w = σ0·s [N·m].
pub const W: usize = 5;
/// Armature current i [A] (a state only when L > 0).
pub const CURRENT: usize = 6;
/// Controller integrator ∫e dt [rad·s] (closed loop, continuous time; 0 otherwise).
pub const CTL_I: usize = 7;
/// Controller derivative-filter state: the error low-passed with time constant τd [rad].
pub const CTL_D: usize = 8;
/// Friction observer's bristle torque ŵ = σ0·ŝ of the controller model [N·m].
pub const OBS_W: usize = 9;
/// Compliance pre-filter state q = ẑ − A·θ̂ of the controller model's memory [N·m].
pub const CMP_Q: usize = 10;
/// Bristle torque of the load-side LuGre law w_L = σ0_L·s_L [N·m] (zero and inactive
/// without that law; a coupled state only with it, see `DriveSystem::coupled`).
pub const W_LOAD: usize = 11;
/// ∫ z·θ̇ dt: work done on the memory element [J].
pub const Q_HYST: usize = 12;
/// ∫ Tf·v dt: friction dissipation [J] (both laws': the load-side law's Tf·ωz included).
pub const Q_FRIC: usize = 13;
/// ∫ max(T_out·ωz, 0) dt: positive output work [J].
pub const Q_OUT: usize = 14;
/// ∫ max(Ta·ωj, 0) dt: positive input work at the wave generator [J].
pub const Q_IN: usize = 15;
/// ∫ u·i dt: electrical energy in [J].
pub const Q_ELEC: usize = 16;
/// ∫ (R·i² + Cj·ωj² + Cz·ωz² + B·z²/A) dt: other dissipation [J].
pub const Q_DISS: usize = 17;
/// ∫ T_L·ωz dt: work the load does against the external load torque [J].
pub const Q_LOAD: usize = 18;

/// Number of leading states with a rate (plant, controller and quadratures); the states
/// from here on change only when a step is accepted.
pub const LIVE: usize = Q_LOAD + 1;

/// ∫ slip dissipation: energy the slip elements' sliders have turned into heat [J],
/// advanced when a step is accepted (not by a rate).
pub const Q_SLIP: usize = 19;
/// First of the slip elements' offsets oᵢ = eᵢ − θ [rad], one per element (at most
/// [`crate::laws::slip_set::MAX_SLIP`]); rewritten when a step is accepted, constant
/// inside a step.
pub const SLIP: usize = 20;

/// Number of coupled states of the plant alone (an open-loop run).
pub const PLANT: usize = 7;
/// Number of coupled (dynamic) states: the plant's, the controller's and the load-side
/// bristle's.
pub const COUPLED: usize = 12;
/// Total state dimension.
pub const DIM: usize = SLIP + crate::laws::slip_set::MAX_SLIP;

/// The integrated state.
pub type State = SVector<f64, DIM>;
