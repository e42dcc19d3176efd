//! One step of an additive (implicit–explicit) Runge–Kutta pair that integrates one stiff
//! component implicitly and everything else explicitly: ARK4(3)6L[2]SA of Kennedy &
//! Carpenter (Appl. Numer. Math. 44, 2003), order 4 with an embedded order 3, its
//! implicit part an L-stable ESDIRK with γ = 1/4. The coefficients are the published ones
//! (as tabulated in the SUNDIALS ARKode documentation).
//!
//! The split is the system's [`OdeSystem::stiff_split`]: component k's rate is
//! `f_k = g(t, y) + d(t, y)·y_k` with g and d independent of y_k (the LuGre bristle:
//! `ẇ = σ0·v − (σ0·|v|/G)·w`). The whole of f_k is the implicit part, the other
//! components' rates the explicit part: the forcing g = σ0·v grows with σ0 just as the
//! relaxation rate d does, and an explicit forcing against an implicit relaxation loses
//! both accuracy and stability (measured: 665 646 steps at σ0 = 1e8, against 960 with
//! the whole rate implicit). Each stage needs no Newton iteration and no matrix: the
//! explicit part fixes every other component, g and d follow from them, and
//! `Y_k = (base + h·γ·g)/(1 − h·γ·d)` is exact. The bristle relaxation rate, which bounds
//! an explicit step to about 3.3/7.6e4 s on the seed case, no longer limits the step.

use super::{OdeSystem, combine, combine_into};
use nalgebra::SVector;

const GAMMA: f64 = 0.25;
const C: [f64; 6] = [0.0, 0.5, 83.0 / 250.0, 31.0 / 50.0, 17.0 / 20.0, 1.0];
/// Explicit coefficients a_ij (j < i).
const AE: [[f64; 5]; 6] = [
    [0.0; 5],
    [0.5, 0.0, 0.0, 0.0, 0.0],
    [13861.0 / 62500.0, 6889.0 / 62500.0, 0.0, 0.0, 0.0],
    [
        -116923316275.0 / 2393684061468.0,
        -2731218467317.0 / 15368042101831.0,
        9408046702089.0 / 11113171139209.0,
        0.0,
        0.0,
    ],
    [
        -451086348788.0 / 2902428689909.0,
        -2682348792572.0 / 7519795681897.0,
        12662868775082.0 / 11960479115383.0,
        3355817975965.0 / 11060851509271.0,
        0.0,
    ],
    [
        647845179188.0 / 3216320057751.0,
        73281519250.0 / 8382639484533.0,
        552539513391.0 / 3454668386233.0,
        3354512671639.0 / 8306763924573.0,
        4040.0 / 17871.0,
    ],
];
/// Implicit coefficients a_ij (j < i; the diagonal is γ, the first stage explicit).
const AI: [[f64; 5]; 6] = [
    [0.0; 5],
    [0.25, 0.0, 0.0, 0.0, 0.0],
    [8611.0 / 62500.0, -1743.0 / 31250.0, 0.0, 0.0, 0.0],
    [5012029.0 / 34652500.0, -654441.0 / 2922500.0, 174375.0 / 388108.0, 0.0, 0.0],
    [
        15267082809.0 / 155376265600.0,
        -71443401.0 / 120774400.0,
        730878875.0 / 902184768.0,
        2285395.0 / 8070912.0,
        0.0,
    ],
    [82889.0 / 524892.0, 0.0, 15625.0 / 83664.0, 69875.0 / 102672.0, -2260.0 / 8211.0],
];
/// Fourth-order weights, shared by both parts (the implicit part is stiffly accurate).
const B: [f64; 6] =
    [82889.0 / 524892.0, 0.0, 15625.0 / 83664.0, 69875.0 / 102672.0, -2260.0 / 8211.0, 0.25];
/// Third-order (embedded) weights.
const BHAT: [f64; 6] = [
    4586570599.0 / 29645900160.0,
    0.0,
    178811875.0 / 945068544.0,
    814220225.0 / 1159782912.0,
    -3700637.0 / 11593932.0,
    61727.0 / 225920.0,
];

/// Result of a trial step.
pub(crate) struct Trial<const D: usize> {
    pub y1: SVector<f64, D>,
    pub err: SVector<f64, D>,
    /// Right-hand-side and split evaluations used.
    pub evals: u64,
}

/// Stage rates, kept by the caller across steps so that a step does not clear 6·D values.
pub(crate) type Rates<const D: usize> = [SVector<f64, D>; 6];

/// Take a trial step of size h from (t, y) with f0 = f(t, y), treating component `k`'s
/// term `d0·y_k` (d0 at (t, y)) implicitly. Only the first [`OdeSystem::live`] components
/// are advanced; `f` is scratch space for the stage rates (its contents do not matter).
#[allow(clippy::too_many_arguments)]
pub(crate) fn step<const D: usize, S: OdeSystem<D>>(
    sys: &S,
    t: f64,
    y: &SVector<f64, D>,
    f0: &SVector<f64, D>,
    k: usize,
    d0: f64,
    h: f64,
    f: &mut Rates<D>,
) -> Trial<D> {
    let n = sys.live();
    f[0] = *f0;
    // Each stage rewrites the coupled block only (no rate reads a quadrature); the rest
    // stays y's.
    let mut yi = *y;
    for i in 1..6 {
        combine_into(&mut yi, y, h, &AE[i][..i], f, S::COUPLED);
        // Component k's whole rate is implicit (its forcing g grows with the relaxation
        // rate too, so it must not be explicit): base with AI, then the stage's own term.
        let mut base_k = y[k];
        for j in 0..i {
            base_k += h * AI[i][j] * f[j][k];
        }
        // g and d depend on the other components only: the system solves for y_k.
        yi[k] = base_k;
        sys.implicit_stage(t + C[i] * h, &mut yi, k, h * GAMMA, &mut f[i]);
    }
    let y1 = combine(y, h, &B, f, n);
    let diff: [f64; 6] = std::array::from_fn(|j| B[j] - BHAT[j]);
    // Error control reads the coupled components only (k is one of them; `COUPLED` is
    // a constant, so the loop keeps a fixed length).
    let mut err = combine(&SVector::zeros(), h, &diff, f, S::COUPLED);
    // Filter the stiff component's estimate through the stage's implicit factor (as
    // SDIRK, Radau and Rosenbrock codes do): the raw difference overstates its error by
    // about h·γ·|d| when the component relaxes fast.
    err[k] /= 1.0 - h * GAMMA * d0;
    Trial { y1, err, evals: 5 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The classical order conditions up to order 4 for each part, the coupling
    /// conditions of order 3 and 4 between them, order 3 for the embedding, and c = A·1.
    #[test]
    fn coefficients_satisfy_the_order_conditions() {
        let full = |a: &[[f64; 5]; 6], diag: f64| {
            let mut m = [[0.0; 6]; 6];
            for i in 0..6 {
                for j in 0..i {
                    m[i][j] = a[i][j];
                }
                if i > 0 {
                    m[i][i] = diag;
                }
            }
            m
        };
        let (e, im) = (full(&AE, 0.0), full(&AI, GAMMA));
        let mv = |m: &[[f64; 6]; 6], v: &[f64; 6]| {
            let mut r = [0.0; 6];
            for i in 0..6 {
                r[i] = (0..6).map(|j| m[i][j] * v[j]).sum();
            }
            r
        };
        let dot = |a: &[f64; 6], b: &[f64; 6]| (0..6).map(|i| a[i] * b[i]).sum::<f64>();
        let sq = |v: &[f64; 6]| std::array::from_fn::<f64, 6, _>(|i| v[i] * v[i]);
        let prod = |a: &[f64; 6], b: &[f64; 6]| std::array::from_fn::<f64, 6, _>(|i| a[i] * b[i]);
        let ones = [1.0; 6];
        for m in [&e, &im] {
            let rows = mv(m, &ones);
            for i in 0..6 {
                assert!((rows[i] - C[i]).abs() < 1e-12, "row {i}: {} vs {}", rows[i], C[i]);
            }
        }
        let close = |got: f64, want: f64| assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        close(dot(&B, &ones), 1.0);
        close(dot(&B, &C), 0.5);
        close(dot(&B, &sq(&C)), 1.0 / 3.0);
        close(dot(&B, &prod(&C, &sq(&C))), 0.25);
        close(dot(&BHAT, &ones), 1.0);
        close(dot(&BHAT, &C), 0.5);
        close(dot(&BHAT, &sq(&C)), 1.0 / 3.0);
        // Every combination of the two parts in the tree conditions of order 3 and 4.
        for a in [&e, &im] {
            close(dot(&B, &mv(a, &C)), 1.0 / 6.0);
            close(dot(&BHAT, &mv(a, &C)), 1.0 / 6.0);
            close(dot(&B, &prod(&C, &mv(a, &C))), 1.0 / 8.0);
            close(dot(&B, &mv(a, &sq(&C))), 1.0 / 12.0);
            for b in [&e, &im] {
                close(dot(&B, &mv(a, &mv(b, &C))), 1.0 / 24.0);
            }
        }
    }
}
