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
    step.t0 + illinois(at, (0.0, s0), (1.0, s1), |_| ROOT_TOL) * h
}

/// The root of `at` between `a` and `b > a`, where its values `fa` and `fb` have opposite
/// signs, by the Illinois variant of regula falsi: until the bracket is at most `width(b)`
/// wide for its current upper end b (or [`MAX_ITER`] evaluations), then its middle; an
/// exact zero is returned at once.
fn illinois(
    at: impl Fn(f64) -> f64,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    width: impl Fn(f64) -> f64,
) -> f64 {
    let mut side = 0i8;
    for _ in 0..MAX_ITER {
        if b - a <= width(b) {
            break;
        }
        let x = (a * fb - b * fa) / (fb - fa);
        let x = if x > a && x < b { x } else { 0.5 * (a + b) };
        let fx = at(x);
        if fx == 0.0 {
            return x;
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
    0.5 * (a + b)
}

/// Where the switching function will cross zero within `ahead` [s] after a step of size
/// `h` [s], extrapolated from the step: the cubic with values `s0`, `s1` and rates `ds0`,
/// `ds1` [unit/s] at the step's two ends. Returns the time after the step's end [s] of
/// the first crossing, if the cubic changes sign by `ahead`. A smooth switching function
/// near a crossing is extrapolated to O(h⁴): on the seed case the crossing of each
/// velocity reversal is placed to 4e-6 of the distance, where the tangent alone misses by
/// 3e-4.
pub(crate) fn predicted_crossing(
    h: f64,
    (s0, ds0): (f64, f64),
    (s1, ds1): (f64, f64),
    ahead: f64,
) -> Option<f64> {
    // Only a function moving towards zero (a NaN anywhere fails these tests too).
    let approaching = s1 * ds1 < 0.0;
    if !(h > 0.0 && ahead > 0.0 && approaching) {
        return None;
    }
    // The cubic in x = (t − t_start)/h, on [1, 1 + ahead/h].
    let at = |x: f64| {
        let [h00, h10, h01, h11] = crate::interp::hermite_basis(x);
        h00 * s0 + h10 * h * ds0 + h01 * s1 + h11 * h * ds1
    };
    let end = 1.0 + ahead / h;
    let f_end = at(end);
    if !f_end.is_finite() || !straddles(s1, f_end) {
        return None;
    }
    // As in [`crossing`], to a far finer width (the cubic is cheap).
    Some((illinois(at, (1.0, s1), (end, f_end), |b| 1e-14 * b) - 1.0) * h)
}

#[cfg(test)]
mod tests {
    use super::predicted_crossing;

    /// A cubic switching function is extrapolated exactly: s(t) = (t − 0.3)(t + 1)(2 − t)
    /// sampled at t = −0.2 and 0.1 crosses zero at t = 0.3 (0.2 after the step).
    #[test]
    fn a_cubic_switching_function_is_extrapolated_exactly() {
        let s = |t: f64| (t - 0.3) * (t + 1.0) * (2.0 - t);
        let ds = |t: f64| (t + 1.0) * (2.0 - t) + (t - 0.3) * (2.0 - t) - (t - 0.3) * (t + 1.0);
        let ahead = predicted_crossing(0.3, (s(-0.2), ds(-0.2)), (s(0.1), ds(0.1)), 0.5);
        let ahead = ahead.expect("a crossing within the horizon");
        assert!((ahead - 0.2).abs() < 1e-13, "{ahead}");
        // Beyond the horizon, moving away, or already at zero: none.
        assert_eq!(predicted_crossing(0.3, (s(-0.2), ds(-0.2)), (s(0.1), ds(0.1)), 0.1), None);
        assert_eq!(predicted_crossing(0.3, (s(0.6), ds(0.6)), (s(0.9), ds(0.9)), 0.5), None);
        assert_eq!(predicted_crossing(0.3, (-1.0, 3.0), (0.0, 3.0), 0.5), None);
    }
}
