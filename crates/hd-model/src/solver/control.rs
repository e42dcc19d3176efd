//! The step-size controller's settings. They are fixed for every solve (not user options):
//! the values are the usual ones for these methods (Hairer & Wanner), and each range says
//! where the controller stays stable and sensible.

/// Safety factor on the optimal step [–]; range (0.7, 0.95): smaller means fewer
/// rejections and more steps.
pub const SAFETY: f64 = 0.9;

/// Largest growth of the step after an accepted step [–]; range 2–10.
pub const GROW_MAX: f64 = 6.0;

/// Largest shrink after an accepted step (the step may be cut to this fraction) [–];
/// range 0.1–0.5.
pub const SHRINK_ACCEPTED_MIN: f64 = 0.2;

/// Shrink limits after a rejected step [–]: the new step lies in `[min, max]` of the old;
/// min 0.05–0.2, max 0.5–0.9 (a rejection always shrinks the step).
pub const SHRINK_REJECTED: (f64, f64) = (0.1, 0.9);

/// Shrink after a step whose error could not be computed (singular matrix, overflow) [–].
pub const SHRINK_FAILED: f64 = 0.1;

/// Dopri5's PI controller: exponent on the current error (≈ 0.7/5) and on the previous one
/// (Hairer's β = 0.04, 0–0.08), which damps the step-size oscillation of an explicit
/// method held by stability.
pub const DOPRI5_PI: (f64, f64) = (0.17, 0.04);

/// Rodas4's controller: exponent 1/4 on the error (order 3 embedded, 4 main), no memory.
pub const RODAS4_EXPONENT: f64 = 0.25;

/// The IMEX pair's PI controller (order 3 embedded): 0.7/4 on the current error, 0.4/4
/// on the previous one.
pub const IMEX_PI: (f64, f64) = (0.175, 0.1);

/// The IMEX pair's exponent after a rejection: 1/(3 + 1), from its table.
pub const IMEX_EXPONENT: f64 = 1.0 / super::imex_tables::ARK436.order as f64;

/// The fifth-order IMEX pair's PI controller (order 4 embedded): 0.7/5 on the current
/// error, 0.4/5 on the previous one.
pub const IMEX5_PI: (f64, f64) = (0.14, 0.08);

/// The fifth-order IMEX pair's exponent after a rejection: 1/(4 + 1), from its table.
pub const IMEX5_EXPONENT: f64 = 1.0 / super::imex_tables::ARK548.order as f64;

/// DOP853's PI controller: 1/8 − 0.75·β on the current error and β = 0.04 on the
/// previous one. On the seed case its steps sit at the bristle's stability limit, where
/// Hairer's β = 0 rejected 2 542 of 12 429 attempts at rtol 1e-8; with β = 0.04, 1 063 of
/// 11 294, in less time (β = 0.08 doubled the steps).
pub const DOP853_PI: (f64, f64) = (0.095, 0.04);

/// DOP853's exponent after a rejection: 1/8.
pub const DOP853_EXPONENT: f64 = 0.125;

/// Dopri5's exponent after a rejection: 1/(order of the error estimate + 1) = 1/5.
pub const DOPRI5_REJECT_EXPONENT: f64 = 0.2;

/// Floor of the remembered error norm in the PI controller [–] (keeps a tiny error from
/// allowing an unbounded growth at the next step).
pub const ERROR_FLOOR: f64 = 1e-4;

/// A step that would stop within this fraction of a step before a segment end is
/// stretched to land on it instead of leaving a sliver [–]; range 1e-4–1e-2.
pub const SLIVER: f64 = 1e-3;

/// Smallest step relative to the time, in units of machine epsilon, before the solve
/// gives up with `StepSizeTooSmall` [–].
pub const MIN_STEP_EPS: f64 = 16.0;

/// A kink crossing closer than this fraction of the step to either end is left inside the
/// step instead of being landed on [–] (range 1e-4–1e-2): after a landing, the crossing
/// may sit a hair inside the next step, and where the switching function chatters about
/// zero (sticking) every crossing would otherwise cost a landing.
pub const LAND_SLIVER: f64 = 1e-3;

/// The same sliver for the two steps after a landing aimed from a rejected step (see the
/// driver's rejected-step branch) [–] (range 1e-6–1e-4): a secant can fall short of the
/// crossing by more than a hair, and a kink left 2e-4 of a step inside it costs the step its order
/// (measured on the kinked test system: error 1.9e-7 instead of 2.8e-11). Much smaller,
/// and a landing just short of a kink is followed by landings 1e-12 s long.
pub const AIMED_SLIVER: f64 = 1e-5;

/// A step that ends so close before a kink that the switching function's tangent reaches
/// zero within this fraction of the next step is followed by a landing on the crossing
/// [–] (range 1e-3–1e-1): the distance is one Newton step, exact to its square.
pub const HAIR: f64 = 1e-2;

/// A step aimed at a kink's crossing predicted by extrapolation is shortened by this
/// fraction of its length [–] (range 1e-5–1e-3), so that it ends a hair before the
/// crossing (finished by a hair landing) rather than a hair after it (a straddle, a
/// rejected step and a landing).
pub const PREDICT_SHORT: f64 = 1e-4;

/// A kink crossing closer than this fraction of the step to its end is left inside the
/// step [–]: the crossing is located to 1e-10 of the step, so a step shortened to it ends
/// there, and anything wider would leave a long step (DOP853's) visibly past the kink.
pub const LAND_END_SLIVER: f64 = 1e-9;

/// A method's step-size exponent (1/(q+1) for an error estimate of order q: the rejection
/// shrink and the order the first step is sized by) and its PI gains (α, β) [–].
pub fn gains(m: super::Method) -> (f64, (f64, f64)) {
    use super::Method;
    match m {
        Method::Rodas4 => (RODAS4_EXPONENT, (RODAS4_EXPONENT, 0.0)),
        Method::Imex => (IMEX_EXPONENT, IMEX_PI),
        Method::Imex5 => (IMEX5_EXPONENT, IMEX5_PI),
        Method::Dop853 => (DOP853_EXPONENT, DOP853_PI),
        Method::Dopri5 | Method::Auto => (DOPRI5_REJECT_EXPONENT, DOPRI5_PI),
    }
}
