//! Physics of the harmonic-drive workbench: a DC motor driving an inertial load through a
//! harmonic drive whose stiffness is hysteretic (an elastic curve plus fading memory,
//! Bouc–Wen or Maxwell-slip elements) and whose friction is dynamic (LuGre). The equations are those of `docs/model.md`.
//!
//! Main types:
//! - [`Params`] and the [`registry`]: every parameter with one name, unit, default, range;
//! - the laws in [`laws`] ([`laws::composed::Stiffness`], [`laws::friction::FrictionLaw`],
//!   [`laws::motor::DcMotor`], [`laws::input::Input`]) combined by a [`Variant`];
//! - [`DriveSystem`], the assembled ODE with its analytic Jacobian;
//! - [`solver`], the adaptive Dopri5 / Rodas4 integrators;
//! - [`simulate`] with [`SimConfig`] → [`SimOutput`] ([`Trace`], [`Metrics`], [`SolverStats`]).
//!
//! No I/O happens here; everything is `Send + Sync` and the integration allocates nothing
//! per step.

pub mod balance;
pub mod closed_loop;
pub mod compliant;
pub mod control;
pub mod cpu;
pub mod dual;
pub mod error;
pub mod fma;
pub mod interp;
pub mod laws;
pub mod metrics;
pub mod out_table;
pub mod params;
pub mod params_file;
pub mod registry;
pub mod registry_slip;
pub mod schema;
pub mod signals;
pub mod simulate;
pub mod solver;
pub mod state;
pub mod stepper;
pub mod system;
pub mod text_file;
pub mod trace;
pub mod variant;

pub use control::{Compensation, ControllerConfig, Feedback, Reference};
pub use error::{ConfigError, ParamError, SolverError};
pub use laws::input::{Input, Profile};
pub use metrics::{METRICS, MetricSettings, Metrics};
pub use out_table::{Cells, OutColumn, OutTable};
pub use params::Params;
pub use simulate::{SimConfig, SimError, SimOutput, simulate, simulate_states, simulate_streaming};
pub use solver::{Method, SolverOptions, SolverStats};
pub use system::{DriveSystem, FrictionVelocity};
pub use trace::{TRACE_COLUMNS, Trace, TraceColumn};
pub use variant::{HystLaw, Variant};
