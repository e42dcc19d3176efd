//! One module per subcommand.

pub mod common;
pub mod sensitivity;
pub mod simulate;
pub mod study;
