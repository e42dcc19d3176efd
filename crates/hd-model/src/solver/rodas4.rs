//! One step of Rodas4 (Hairer & Wanner, "Solving ODEs II", §IV.7): six stages, order 4
//! with an embedded order-3 solution, stiffly accurate and L-stable.
//!
//! Stage form used here, with `W = I/(h·γ) − J` and `J = ∂f/∂y(t, y)`:
//! `W·k_i = f(t + α_i·h, y + Σ_j a_ij·k_j) + Σ_j (c_ij/h)·k_j + γ_i·h·∂f/∂t`,
//! `y_new = y + Σ_j m_j·k_j`; the error estimate is the last stage `k_6`.

use super::lu::BlockLu;
use super::{OdeSystem, combine};
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
    let (m, n) = (sys.coupled(), sys.live());
    let lu = BlockLu::new(jac, 1.0 / (h * GAMMA), m, n).ok_or(Singular)?;
    let mut k = [SVector::<f64, D>::zeros(); 6];
    for i in 0..6 {
        let f = if i == 0 {
            *f0
        } else {
            sys.rhs(t + ALPHA[i] * h, &combine(y, 1.0, &A[i][..i], &k, n))
        };
        let mut rhs = f;
        let g = GAMMA_I[i] * h;
        for (r, dr) in rhs.as_mut_slice()[..n].iter_mut().zip(dfdt.as_slice()) {
            *r += g * dr;
        }
        for j in 0..i {
            let c = CC[i][j] / h;
            for (r, kv) in rhs.as_mut_slice()[..n].iter_mut().zip(k[j].as_slice()) {
                *r += c * kv;
            }
        }
        k[i] = lu.solve(jac, &rhs);
    }
    let y1 = combine(y, 1.0, &[A[5][0], A[5][1], A[5][2], A[5][3], A[5][4], 1.0], &k, n);
    Ok(Trial { y1, err: k[5] })
}
