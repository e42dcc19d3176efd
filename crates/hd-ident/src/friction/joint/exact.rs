//! The joint fit's exact derivatives: the model's sensitivity to each free nonlinear
//! parameter from the bristle run's carried sensitivities, and the Jacobian of the
//! variable-projection residual built from them (no finite differences).
//!
//! With the free linear columns A (those not held at a bound), the residual is
//! `r = y − w − A·β̂` with `β̂ = (AᵀA)⁻¹Aᵀ(y − w − fixed terms)`. For a nonlinear parameter
//! p, let `d = ∂(w + σ1·ṡ)/∂p` at fixed β (the only column that moves with p is ṡ's).
//! Differentiating β̂ gives `∂β̂/∂p = (AᵀA)⁻¹(∂Aᵀ/∂p·r − Aᵀd)`, hence
//! `∂model/∂p = d + A·∂β̂/∂p`, exact for the active set of the bounds at that point.

use super::{JointProblem, NONLINEAR_ALL, Projected};
use crate::error::FitError;
use nalgebra::{DMatrix, DVector};

impl JointProblem<'_> {
    /// Indices into the bristle run's gradient that parameter `name` moves (the
    /// symmetric law's Tc and Ts also set the negative-side levels).
    fn grad_slots(&self, name: &str) -> Vec<usize> {
        let k = NONLINEAR_ALL.iter().position(|n| *n == name).expect("a nonlinear name");
        if !self.asymmetric && k < 2 { vec![k, k + 4] } else { vec![k] }
    }

    /// The value of the linear parameter `name` in `proj` (0 when not in the model).
    fn beta_of(&self, proj: &Projected, name: &str) -> f64 {
        self.linear.iter().position(|(n, _)| *n == name).map_or(0.0, |j| proj.beta[j])
    }

    /// For each free nonlinear parameter (in `self.nonlinear` order), the sensitivity of
    /// the model to it at fixed linear parameters, `∂(w + σ1·ṡ)/∂p` [N·m per unit of p],
    /// and `∂ṡ/∂p`. `proj` must come from [`JointProblem::project_with`] with `grad`.
    pub(super) fn nonlinear_columns(&self, proj: &Projected) -> Vec<(Vec<f64>, Vec<f64>)> {
        let run = &proj.pieces.run;
        let s1 = self.beta_of(proj, "sigma1");
        self.nonlinear
            .iter()
            .map(|name| {
                let slots = self.grad_slots(name);
                let d_slip: Vec<f64> =
                    run.d_slip.iter().map(|g| slots.iter().map(|&i| g[i]).sum()).collect();
                let d: Vec<f64> = run
                    .d_w
                    .iter()
                    .zip(&d_slip)
                    .map(|(g, ds)| slots.iter().map(|&i| g[i]).sum::<f64>() + s1 * ds)
                    .collect();
                (d, d_slip)
            })
            .collect()
    }

    /// The projected residuals at x (logarithms of the free nonlinear parameters) and
    /// the model's exact derivatives with respect to x, one column per parameter.
    pub(super) fn residuals_and_jacobian(
        &self,
        x: &[f64],
    ) -> Result<(Vec<f64>, Vec<Vec<f64>>), FitError> {
        let v = self.values(x);
        let proj = self.project_with(&v, true)?;
        let r = &proj.residuals;
        // The linear columns that move freely here, scaled to unit norm.
        let active: Vec<usize> = (0..self.linear.len())
            .filter(|&j| self.linear[j].1.is_none() && !proj.at_bound[j])
            .collect();
        let n = r.len();
        let cols = &proj.pieces.columns;
        let norms: Vec<f64> = active
            .iter()
            .map(|&j| cols[j].iter().map(|c| c * c).sum::<f64>().sqrt().max(f64::MIN_POSITIVE))
            .collect();
        let m = active.len();
        let gram = DMatrix::from_fn(m, m, |a, b| {
            let (ca, cb) = (&cols[active[a]], &cols[active[b]]);
            ca.iter().zip(cb).map(|(p, q)| p * q).sum::<f64>() / (norms[a] * norms[b])
        });
        let gram_inv = gram.clone().try_inverse();
        let slip_slot = active.iter().position(|&j| self.linear[j].0 == "sigma1");
        let mut jac = Vec::with_capacity(self.nonlinear.len());
        for ((d, d_slip), name) in self.nonlinear_columns(&proj).into_iter().zip(&self.nonlinear) {
            let k = NONLINEAR_ALL.iter().position(|nm| nm == name).expect("a nonlinear name");
            let mut col = d;
            if let (Some(inv), true) = (&gram_inv, m > 0) {
                // rhs = Âᵀ(∂A/∂p·β-free part)ᵀr − Âᵀd, with Â = A scaled.
                let mut rhs = DVector::from_fn(m, |a, _| {
                    -cols[active[a]].iter().zip(&col).map(|(c, x)| c * x).sum::<f64>() / norms[a]
                });
                if let Some(s) = slip_slot {
                    rhs[s] += d_slip.iter().zip(r).map(|(a, b)| a * b).sum::<f64>() / norms[s];
                }
                let coef = inv * rhs;
                for (a, &j) in active.iter().enumerate() {
                    let c = coef[a] / norms[a];
                    col.iter_mut().zip(&cols[j]).for_each(|(x, y)| *x += c * y);
                }
            }
            // ∂/∂ln p = p·∂/∂p.
            let p = v[k];
            col.iter_mut().for_each(|x| *x *= p);
            debug_assert_eq!(col.len(), n);
            jac.push(col);
        }
        Ok((proj.residuals, jac))
    }
}
