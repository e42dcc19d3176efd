//! One step of the Dormand–Prince 5(4) pair (first-same-as-last).

use super::{OdeSystem, combine, combine_coupled, combine_coupled_from, stiffness_indicator};
use nalgebra::SVector;

const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
const A2: [f64; 1] = [1.0 / 5.0];
const A3: [f64; 2] = [3.0 / 40.0, 9.0 / 40.0];
const A4: [f64; 3] = [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0];
const A5: [f64; 4] = [19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0];
const A6: [f64; 5] =
    [9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0];
/// Fifth-order weights (also the last row of A).
const B: [f64; 6] =
    [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0];
/// Difference between fifth- and fourth-order weights (7 stages, the last is f(y_new)).
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Result of a trial step.
pub(crate) struct Trial<const D: usize> {
    pub y1: SVector<f64, D>,
    pub f1: SVector<f64, D>,
    pub err: SVector<f64, D>,
    /// Stiffness indicator h·ρ, with ρ = ‖f(y1) − f(y6)‖ / ‖y1 − y6‖ an estimate of the
    /// dominant eigenvalue's size (Hairer & Wanner's test: the explicit method is
    /// stability-bound when h·ρ stays near its stability boundary, about 3.3).
    pub stiffness: f64,
}

/// Stage rates, kept by the caller across steps so that a step does not clear 7·D values.
pub(crate) type Rates<const D: usize> = [SVector<f64, D>; 7];

/// Take a trial step of size h from (t, y) with f0 = f(t, y); uses 6 evaluations. Only
/// the first [`OdeSystem::live`] components are advanced; the rest are copied from y. `k`
/// is scratch space for the stage rates (its contents do not matter).
pub(crate) fn step<const D: usize, S: OdeSystem<D>>(
    sys: &S,
    t: f64,
    y: &SVector<f64, D>,
    f0: &SVector<f64, D>,
    h: f64,
    k: &mut Rates<D>,
) -> Trial<D> {
    let n = sys.live();
    // Stage states need only the coupled block: no rate reads a quadrature.
    k[0] = *f0;
    let stages: [&[f64]; 4] = [&A2, &A3, &A4, &A5];
    let mut yi = *y;
    for (i, a) in stages.into_iter().enumerate() {
        combine_coupled(sys, &mut yi, y, h, a, k);
        sys.rhs_into(t + C[i + 1] * h, &yi, &mut k[i + 1]);
    }
    let y6 = combine_coupled_from(sys, y, h, &A6, k);
    sys.rhs_into(t + C[5] * h, &y6, &mut k[5]);
    let y1 = combine(y, h, &B, k, n);
    sys.rhs_into(t + h, &y1, &mut k[6]);
    let err = combine_coupled_from(sys, &SVector::zeros(), h, &E, k);
    let stiffness = stiffness_indicator(h, (&y6, &k[5]), (&y1, &k[6]), sys.coupled());
    Trial { y1, f1: k[6], err, stiffness }
}
