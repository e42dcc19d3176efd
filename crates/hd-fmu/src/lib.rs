//! The drive of hdw as a co-simulation FMU, FMI 2.0 and 3.0.
//!
//! Built as a `cdylib`, this crate is the FMU's binary: it exports the FMI C functions
//! ([`fmi2`], [`fmi3`]) and runs the drive with hd-model's own system, laws, solver and
//! controller, exactly as `hdw simulate` does ([`hd_model::stepper::Stepper`]), one
//! communication step at a time with the host's inputs held over the step. The drive it
//! runs is read from the FMU's `resources/model.toml` ([`config`]).
//!
//! Built as an `rlib`, it gives `hdw export fmu` the pieces of the archive: the
//! configuration file and `modelDescription.xml` ([`xml`]), whose variables ([`variables`])
//! come from hd-model's schema source (trace columns, parameter registry).
//!
//! Main types: [`instance::Instance`] (one FMU instance, FMI-independent) and
//! [`ffi::Component`] (an instance with its host's logger, behind the C pointer).

pub mod config;
pub mod ffi;
pub mod fmi2;
pub mod fmi3;
pub mod instance;
pub mod variables;
pub mod xml;

pub use config::{CONFIG_FILE, MODEL_IDENTIFIER};
pub use xml::{FmiVersion, model_description};
