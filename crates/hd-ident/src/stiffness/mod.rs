//! Fitting any stiffness law to a torque–deflection record, and comparing the laws.
//!
//! - `memory`: the seed's fading memory (the separable fit of [`crate::hysteresis`]);
//! - `maxwell-slip`: f(θ) plus elastoplastic elements whose yield deflections start from
//!   the record's own reversal excursions; for fixed yield deflections the torque is linear
//!   in a, b, c and the element stiffnesses (≥ 0), solved exactly by non-negative least
//!   squares, then the yield deflections are refined by Levenberg–Marquardt
//!   ([`maxwell_slip`]);
//! - `bouc-wen`: f(θ) plus α·w with A held at 1; a, b, c, α linear, β, γ, n from a grid
//!   and Levenberg–Marquardt ([`bouc_wen`]).
//!
//! Every fit returns a [`LawFit`]: the usual [`FitReport`] (errors, intervals, verdicts),
//! the fitted torque row for row, the loop energy per cycle of each amplitude block
//! ([`cycles`]) and the count of parameters the information criteria charge
//! ([`compare`]).

pub mod bouc_wen;
pub mod compare;
pub mod cycles;
pub mod maxwell_slip;
mod report;

use crate::data::HysteresisData;
use crate::error::FitError;
use crate::fix::Fixed;
use crate::hysteresis::fit_hysteresis_with;
use crate::report::FitReport;

pub use compare::{Comparison, ComparisonEntry, compare_laws};

/// The stiffness laws a record can be fitted with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Law {
    /// Cubic spring plus fading memory (rate-dependent).
    Memory,
    /// Cubic spring plus elastoplastic elements (rate-independent).
    MaxwellSlip,
    /// Cubic spring plus a Bouc–Wen element (rate-independent).
    BoucWen,
}

impl Law {
    /// Every law, in the order `--law all` fits them.
    pub const ALL: [Law; 3] = [Law::Memory, Law::MaxwellSlip, Law::BoucWen];

    /// The name used on the command line and in outputs.
    pub fn name(self) -> &'static str {
        match self {
            Law::Memory => "memory",
            Law::MaxwellSlip => "maxwell-slip",
            Law::BoucWen => "bouc-wen",
        }
    }

    /// The law called `name`; the error lists the valid names.
    pub fn parse(name: &str) -> Result<Law, FitError> {
        Law::ALL.into_iter().find(|l| l.name() == name).ok_or_else(|| FitError::Setting {
            field: "law",
            value: name.to_string(),
            expected: "memory, maxwell-slip, bouc-wen or all".into(),
        })
    }
}

/// Settings of a stiffness-law fit.
#[derive(Clone, Debug, PartialEq)]
pub struct LawOptions {
    /// Fit a constant torque offset of the measurement (`offset` [N·m]).
    pub offset: bool,
    /// Maxwell-slip: number of elements (default 8).
    pub elements: usize,
    /// Parameters held fixed (registry names; memory law only).
    pub fixed: Fixed,
}

impl Default for LawOptions {
    fn default() -> Self {
        Self { offset: false, elements: maxwell_slip::DEFAULT_ELEMENTS, fixed: Fixed::none() }
    }
}

/// The result of fitting one law.
#[derive(Clone, Debug, PartialEq)]
pub struct LawFit {
    /// The law.
    pub law: Law,
    /// The report (fit.json).
    pub report: FitReport,
    /// Torque of the fitted law along the measured deflection [N·m].
    pub fitted: Vec<f64>,
    /// Measured minus fitted [N·m].
    pub residuals: Vec<f64>,
    /// Parameters the information criteria charge (free and effective).
    pub charged: usize,
    /// The linear spring coefficient c [N·m/rad] (for plots with c·θ taken off).
    pub c: f64,
}

impl LawFit {
    /// Residual sum of squares [N²·m²].
    pub fn rss(&self) -> f64 {
        self.residuals.iter().map(|r| r * r).sum()
    }
}

/// Fit `law` to `data`. The report names the law, and carries the loop energy per cycle
/// of each amplitude block of the record.
pub fn fit_law(data: &HysteresisData, law: Law, opts: &LawOptions) -> Result<LawFit, FitError> {
    if law != Law::Memory && !opts.fixed.is_empty() {
        return Err(FitError::Setting {
            field: "fix",
            value: opts.fixed.names().collect::<Vec<_>>().join(", "),
            expected: "no fixed parameters: --fix applies to --law memory only".into(),
        });
    }
    let mut fit = match law {
        Law::Memory => {
            let f = fit_hysteresis_with(data, &opts.fixed, opts.offset)?;
            let charged = f.free.len();
            LawFit {
                law,
                c: f.value("c").unwrap_or(0.0),
                fitted: f.fitted,
                residuals: f.residuals,
                report: f.report,
                charged,
            }
        }
        Law::MaxwellSlip => maxwell_slip::fit(data, opts)?,
        Law::BoucWen => bouc_wen::fit(data, opts)?,
    };
    fit.report.law = Some(law.name().to_string());
    fit.report.loop_energy = cycles::loop_energies(data.theta(), data.torque(), &fit.fitted);
    Ok(fit)
}

/// The regressor columns of the cubic spring `a·θ³ + b·θ² + c·θ` over `theta` (in that
/// order), and a constant column for the torque offset when `offset` is set: the linear
/// part every stiffness-law fit shares.
pub(crate) fn spring_columns(theta: &[f64], offset: bool) -> Vec<Vec<f64>> {
    let mut cols: Vec<Vec<f64>> =
        (1..=3).rev().map(|p| theta.iter().map(|t| t.powi(p)).collect()).collect();
    if offset {
        cols.push(vec![1.0; theta.len()]);
    }
    cols
}
