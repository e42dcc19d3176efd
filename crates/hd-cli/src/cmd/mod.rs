//! One module per subcommand.

pub mod common;
pub mod datasheet;
pub mod explore;
pub mod fit;
pub mod fit_hysteresis;
pub mod fit_input;
pub mod plot;
pub mod sensitivity;
pub mod simulate;
pub mod study;
pub mod synth;
