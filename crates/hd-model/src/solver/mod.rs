//! Adaptive integrators for small, fixed-size ODE systems.
//!
//! Five embedded methods with error control share one driver:
//! - [`Method::Dopri5`]: Dormand–Prince 5(4), explicit, for non-stiff systems;
//! - [`Method::Dop853`]: Dormand–Prince 8(5,3), explicit, for tight tolerances;
//! - [`Method::Rodas4`]: the stiffly accurate, L-stable Rosenbrock method of order 4(3) of
//!   Hairer and Wanner, which uses the analytic Jacobian and copes with the stiff friction
//!   and inductance cases;
//! - [`Method::Imex`]: an additive Runge–Kutta pair of order 4(3) that integrates the
//!   drive's one stiff state (the LuGre bristle) implicitly and the rest explicitly, so
//!   that neither stability nor a Jacobian limits it;
//! - [`Method::Imex5`]: the same split with a pair of order 5(4), which takes longer steps
//!   where accuracy sets them, but whose explicit part has a small stability interval on
//!   the imaginary axis (a stiff gear's torsional mode holds it).
//!
//! Where the right-hand side has a kink (LuGre's |v| where the sliding speed reverses),
//! the system reports a switching function and the driver lands a step on its zero, so no
//! step straddles the kink ([`OdeSystem::switch_value`]).
//!
//! States beyond [`OdeSystem::COUPLED`] are *quadratures*: their rates depend on the other
//! states but nothing depends on them. The Rosenbrock solve exploits that block structure,
//! they are left out of error control (they are integrals of controlled states), and the
//! explicit and implicit–explicit stages form only the coupled block of their stage states
//! (no rate reads the rest); the step's result advances every live component.
//!
//! Everything is stack-allocated (`SVector<f64, D>`), so a solve allocates nothing.

pub mod control;
mod dop853;
mod dopri5;
mod driver;
mod events;
pub mod fixed_step;
mod hair;
mod imex;
mod imex_tables;
mod lu;
mod rodas4;
mod shadow;
pub mod switching;

pub use dop853::Dense;
pub use driver::{Step, solve};

use crate::fma::fmadd;
use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};

/// An ODE system `y' = f(t, y)` of fixed dimension `D`.
pub trait OdeSystem<const D: usize>: Sync {
    /// Number of leading, coupled states; the rest are quadratures. No rate may read a
    /// quadrature (states beyond [`OdeSystem::live`], constant within a step, may be read):
    /// the stages form only the coupled block of their stage states.
    const COUPLED: usize = D;

    /// Number of leading states that every instance couples (at most `COUPLED`). The
    /// stages form these in loops of constant length, and the rest of the coupled block
    /// only in an instance whose [`OdeSystem::coupled`] reaches past them: a constant loop
    /// over all of `COUPLED` works on states an open-loop drive leaves at rest, and a loop
    /// whose length is read at run time is not unrolled (seed case, fifth-order pair at
    /// rtol 5e-6: 2.18 ms with all 11 of the drive's, 3.0 ms with the length read at run
    /// time, 2.06 ms with a lead of 8). States in the lead that an instance leaves at rest
    /// have zero rates, so the stages leave them as they are.
    const COUPLED_LEAD: usize = Self::COUPLED;

    /// Number of leading states that are actually coupled in this instance (at most
    /// `COUPLED`); the states from here to `COUPLED` must have zero rates and nothing may
    /// depend on them, so the solver treats them like quadratures.
    fn coupled(&self) -> usize {
        Self::COUPLED
    }

    /// Number of leading components whose rates can be non-zero (at most D); the solver
    /// advances only these and copies the rest, which the system may still rewrite in
    /// [`OdeSystem::commit`]. Default: all of them.
    fn live(&self) -> usize {
        D
    }

    /// The right-hand side f(t, y).
    fn rhs(&self, t: f64, y: &SVector<f64, D>) -> SVector<f64, D>;

    /// [`OdeSystem::rhs`] written into `rate`. The explicit stages call this; a system can
    /// write in place and spare the copy of a returned vector.
    #[inline]
    fn rhs_into(&self, t: f64, y: &SVector<f64, D>, rate: &mut SVector<f64, D>) {
        *rate = self.rhs(t, y);
    }

    /// The Jacobian ∂f/∂y and the time derivative ∂f/∂t at (t, y).
    fn jacobian(&self, t: f64, y: &SVector<f64, D>) -> (SMatrix<f64, D, D>, SVector<f64, D>);

    /// A stiff component that is linear in itself, for the implicit–explicit method
    /// ([`Method::Imex`]): `Some((k, d))` when component k's rate is `g(t, y) + d·y_k`
    /// with g and d independent of `y_k`, d evaluated at (t, y). `None` (the default):
    /// no such split.
    fn stiff_split(&self, _t: f64, _y: &SVector<f64, D>) -> Option<(usize, f64)> {
        None
    }

    /// A switching function whose sign change marks a kink in the right-hand side (a rate
    /// with |v| in it changes its derivative where v crosses zero). The driver lands a
    /// step on each crossing, so that no step straddles a kink and every step keeps the
    /// method's order. `None` (the default): no kinks.
    fn switch_value(&self, _t: f64, _y: &SVector<f64, D>) -> Option<f64> {
        None
    }

    /// The rate of [`OdeSystem::switch_value`] along the solution at (t, y) with rate f
    /// [its unit per s]. The default differentiates numerically along f; a system whose
    /// switching function is linear in y can return it exactly.
    fn switch_rate(&self, t: f64, y: &SVector<f64, D>, f: &SVector<f64, D>) -> Option<f64> {
        let tau = 1e-7 * (1.0 + t.abs());
        let s0 = self.switch_value(t, y)?;
        let s1 = self.switch_value(t + tau, &(y + tau * f))?;
        Some((s1 - s0) / tau)
    }

    /// Whether the system can be stiff at all; `auto` never tries a stiff method on one
    /// that cannot. Default: true.
    fn may_be_stiff(&self) -> bool {
        true
    }

    /// Whether [`OdeSystem::stiff_split`] holds all of the system's stiffness, so that
    /// `auto` may use the implicit–explicit pair instead of Rodas4. Default: false.
    fn split_is_complete(&self) -> bool {
        false
    }

    /// One implicit stage of [`Method::Imex`] for the split component k of
    /// [`OdeSystem::stiff_split`]: `y[k]` holds the stage's explicit base b; replace it by
    /// the solution of `y_k = b + c·d·y_k`, that is `b/(1 − c·d)` with d at (t, y), write
    /// f(t, y) into `rate` and return d. The default uses `stiff_split` and `rhs`; a system
    /// whose rate is affine in y_k can do both with one evaluation of its laws. (The rate
    /// is written in place: returning the 31-state vector cost two copies a stage.)
    fn implicit_stage(
        &self,
        t: f64,
        y: &mut SVector<f64, D>,
        k: usize,
        c: f64,
        rate: &mut SVector<f64, D>,
    ) -> f64 {
        let d = self.stiff_split(t, y).map_or(0.0, |(_, d)| d);
        y[k] /= 1.0 - c * d;
        *rate = self.rhs(t, y);
        d
    }

    /// Called once per accepted step from `(t0, y0)` to `(t1, y1)` (with the rates `f0`,
    /// `f1` at both ends), before the observer sees it: lets the system advance states it
    /// keeps outside the ODE (constant within a step, zero rate), such as the slip
    /// elements of a Maxwell-slip law. The default changes nothing.
    fn commit(
        &self,
        _t0: f64,
        _t1: f64,
        _y0: &SVector<f64, D>,
        _f0: &SVector<f64, D>,
        _y1: &mut SVector<f64, D>,
        _f1: &SVector<f64, D>,
    ) {
    }

    /// Scale of each state's absolute tolerance: component i is held to
    /// `atol·abs_scale[i] + rtol·|y_i|`.
    fn abs_scale(&self) -> SVector<f64, D> {
        SVector::from_element(1.0)
    }
}

/// Integration method.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Dopri5, switching to a stiff method (the implicit–explicit pair when the system's
    /// split holds all of its stiffness, Rodas4 otherwise) and back when that is cheaper.
    #[default]
    Auto,
    /// Explicit Dormand–Prince 5(4).
    Dopri5,
    /// Explicit Dormand–Prince 8(5,3) (Hairer's DOP853): for tight tolerances, where
    /// Dopri5 is held by accuracy rather than stability.
    Dop853,
    /// Linearly implicit Rosenbrock Rodas4.
    Rodas4,
    /// Additive Runge–Kutta ARK4(3)6L: the system's one stiff state (the LuGre bristle)
    /// implicit, the rest explicit; no Jacobian, no matrix.
    Imex,
    /// Additive Runge–Kutta ARK5(4)8L: the same split with a fifth-order pair (eight
    /// stages), for tighter tolerances.
    Imex5,
}

impl Method {
    /// Whether this is one of the implicit–explicit pairs (the split's methods).
    pub fn is_imex(self) -> bool {
        matches!(self, Method::Imex | Method::Imex5)
    }

    /// The name used in study files, on the command line and in run tables.
    pub fn name(self) -> &'static str {
        match self {
            Method::Auto => "auto",
            Method::Dopri5 => "dopri5",
            Method::Dop853 => "dop853",
            Method::Rodas4 => "rodas4",
            Method::Imex => "imex",
            Method::Imex5 => "imex5",
        }
    }
}

/// Solver settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverOptions {
    /// Method; `auto` is resolved by the caller.
    pub method: Method,
    /// Relative tolerance [–]; default 1e-6.
    pub rtol: f64,
    /// Absolute tolerance [state units, scaled by `abs_scale`]; default 1e-9.
    pub atol: f64,
    /// Largest step [s]; default unbounded (written as null in JSON, which has no infinity).
    #[serde(with = "unbounded_as_null")]
    pub h_max: f64,
    /// First step [s]; 0 chooses it automatically.
    pub h_init: f64,
    /// Step budget (accepted plus rejected); default 50 million.
    pub max_steps: u64,
}

impl Default for SolverOptions {
    fn default() -> Self {
        Self {
            method: Method::Auto,
            rtol: 1e-6,
            atol: 1e-9,
            h_max: f64::INFINITY,
            h_init: 0.0,
            max_steps: 50_000_000,
        }
    }
}

/// Work done by a solve.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SolverStats {
    /// Method used.
    pub method: Method,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps.
    pub rejected: u64,
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// Jacobian evaluations.
    pub jac_evals: u64,
    /// LU decompositions.
    pub lu_decomps: u64,
    /// Accepted steps taken by a stiff method (Rodas4 or the implicit–explicit pair).
    pub implicit_steps: u64,
    /// Method switches of an `auto` solve.
    pub switches: u64,
}

impl SolverStats {
    /// Add the work of a further solve (a sampled run solves once per period).
    pub fn accumulate(&mut self, o: &SolverStats) {
        self.steps += o.steps;
        self.rejected += o.rejected;
        self.rhs_evals += o.rhs_evals;
        self.jac_evals += o.jac_evals;
        self.lu_decomps += o.lu_decomps;
        self.implicit_steps += o.implicit_steps;
        self.switches += o.switches;
    }
}

/// `y + h·Σ_j c_j·k_j` over the first `n` components, the rest copied from `y` (the sum
/// is formed first and then scaled, term by term in order).
#[inline(always)]
pub(crate) fn combine<const D: usize>(
    y: &SVector<f64, D>,
    h: f64,
    c: &[f64],
    k: &[SVector<f64, D>],
    n: usize,
) -> SVector<f64, D> {
    let mut out = *y;
    combine_range(&mut out, y, h, c, k, 0, n);
    out
}

/// `out`'s coupled block set to `y + h·Σ_j c_j·k_j` (as [`combine`]), its other
/// components left as they are (a stage loop copies y into its stage state once, not per
/// stage): the leading [`OdeSystem::COUPLED_LEAD`] components in a loop of constant
/// length, the rest only when the instance couples them.
#[inline(always)]
pub(crate) fn combine_coupled<const D: usize, S: OdeSystem<D>>(
    sys: &S,
    out: &mut SVector<f64, D>,
    y: &SVector<f64, D>,
    h: f64,
    c: &[f64],
    k: &[SVector<f64, D>],
) {
    combine_range(out, y, h, c, k, 0, S::COUPLED_LEAD);
    if S::COUPLED_LEAD < S::COUPLED && sys.coupled() > S::COUPLED_LEAD {
        combine_range(out, y, h, c, k, S::COUPLED_LEAD, S::COUPLED);
    }
}

/// [`combine`] over the coupled block of `sys` ([`combine_coupled`]), the rest copied
/// from `y`.
#[inline(always)]
pub(crate) fn combine_coupled_from<const D: usize, S: OdeSystem<D>>(
    sys: &S,
    y: &SVector<f64, D>,
    h: f64,
    c: &[f64],
    k: &[SVector<f64, D>],
) -> SVector<f64, D> {
    let mut out = *y;
    combine_coupled(sys, &mut out, y, h, c, k);
    out
}

/// `out`'s components `lo..hi` set to `y + h·Σ_j c_j·k_j` (the sum formed first, then
/// scaled), the others left as they are.
#[inline(always)]
fn combine_range<const D: usize>(
    out: &mut SVector<f64, D>,
    y: &SVector<f64, D>,
    h: f64,
    c: &[f64],
    k: &[SVector<f64, D>],
    lo: usize,
    hi: usize,
) {
    let mut acc = [0.0; D];
    for (cj, kj) in c.iter().zip(k) {
        let kj = &kj.as_slice()[lo..hi];
        for (a, kv) in acc[lo..hi].iter_mut().zip(kj) {
            *a = fmadd(*cj, *kv, *a);
        }
    }
    let ys = &y.as_slice()[lo..hi];
    for ((o, a), yv) in out.as_mut_slice()[lo..hi].iter_mut().zip(&acc[lo..hi]).zip(ys) {
        *o = fmadd(h, *a, *yv);
    }
}

/// Whether every component of `v` is finite. `x·0` is ±0 for a finite x and NaN for an
/// infinite or NaN one, so the sum of those products is 0 exactly when all are finite;
/// four partial sums let the compiler use vector registers. nalgebra's element iterator
/// cost 845 instructions a step for the driver's two checks (callgrind), and a scalar fold
/// over the slice still about 110 a check.
#[inline]
pub(crate) fn all_finite<const D: usize>(v: &SVector<f64, D>) -> bool {
    let mut acc = [0.0f64; 4];
    let chunks = v.as_slice().chunks_exact(4);
    let tail: f64 = chunks.remainder().iter().map(|x| x * 0.0).sum();
    for c in chunks {
        for (a, x) in acc.iter_mut().zip(c) {
            *a += x * 0.0;
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail == 0.0
}

/// Hairer's stiffness indicator h·ρ of an explicit step, with ρ = ‖f_b − f_a‖/‖y_b − y_a‖
/// over the first `m` components: two states of the step with the same time node and their
/// rates estimate the dominant eigenvalue's size [–].
pub(crate) fn stiffness_indicator<const D: usize>(
    h: f64,
    (y_a, f_a): (&SVector<f64, D>, &SVector<f64, D>),
    (y_b, f_b): (&SVector<f64, D>, &SVector<f64, D>),
    m: usize,
) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..m {
        num += (f_b[i] - f_a[i]).powi(2);
        den += (y_b[i] - y_a[i]).powi(2);
    }
    if den > 0.0 { h * (num / den).sqrt() } else { 0.0 }
}

/// Weighted RMS norm of `err` over the controlled (coupled) components.
pub(crate) fn error_norm<const D: usize>(
    err: &SVector<f64, D>,
    y0: &SVector<f64, D>,
    y1: &SVector<f64, D>,
    scale: &SVector<f64, D>,
    opts: &SolverOptions,
    coupled: usize,
) -> f64 {
    let mut sum = 0.0;
    for i in 0..coupled {
        let sc = opts.atol * scale[i] + opts.rtol * y0[i].abs().max(y1[i].abs());
        let r = err[i] / sc;
        sum += r * r;
    }
    (sum / coupled as f64).sqrt()
}

#[cfg(test)]
mod tests;

/// An unbounded (infinite) value written as null and read back from null, so settings
/// survive a round trip through JSON.
mod unbounded_as_null {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        if v.is_finite() { s.serialize_some(v) } else { s.serialize_none() }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::INFINITY))
    }
}
