//! One step of Rodas4 (Hairer & Wanner, "Solving ODEs II", §IV.7): six stages, order 4
//! with an embedded order-3 solution, stiffly accurate and L-stable.
//!
//! Stage form used here, with `W = I/(h·γ) − J` and `J = ∂f/∂y(t, y)`:
//! `W·k_i = f(t + α_i·h, y + Σ_j a_ij·k_j) + Σ_j (c_ij/h)·k_j + γ_i·h·∂f/∂t`,
//! `y_new = y + Σ_j m_j·k_j`; the error estimate is the last stage `k_6`.

use super::OdeSystem;
use super::lu::BlockLu;
use nalgebra::{SMatrix, SVector};

const GAMMA: f64 = 0.25;
const ALPHA: [f64; 6] = [0.0, 0.386, 0.21, 0.63, 1.0, 1.0];
const GAMMA_I: [f64; 6] = [0.25, -0.1043, 0.1035, -0.362e-1, 0.0, 0.0];
const A: [[f64; 5]; 6] = [
    [0.0; 5],
    [1.544, 0.0, 0.0, 0.0, 0.0],
    [0.9466785280815826, 0.2557011698983284, 0.0, 0.0, 0.0],
    [3.314825187068521, 2.896124015972201, 0.9986419139977817, 0.0, 0.0],
    [1.221224509226641, 6.019134481288629, 12.53708332932087, -0.687886036105895, 0.0],
    [1.221224509226641, 6.019134481288629, 12.53708332932087, -0.687886036105895, 1.0],
];
const CC: [[f64; 5]; 6] = [
    [0.0; 5],
    [-5.6688, 0.0, 0.0, 0.0, 0.0],
    [-2.430093356833875, -0.2063599157091915, 0.0, 0.0, 0.0],
    [-0.1073529058151375, -9.594562251023355, -20.47028614809616, 0.0, 0.0],
    [7.496443313967647, -10.24680431464352, -33.99990352819905, 11.7089089320616, 0.0],
    [
        8.083246795921522,
        -7.981132988064893,
        -31.52159432874371,
        16.31930543123136,
        -6.058818238834054,
    ],
];

/// Result of a trial step.
pub(crate) struct Trial<const D: usize> {
    pub y1: SVector<f64, D>,
    pub err: SVector<f64, D>,
}

/// Why a trial step could not be formed.
pub(crate) struct Singular;

/// Take a trial step of size h from (t, y) with f0 = f(t, y), Jacobian `jac` and time
/// derivative `dfdt`; uses 5 evaluations and one LU factorisation.
pub(crate) fn step<const D: usize, S: OdeSystem<D>>(
    sys: &S,
    t: f64,
    y: &SVector<f64, D>,
    f0: &SVector<f64, D>,
    jac: &SMatrix<f64, D, D>,
    dfdt: &SVector<f64, D>,
    h: f64,
) -> Result<Trial<D>, Singular> {
    let mut w = -jac;
    let d = 1.0 / (h * GAMMA);
    for i in 0..D {
        w[(i, i)] += d;
    }
    let lu = BlockLu::new(w, sys.coupled()).ok_or(Singular)?;
    let mut k = [SVector::<f64, D>::zeros(); 6];
    for i in 0..6 {
        let f = if i == 0 {
            *f0
        } else {
            let mut yi = *y;
            for j in 0..i {
                yi += A[i][j] * k[j];
            }
            sys.rhs(t + ALPHA[i] * h, &yi)
        };
        let mut rhs = f + (GAMMA_I[i] * h) * dfdt;
        for j in 0..i {
            rhs += (CC[i][j] / h) * k[j];
        }
        k[i] = lu.solve(&rhs);
    }
    let mut y1 = *y;
    for j in 0..5 {
        y1 += A[5][j] * k[j];
    }
    y1 += k[5];
    Ok(Trial { y1, err: k[5] })
}
