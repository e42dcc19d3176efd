//! Carrying the static stage's uncertainty into the dynamic stage. The dynamic estimates
//! β_d are conditional on the static estimates β_s; to first order they move by
//! `G·δβ_s` with `G = −(J_dᵀJ_d)⁻¹·J_dᵀ·J_s` (J_d, J_s the transient prediction's
//! sensitivities to β_d and β_s), so with independent data sets
//! `Cov(β_d) = Cov(β_d | β_s) + G·Cov(β_s)·Gᵀ` and `Cov(β_d, β_s) = G·Cov(β_s)`.

use super::transient::TransientProblem;
use crate::data::TransientData;
use crate::error::FitError;
use crate::separable::{Separable, SeparableFit};
use nalgebra::DMatrix;

/// The propagated covariance blocks.
pub(crate) struct Propagated {
    /// Cov(β_d), over `stage2.free` [registry units²].
    pub dynamic: DMatrix<f64>,
    /// Cov(β_d, β_s): rows `stage2.free`, columns `stage1.free`.
    pub cross: DMatrix<f64>,
}

fn block(fit: &SeparableFit) -> DMatrix<f64> {
    let p = fit.free.len();
    DMatrix::from_fn(p, p, |i, j| fit.covariance.entry(i, j).unwrap_or(0.0))
}

/// Propagate `stage1`'s covariance into `stage2` (fitted on `data` with static values
/// `statics` = Tc, Ts, ωs, σ2). `None` when either stage has no free parameter.
pub(crate) fn propagate(
    stage1: &SeparableFit,
    stage2: &SeparableFit,
    data: &TransientData,
    statics: [f64; 4],
) -> Result<Option<Propagated>, FitError> {
    let (ps, pd) = (stage1.free.len(), stage2.free.len());
    if ps == 0 || pd == 0 {
        return Ok(None);
    }
    let n = data.len();
    let sigma1 = stage2.value("sigma1").unwrap_or(0.0);
    let sigma0 = stage2.value("sigma0").unwrap_or(1.0);
    let order = ["Tc", "Ts", "ws", "sigma2"];
    let mut js = DMatrix::<f64>::zeros(n, ps);
    for (k, name) in stage1.free.iter().enumerate() {
        let idx = order.iter().position(|o| o == name).expect("a static parameter");
        let se = stage1.covariance.std_error[k].unwrap_or(0.0);
        let h = 1e-3 * statics[idx].abs().max(se).max(f64::MIN_POSITIVE);
        let predict = |delta: f64| {
            let mut s = statics;
            s[idx] += delta;
            TransientProblem::new(data, s[0], s[1], s[2], s[3]).predict(&[sigma1], sigma0)
        };
        let (up, down) = (predict(h)?, predict(-h)?);
        for i in 0..n {
            js[(i, k)] = (up[i] - down[i]) / (2.0 * h);
        }
    }
    // Column-scaled normal equations of the dynamic stage.
    let norms: Vec<f64> = stage2
        .jacobian
        .iter()
        .map(|c| c.iter().map(|v| v * v).sum::<f64>().sqrt().max(f64::MIN_POSITIVE))
        .collect();
    let jd = DMatrix::from_fn(n, pd, |i, j| stage2.jacobian[j][i] / norms[j]);
    let m = jd.transpose() * &jd;
    let Ok(m_inv) = m.pseudo_inverse(1e-12) else { return Ok(None) };
    let d_inv = DMatrix::from_fn(pd, pd, |i, j| if i == j { 1.0 / norms[i] } else { 0.0 });
    let g = -(d_inv * m_inv * jd.transpose() * js);
    let cov_s = block(stage1);
    let cross = &g * &cov_s;
    let dynamic = block(stage2) + &cross * g.transpose();
    Ok(Some(Propagated { dynamic, cross }))
}
