//! The joint fit's exact derivatives: the model's sensitivity to each free nonlinear
//! parameter from the bristle run's carried sensitivities, and the Jacobian of the
//! variable-projection residual built from them (no finite differences).
//!
//! For a nonlinear parameter p, `d = ∂(w + σ1·ṡ)/∂p` at fixed β, and the only linear
//! column that moves with p is ṡ's ([`crate::varpro`] assembles the rest).

use super::{JointProblem, NONLINEAR_ALL, Projected};
#[cfg(test)]
use crate::error::FitError;
#[cfg(test)]
use crate::varpro::{Moving, projected_jacobian};

impl JointProblem<'_> {
    /// Indices into the bristle run's gradient that parameter `name` moves (the
    /// symmetric law's Tc and Ts also set the negative-side levels).
    pub(super) fn grad_slots(&self, name: &str) -> Vec<usize> {
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
    /// the model's exact derivatives with respect to x, one column per parameter: the
    /// allocating reference for the fit's own evaluation ([`JointProblem::normal_at`]).
    #[cfg(test)]
    pub(super) fn residuals_and_jacobian(
        &self,
        x: &[f64],
    ) -> Result<(Vec<f64>, Vec<Vec<f64>>), FitError> {
        let v = self.values(x);
        let proj = self.project_with(&v, true)?;
        let r = &proj.residuals;
        // The linear columns that move freely here.
        let free: Vec<usize> = (0..self.linear.len())
            .filter(|&j| self.linear[j].1.is_none() && !proj.at_bound[j])
            .collect();
        let cols = &proj.pieces.columns;
        let active: Vec<&[f64]> = free.iter().map(|&j| cols[j].as_slice()).collect();
        let slip_slot = free.iter().position(|&j| self.linear[j].0 == "sigma1");
        let sens = self.nonlinear_columns(&proj);
        let params = sens
            .iter()
            .map(|(d, d_slip)| Moving {
                d: d.clone(),
                column: slip_slot.map(|s| (s, d_slip.as_slice())),
            })
            .collect();
        let mut jac = projected_jacobian(&active, r, params);
        // ∂/∂ln p = p·∂/∂p.
        for (col, name) in jac.iter_mut().zip(&self.nonlinear) {
            let k = NONLINEAR_ALL.iter().position(|nm| nm == name).expect("a nonlinear name");
            let p = v[k];
            col.iter_mut().for_each(|x| *x *= p);
        }
        Ok((proj.residuals, jac))
    }
}
