//! Where a step crosses a kink of the right-hand side: the root of the system's
//! switching function ([`super::OdeSystem::switch_value`]) along the step's interpolant
//! (the method's continuous extension, or the cubic Hermite one), found by the Illinois
//! variant of regula falsi.

use super::OdeSystem;
use super::driver::Step;

/// Relative width [–] of the step fraction to which a crossing is located.
const ROOT_TOL: f64 = 1e-10;
/// Iteration cap of the root search [–] (Illinois converges superlinearly; bisection
/// would need 34 halvings for [`ROOT_TOL`]).
const MAX_ITER: u32 = 60;

/// Whether a switching function changes sign from `s0` to `s1` (a zero at either end is
/// not a crossing: the step starts or ends on the kink).
#[inline]
pub(crate) fn straddles(s0: f64, s1: f64) -> bool {
    s0 != 0.0 && s1 != 0.0 && (s0 > 0.0) != (s1 > 0.0)
}

/// The time in `(step.t0, step.t1)` where the switching function, `s0` at the start and
/// `s1` at the end (of opposite signs), crosses zero along the interpolant [s].
pub(crate) fn crossing<const D: usize, S: OdeSystem<D>>(
    sys: &S,
    step: &Step<D>,
    s0: f64,
    s1: f64,
) -> f64 {
    let h = step.t1 - step.t0;
    let at = |x: f64| {
        let t = step.t0 + x * h;
        sys.switch_value(t, &step.interpolate(t)).unwrap_or(0.0)
    };
    let (mut a, mut fa, mut b, mut fb) = (0.0, s0, 1.0, s1);
    let mut side = 0i8;
    for _ in 0..MAX_ITER {
        if b - a <= ROOT_TOL {
            break;
        }
        let x = (a * fb - b * fa) / (fb - fa);
        let x = if x > a && x < b { x } else { 0.5 * (a + b) };
        let fx = at(x);
        if fx == 0.0 {
            return step.t0 + x * h;
        }
        if (fx > 0.0) == (fb > 0.0) {
            b = x;
            fb = fx;
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        } else {
            a = x;
            fa = fx;
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        }
    }
    step.t0 + 0.5 * (a + b) * h
}
