//! The Levenberg–Marquardt normal equations of the joint fit at one point, column by
//! column.
//!
//! One pass runs the bristle torque along the record with its exact sensitivities
//! ([`LuGre::step_interval`], [`LuGre::slip_rate_grad`]) and stores, per free nonlinear
//! parameter, ∂w/∂p and ∂ṡ/∂p as columns (the symmetric law's Tc and Ts already summed
//! over both sides). Everything after it is column arithmetic that the compiler
//! vectorises: the projection onto σ1, σ2 and the offset, d_i = ∂w/∂p_i + σ1·∂ṡ/∂p_i, the
//! projection's correction J_i = d_i + A·(AᵀA)⁻¹(∂Aᵀ/∂p_i·r − Aᵀd_i) ([`crate::varpro`]),
//! and JᵀJ, Jᵀr as dot products. No n × p matrix is formed beyond the columns the
//! workspace keeps from trial to trial.

use super::fast::{Workspace, dot, factor};
use super::{JointProblem, NONLINEAR_ALL, kernel};
use crate::error::FitError;
use crate::lm::Normal;
use nalgebra::{DMatrix, DVector};

/// Samples per block of the column passes: a block of every column touched stays in the
/// L1 cache.
const BLOCK: usize = 512;

impl JointProblem<'_> {
    /// The bristle run at nonlinear values `v` with its sensitivities summed per free
    /// parameter into `ws.w`, `ws.slip`, `ws.dw`, `ws.ds`.
    fn grad_run(&self, v: &[f64; 6], ws: &mut Workspace) -> Result<(), FitError> {
        let law = self.law(v);
        let (t, omega, y) = (self.data.t(), self.data.omega(), self.data.torque());
        let (n, q) = (t.len(), self.nonlinear.len());
        // The sensitivity slot of each free parameter ([`kernel::Slots`]).
        let slots: Vec<usize> = self
            .nonlinear
            .iter()
            .map(|name| NONLINEAR_ALL.iter().position(|nm| nm == name).expect("a name"))
            .collect();
        let Workspace { w: ws_w, slip: ws_slip, dw: cols_w, ds: cols_s, .. } = ws;
        for buf in [&mut *ws_w, &mut *ws_slip] {
            buf.clear();
            buf.resize(n, 0.0);
        }
        for cols in [&mut *cols_w, &mut *cols_s] {
            cols.resize_with(q, Vec::new);
            for c in cols.iter_mut() {
                c.clear();
                c.resize(n, 0.0);
            }
        }
        let first = y[0] - self.first_bias;
        kernel::grad_run(&law, self.asymmetric, t, omega, first, |k0, len, out| {
            let span = k0..k0 + len;
            ws_w[span.clone()].copy_from_slice(&out.w[..len]);
            ws_slip[span.clone()].copy_from_slice(&out.slip[..len]);
            for (i, &s) in slots.iter().enumerate() {
                cols_w[i][span.clone()].copy_from_slice(&out.dw[s][..len]);
                cols_s[i][span.clone()].copy_from_slice(&out.ds[s][..len]);
            }
        });
        // Any non-finite value makes the sum NaN (∞·0 is NaN).
        let probe = ws_w.iter().chain(ws_slip.iter()).fold(0.0, |acc, x| acc + x * 0.0);
        if probe.is_nan() {
            return Err(FitError::Optimiser(format!(
                "non-finite bristle state with sigma0 = {:e}",
                law.sigma0
            )));
        }
        Ok(())
    }

    /// The cost ‖r‖² and the normal equations of the projected residual at x (logarithms
    /// of the free nonlinear parameters), in `ws`.
    pub(super) fn normal_at(&self, x: &[f64], ws: &mut Workspace) -> Result<Normal, FitError> {
        let v = self.values(x);
        self.grad_run(&v, ws)?;
        let solved = {
            let Workspace { w, slip, resid, .. } = &mut *ws;
            self.project_run(w, slip, resid)
        };
        let q = self.nonlinear.len();
        let Workspace { slip, resid, dw, ds, .. } = &mut *ws;
        let s1 =
            self.linear.iter().position(|(nm, _)| *nm == "sigma1").map_or(0.0, |j| solved.beta[j]);
        let active: Vec<&[f64]> =
            solved.active.iter().map(|&j| self.linear_column(j, slip)).collect();
        let slip_slot = solved.active.iter().position(|&j| self.linear[j].0 == "sigma1");
        let m = active.len();
        // ∂/∂ln p = p·∂/∂p.
        let scale: Vec<f64> = self
            .nonlinear
            .iter()
            .map(|name| v[NONLINEAR_ALL.iter().position(|nm| nm == name).expect("a name")])
            .collect();
        // d_i = ∂w/∂p_i + σ1·∂ṡ/∂p_i (in place), with Aᵀd_i and (∂ṡ/∂p_i)ᵀr, a block of
        // samples at a time so that the block's columns are read from the cache.
        let n = resid.len();
        let mut atd = [[0.0f64; 6]; 3];
        let mut dsr = [0.0f64; 6];
        for lo in (0..n).step_by(BLOCK) {
            let span = lo..(lo + BLOCK).min(n);
            let r = &resid[span.clone()];
            for i in 0..q {
                let (d, s) = (&mut dw[i][span.clone()], &ds[i][span.clone()]);
                dsr[i] += dot(s, r);
                d.iter_mut().zip(s).for_each(|(d, s)| *d += s1 * s);
                for (a, col) in active.iter().enumerate() {
                    atd[a][i] += dot(&col[span.clone()], d);
                }
            }
        }
        // The correction's coefficients: J_i = d_i + Σ_a coef[a][i]·A_a.
        let mut coef = [[0.0f64; 6]; 3];
        if m > 0 {
            let norms: Vec<f64> =
                active.iter().map(|c| dot(c, c).sqrt().max(f64::MIN_POSITIVE)).collect();
            let scaled =
                DMatrix::from_fn(m, m, |a, b| dot(active[a], active[b]) / (norms[a] * norms[b]));
            let all: Vec<usize> = (0..m).collect();
            let inv = factor(&scaled, &all).map(|c| c.inverse()).or_else(|| scaled.try_inverse());
            if let Some(inv) = inv {
                for i in 0..q {
                    let mut rhs = DVector::from_fn(m, |a, _| -atd[a][i] / norms[a]);
                    if let Some(slot) = slip_slot {
                        rhs[slot] += dsr[i] / norms[slot];
                    }
                    let u = &inv * rhs;
                    for a in 0..m {
                        coef[a][i] = u[a] / norms[a];
                    }
                }
            }
        }
        // J_i in place, then JᵀJ and Jᵀr, block by block.
        let mut jtj = DMatrix::zeros(q, q);
        let mut jtr = DVector::zeros(q);
        for lo in (0..n).step_by(BLOCK) {
            let span = lo..(lo + BLOCK).min(n);
            for i in 0..q {
                let col = &mut dw[i][span.clone()];
                for (a, c) in active.iter().enumerate() {
                    let k = coef[a][i];
                    col.iter_mut().zip(&c[span.clone()]).for_each(|(d, c)| *d += k * c);
                }
                col.iter_mut().for_each(|d| *d *= scale[i]);
            }
            let r = &resid[span.clone()];
            for a in 0..q {
                let ja = &dw[a][span.clone()];
                jtr[a] -= dot(ja, r); // J = ∂r/∂x = −∂model/∂x
                for b in 0..=a {
                    jtj[(a, b)] += dot(ja, &dw[b][span.clone()]);
                }
            }
        }
        for a in 0..q {
            for b in 0..a {
                jtj[(b, a)] = jtj[(a, b)];
            }
        }
        Ok(Normal { cost: dot(resid, resid), jtj, jtr })
    }
}
