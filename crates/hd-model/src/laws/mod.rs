//! The physical laws, each behind a small type: stiffness (an elastic curve plus a
//! hysteretic part: fading memory, Bouc–Wen or Maxwell-slip elements, see [`composed`]),
//! friction, motor, load torque and voltage input. Simulator, identifier, controller model
//! and data synthesis share them. Variants are combinations of these (see [`crate::variant`]).

pub mod bouc_wen;
pub mod catalogue;
pub mod composed;
pub mod cycles;
pub mod friction;
pub mod input;
pub mod load;
pub mod lugre_step;
pub mod maxwell_slip;
pub mod motor;
pub mod periodicity;
pub mod slip_set;
pub mod stiffness;
