//! Identification of the harmonic-drive model from recorded data: the stiffness and memory
//! parameters a, b, c, A, B from torque–deflection records, and the LuGre friction
//! parameters from steady-state sweeps and transient time series, each with standard
//! errors, 95 % intervals, correlations and a verdict on whether the data determine it.
//!
//! The objectives evaluate the hd-model laws themselves ([`hd_model::laws`]): the memory
//! runs along the measured deflection with [`FadingMemory::step_linear`], the bristle state
//! along the measured speed with the LuGre law's exact sample updates (with their parameter
//! sensitivities), never a copy of the equations.
//!
//! Main items:
//! - data sets [`HysteresisData`], [`SteadyData`], [`TransientData`], validated on
//!   construction ([`DataError`]);
//! - [`fit_hysteresis`] and [`fit_friction`], both built on the separable driver
//!   [`separable::fit_separable`] (a global search over the one nonlinear parameter with
//!   argmin's Brent method, linear least squares inside);
//! - [`FitReport`], serialised as `fit.json`, with a terminal [`FitReport::table`];
//! - [`Fixed`] for `--fix NAME=VALUE`;
//! - [`stiffness`]: any stiffness law (memory, Maxwell-slip, Bouc–Wen) fitted to a
//!   torque–deflection record, and the laws ranked by BIC ([`stiffness::compare_laws`]);
//! - [`synth`], synthetic data from the model.
//!
//! [`FadingMemory::step_linear`]: hd_model::laws::stiffness::FadingMemory::step_linear

pub mod criteria;
pub mod data;
pub mod datasheet;
pub mod derivative;
pub mod design;
pub mod drive;
pub mod error;
pub mod fix;
pub mod fleet;
pub mod friction;
pub mod hysteresis;
pub mod linear;
pub mod lm;
pub mod memory_profile;
pub mod nnls;
pub mod path;
pub mod qr_stream;
pub mod report;
pub mod search;
pub mod separable;
pub mod stiffness;
pub mod student_t;
pub mod synth;
pub mod uncertainty;
pub mod varpro;

pub use data::{HysteresisData, SteadyData, TransientData};
pub use error::{DataError, FitError};
pub use fix::Fixed;
pub use friction::{
    FrictionFit, FrictionOptions, JointSettings, fit_friction, fit_friction_settings,
    fit_friction_with, fit_joint_with,
};
pub use hysteresis::{HYSTERESIS_PARAMS, fit_hysteresis, fit_hysteresis_with};
pub use report::{DataSource, Estimate, FitReport};
pub use separable::SeparableFit;
pub use stiffness::{Law, LawFit, LawOptions, fit_law};
