//! One module per subcommand.

pub mod common;
pub mod simulate;
pub mod study;
