//! The physical laws, each behind a small trait: stiffness (with optional memory),
//! friction, motor and voltage input. Variants are combinations of these
//! (see [`crate::variant`]).

pub mod friction;
pub mod input;
pub mod load;
pub mod motor;
pub mod stiffness;
