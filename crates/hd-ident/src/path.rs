//! Driving a law's internal state along a prescribed signal with hd-model's integrator:
//! the LuGre bristle state along a speed v(t), the fading memory along a deflection θ(t).
//! The signal is either sampled (measured data, linear between samples) or analytic
//! (synthetic excitations); both integrate with [`hd_model::solver::solve`] and report the
//! state exactly at the sample times (every sample time is a solver breakpoint).

use hd_model::SolverError;
use hd_model::laws::friction::{FrictionLaw, LuGre};
use hd_model::laws::stiffness::{Hysteretic, StiffnessLaw};
use hd_model::solver::{OdeSystem, SolverOptions, solve};
use nalgebra::{SMatrix, SVector};

/// A prescribed signal x(t) with its first two time derivatives.
pub trait Signal: Sync {
    /// `[x, ẋ, ẍ]` at time t [s].
    fn at(&self, t: f64) -> [f64; 3];
}

/// Samples joined by straight lines (held constant outside the sampled interval).
pub struct Sampled<'a> {
    t: &'a [f64],
    x: &'a [f64],
}

impl<'a> Sampled<'a> {
    /// Wrap sample times (strictly increasing, at least two) and values.
    pub fn new(t: &'a [f64], x: &'a [f64]) -> Self {
        Self { t, x }
    }
}

impl Signal for Sampled<'_> {
    fn at(&self, t: f64) -> [f64; 3] {
        let (x, slope) = hd_model::interp::linear_at(self.t, self.x, t);
        [x, slope, 0.0]
    }
}

/// The LuGre bristle state w = σ0·s [N·m] driven by the sliding speed v(t).
pub struct BristleAlong<'a, S: Signal> {
    /// The friction law.
    pub law: LuGre,
    /// Sliding speed v(t) [rad/s].
    pub speed: &'a S,
}

impl<S: Signal> OdeSystem<1> for BristleAlong<'_, S> {
    fn rhs(&self, t: f64, y: &SVector<f64, 1>) -> SVector<f64, 1> {
        let [v, _, _] = self.speed.at(t);
        SVector::from([self.law.eval(v, y[0]).w_rate])
    }
    fn jacobian(&self, t: f64, y: &SVector<f64, 1>) -> (SMatrix<f64, 1, 1>, SVector<f64, 1>) {
        let [v, dv, _] = self.speed.at(t);
        let e = self.law.eval(v, y[0]);
        (SMatrix::from([[e.w_rate_d_w]]), SVector::from([e.w_rate_d_v * dv]))
    }
    fn abs_scale(&self) -> SVector<f64, 1> {
        SVector::from([self.law.max_level()])
    }
}

/// The fading-memory state z [N·m] of a hysteretic law driven by the deflection θ(t).
pub struct MemoryAlong<'a, S: Signal> {
    /// The stiffness law.
    pub law: Hysteretic,
    /// Deflection θ(t) [rad].
    pub deflection: &'a S,
    /// Typical size of z [N·m], for the absolute tolerance.
    pub scale: f64,
}

impl<S: Signal> OdeSystem<1> for MemoryAlong<'_, S> {
    fn rhs(&self, t: f64, y: &SVector<f64, 1>) -> SVector<f64, 1> {
        let [th, dth, _] = self.deflection.at(t);
        SVector::from([self.law.eval(th, dth, y[0]).z_rate])
    }
    fn jacobian(&self, t: f64, y: &SVector<f64, 1>) -> (SMatrix<f64, 1, 1>, SVector<f64, 1>) {
        let [th, dth, ddth] = self.deflection.at(t);
        let e = self.law.eval(th, dth, y[0]);
        (SMatrix::from([[e.z_rate_d_z]]), SVector::from([e.z_rate_d_thetadot * ddth]))
    }
    fn abs_scale(&self) -> SVector<f64, 1> {
        SVector::from([self.scale])
    }
}

/// Integrate the one-state system `sys` from `y0` at `times[0]` and return its state at
/// every time in `times` (strictly increasing).
pub fn state_at_samples<S: OdeSystem<1>>(
    sys: &S,
    times: &[f64],
    y0: f64,
    opts: &SolverOptions,
) -> Result<Vec<f64>, SolverError> {
    let n = times.len();
    let mut out = Vec::with_capacity(n);
    out.push(y0);
    if n < 2 {
        return Ok(out);
    }
    let mut next = 1;
    let mut record = |s: &hd_model::solver::Step<1>| {
        if next < n && s.t1 == times[next] {
            out.push(s.y1[0]);
            next += 1;
        }
    };
    solve(sys, times[0], SVector::from([y0]), times[n - 1], &times[1..n - 1], opts, &mut record)?;
    debug_assert_eq!(out.len(), n);
    Ok(out)
}
