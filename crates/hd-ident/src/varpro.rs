//! The exact Jacobian of a variable-projection residual.
//!
//! With the free linear columns A (those not held at a bound) and the residual
//! `r = y − fixed part − A·β̂`, `β̂ = (AᵀA)⁻¹Aᵀ(y − fixed part)`, a nonlinear parameter p
//! moves the fixed part and at most one column of A. With `d = ∂model/∂p` at fixed β,
//! differentiating β̂ gives `∂β̂/∂p = (AᵀA)⁻¹(∂Aᵀ/∂p·r − Aᵀd)`, hence
//! `∂model/∂p = d + A·∂β̂/∂p`: exact for the active set of the bounds at that point (the
//! full Golub–Pereyra derivative, not Kaufman's approximation). The Gram matrix is formed
//! from columns scaled to unit norm.

use nalgebra::{DMatrix, DVector};

/// One nonlinear parameter's pieces: `d` = ∂model/∂p at fixed linear parameters, and, when
/// p moves one of the active columns, that column's index in `active` and its derivative.
pub struct Moving<'a> {
    /// ∂model/∂p at fixed β [model unit per unit of p].
    pub d: Vec<f64>,
    /// The active column p moves, as (index into `active`, ∂column/∂p).
    pub column: Option<(usize, &'a [f64])>,
}

/// ∂model/∂p of the projected model for each parameter in `params`, given the active
/// linear columns and the residual r at the point.
pub fn projected_jacobian(active: &[&[f64]], r: &[f64], params: Vec<Moving>) -> Vec<Vec<f64>> {
    let m = active.len();
    let norms: Vec<f64> = active
        .iter()
        .map(|c| c.iter().map(|v| v * v).sum::<f64>().sqrt().max(f64::MIN_POSITIVE))
        .collect();
    let gram = DMatrix::from_fn(m, m, |a, b| {
        active[a].iter().zip(active[b]).map(|(p, q)| p * q).sum::<f64>() / (norms[a] * norms[b])
    });
    let inv = if m > 0 { gram.try_inverse() } else { None };
    params
        .into_iter()
        .map(|Moving { d, column }| {
            let mut col = d;
            if let Some(inv) = &inv {
                let mut rhs = DVector::from_fn(m, |a, _| {
                    -active[a].iter().zip(&col).map(|(c, x)| c * x).sum::<f64>() / norms[a]
                });
                if let Some((slot, dc)) = column {
                    rhs[slot] += dc.iter().zip(r).map(|(a, b)| a * b).sum::<f64>() / norms[slot];
                }
                let coef = inv * rhs;
                for (a, c) in active.iter().enumerate() {
                    let k = coef[a] / norms[a];
                    col.iter_mut().zip(c.iter()).for_each(|(x, y)| *x += k * y);
                }
            }
            col
        })
        .collect()
}
