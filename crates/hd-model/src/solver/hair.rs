//! The step that finishes a landing on a kink when the landing fell a hair short.
//!
//! An aimed landing can stop short of the crossing by about 1e-5 of its step (on the seed
//! case 2.3e-9 s before each of the 100 velocity reversals a second); the driver then
//! lands on the crossing with one more step of that width ([`super::control::HAIR`]).
//! Taking it with the running method costs a whole step's evaluations (eight with the
//! fifth-order pair) for a step over which the solution is a straight line to well below
//! the tolerance. This step is Heun's (the explicit trapezoidal rule) with the Euler
//! predictor's distance from it as the error estimate: two evaluations, the second at the
//! end point, which the next step wants anyway. Its error is tested like any step's;
//! where it fails the running method takes the step instead.

use super::{OdeSystem, SolverOptions, all_finite, error_norm};
use crate::fma::fmadd;
use nalgebra::SVector;

/// A Heun step and what the driver needs to accept it.
pub(crate) struct Trial<const D: usize> {
    pub y1: SVector<f64, D>,
    /// f(t + h, y1).
    pub f1: SVector<f64, D>,
    /// Local error estimate y1 − y* (Heun's result less Euler's) over the coupled
    /// components (zero elsewhere).
    pub err: SVector<f64, D>,
    /// The implicit–explicit split's relaxation rate d at the end point, when the step was
    /// given the split component.
    pub d1: Option<f64>,
}

/// Try a Heun step of size h from (t, y) with f0 = f(t, y) (see [`step`]): the trial
/// and its error norm when the error passes and the end point's rate is finite, `None`
/// otherwise. Kept out of line: the driver's loop runs it about once per kink.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
pub(crate) fn attempt<const D: usize, S: OdeSystem<D>>(
    sys: &S,
    t: f64,
    y: &SVector<f64, D>,
    f0: &SVector<f64, D>,
    h: f64,
    split: Option<usize>,
    scale: &SVector<f64, D>,
    opts: &SolverOptions,
) -> Option<(Trial<D>, f64)> {
    let trial = step(sys, t, y, f0, h, split);
    let e = error_norm(&trial.err, y, &trial.y1, scale, opts, sys.coupled());
    (e <= 1.0 && all_finite(&trial.f1)).then_some((trial, e))
}

/// One step of Heun's method (the explicit trapezoidal rule) of size h from (t, y) with
/// f0 = f(t, y): the Euler predictor y* = y + h·f0, then y1 = y + h/2·(f0 + f(y*)).
/// Its error estimate is y1 − y*, Euler's local error to leading order, so the step is
/// kept only where even Euler would meet the tolerance; the second order it carries on
/// top keeps the quadratures' sums (the energy balance) closing to rounding, as the
/// running method's steps do (Euler alone left a residual of 7e-12 of the input energy
/// over the seed case at rtol 1e-9, where the pairs leave 1e-14). With `split = Some(k)`
/// the end point's rate comes from [`OdeSystem::implicit_stage`] with no implicit
/// weight, so that the split's d there is known too (the implicit–explicit pairs start
/// their next step from it). Only the first [`OdeSystem::live`] components are advanced.
pub(crate) fn step<const D: usize, S: OdeSystem<D>>(
    sys: &S,
    t: f64,
    y: &SVector<f64, D>,
    f0: &SVector<f64, D>,
    h: f64,
    split: Option<usize>,
) -> Trial<D> {
    let n = sys.live();
    let t1 = t + h;
    let mut predictor = *y;
    for i in 0..n {
        predictor[i] = fmadd(h, f0[i], y[i]);
    }
    let mut f_pred = SVector::zeros();
    sys.rhs_into(t1, &predictor, &mut f_pred);
    let mut y1 = *y;
    for i in 0..n {
        y1[i] = fmadd(0.5 * h, f0[i] + f_pred[i], y[i]);
    }
    let mut f1 = SVector::zeros();
    let d1 = match split {
        Some(k) => Some(sys.implicit_stage(t1, &mut y1, k, 0.0, &mut f1)),
        None => {
            sys.rhs_into(t1, &y1, &mut f1);
            None
        }
    };
    let mut err = SVector::zeros();
    for i in 0..S::COUPLED {
        err[i] = y1[i] - predictor[i];
    }
    Trial { y1, f1, err, d1 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{SMatrix, Vector2};

    /// y' = λ·y, x' = sin t (the quadrature-free pair of a stiff-ish relaxation and a
    /// forced state), exact from (t, y0, x0): y0·e^{λh} and x0 + cos t − cos(t + h).
    struct Pair {
        lambda: f64,
    }

    impl OdeSystem<2> for Pair {
        fn rhs(&self, t: f64, y: &Vector2<f64>) -> Vector2<f64> {
            Vector2::new(self.lambda * y[0], t.sin())
        }
        fn jacobian(&self, t: f64, _y: &Vector2<f64>) -> (SMatrix<f64, 2, 2>, Vector2<f64>) {
            (SMatrix::<f64, 2, 2>::new(self.lambda, 0.0, 0.0, 0.0), Vector2::new(0.0, t.cos()))
        }
    }

    /// The step is Heun's, second order, and its estimate is Euler's local error to
    /// leading order: against the exact solution, y1's error falls as h³ and the
    /// estimate's distance from Euler's true error is of relative size O(h) (λh/3 for
    /// the relaxation). Measured at h = 1e-3 and 1e-5: estimate off by 8.3e-4 and 8.2e-6
    /// (relaxation), 1.4e-4 and 1.5e-6 (forced state); Heun's error relative to the
    /// step's change 1.0e-6 and 1.0e-10, and 8.3e-8 and 8.6e-12.
    #[test]
    fn heun_with_eulers_error_as_the_estimate() {
        let sys = Pair { lambda: -2.5 };
        let (t, y) = (0.7, Vector2::new(1.3, -0.4));
        let f0 = sys.rhs(t, &y);
        for (h, bound) in [(1e-3, 8e-3), (1e-5, 8e-5)] {
            let tr = step(&sys, t, &y, &f0, h, None);
            let euler = y + h * f0;
            let heun = y + 0.5 * h * (f0 + sys.rhs(t + h, &euler));
            assert_eq!(tr.y1, heun);
            assert_eq!(tr.f1, sys.rhs(t + h, &tr.y1));
            let exact = Vector2::new(y[0] * (sys.lambda * h).exp(), y[1] + t.cos() - (t + h).cos());
            for i in 0..2 {
                let euler_err = exact[i] - euler[i];
                let rel = ((tr.err[i] - euler_err) / euler_err).abs();
                assert!(rel < bound, "h = {h:e}, component {i}: estimate off by {rel:.2e}");
                // Heun's own error is third order: relative to the change, (λh)²/6.
                let heun_err = ((exact[i] - tr.y1[i]) / (exact[i] - y[i])).abs();
                assert!(heun_err < 10.0 * h * h, "h = {h:e}, component {i}: {heun_err:.2e}");
            }
        }
    }

    /// `attempt` keeps a step whose estimate meets the tolerance and refuses one that
    /// does not (err ∝ h², so a hundredfold step raises it ten-thousandfold).
    #[test]
    fn an_attempt_passes_or_fails_on_its_error_norm() {
        let sys = Pair { lambda: -2.5 };
        let (t, y) = (0.7, Vector2::new(1.3, -0.4));
        let f0 = sys.rhs(t, &y);
        let opts = SolverOptions { rtol: 1e-6, atol: 1e-9, ..Default::default() };
        let scale = Vector2::from_element(1.0);
        let (_, e) = attempt(&sys, t, &y, &f0, 1e-4, None, &scale, &opts).expect("passes");
        assert!(e > 0.0 && e < 1.0, "norm {e}");
        assert!(attempt(&sys, t, &y, &f0, 1e-2, None, &scale, &opts).is_none());
    }
}
