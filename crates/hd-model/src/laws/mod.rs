//! The physical laws, each behind a small trait: stiffness (with optional memory),
//! friction, motor and voltage input. The rate-independent stiffness laws (Maxwell-slip,
//! Bouc–Wen, catalogue) are used by the identifier and the data synthesis. Variants are combinations of these
//! (see [`crate::variant`]).

pub mod bouc_wen;
pub mod catalogue;
pub mod friction;
pub mod input;
pub mod load;
pub mod maxwell_slip;
pub mod motor;
pub mod stiffness;
