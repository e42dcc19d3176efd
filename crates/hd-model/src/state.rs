//! Layout of the integrated state vector.
//!
//! The drive is integrated in coordinates chosen for conditioning: the gear deflection θ
//! is a state (not θz, from which θ would follow by cancellation), and the LuGre bristle
//! state is carried in torque units (`σ0·s`). The reported signals use the coordinates of
//! docs/model.md §1 (`θz = θj/N − θ`, `s = w/σ0`).
//!
//! The trailing states are running integrals (quadratures) used by the metrics and the
//! energy audit; nothing feeds back from them.

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
/// ∫ z·θ̇ dt: work done on the memory element [J].
pub const Q_HYST: usize = 7;
/// ∫ Tf·v dt: friction dissipation [J].
pub const Q_FRIC: usize = 8;
/// ∫ max(T_out·ωz, 0) dt: positive output work [J].
pub const Q_OUT: usize = 9;
/// ∫ max(Ta·ωj, 0) dt: positive input work at the wave generator [J].
pub const Q_IN: usize = 10;
/// ∫ u·i dt: electrical energy in [J].
pub const Q_ELEC: usize = 11;
/// ∫ (R·i² + Cj·ωj² + Cz·ωz² + B·z²/A) dt: other dissipation [J].
pub const Q_DISS: usize = 12;

/// Number of coupled (dynamic) states.
pub const COUPLED: usize = 7;
/// Total state dimension.
pub const DIM: usize = 13;

/// The integrated state.
pub type State = SVector<f64, DIM>;
