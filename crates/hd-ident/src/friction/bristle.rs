//! The LuGre bristle state along a measured speed, by the law's exact sample updates
//! ([`LuGre::step_interval`]), optionally with its exact sensitivities to the law's
//! parameters carried beside it: one pass over the record gives the model's pieces and
//! their full Jacobian (docs/model.md §5).

use crate::error::FitError;
use hd_model::laws::friction::LuGre;
use hd_model::laws::lugre_step::ShapeGrad;

/// The bristle torque w [N·m] and slip rate ṡ [rad/s] at every sample, with (when asked)
/// ∂w/∂p and ∂ṡ/∂p for p in [`hd_model::laws::lugre_step::SHAPE_PARAMS`] order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BristleRun {
    /// Bristle torque w = σ0·s [N·m].
    pub w: Vec<f64>,
    /// Slip rate ṡ = v − |v|·w/G(v) [rad/s].
    pub slip: Vec<f64>,
    /// ∂w/∂p per sample (empty unless asked).
    pub d_w: Vec<ShapeGrad>,
    /// ∂ṡ/∂p per sample (empty unless asked).
    pub d_slip: Vec<ShapeGrad>,
}

/// The starting bristle torque [N·m] and its derivatives: the first measured torque
/// `first_torque` held inside the bristles' range at the first speed (a record rarely
/// starts exactly at rest or in steady sliding: a speed derived from an encoder is never
/// exactly zero, and a start in steady state at a tiny negative speed would put w at −Ts
/// where the torque says 0).
pub(super) fn start(law: &LuGre, v0: f64, first_torque: f64) -> (f64, ShapeGrad) {
    let v0 = v0.abs();
    let hi = law.level_grad(v0);
    let lo = law.level_grad(-v0.max(f64::MIN_POSITIVE));
    if -lo.level > hi.level {
        return (0.0, [0.0; 6]);
    }
    if first_torque >= hi.level {
        (hi.level, hi.grad)
    } else if first_torque <= -lo.level {
        (-lo.level, lo.grad.map(|g| -g))
    } else {
        (first_torque, [0.0; 6])
    }
}

/// Run the bristle state of `law` along the speed `omega` [rad/s] sampled at `t` [s],
/// from `first_torque` [N·m] (see [`start`]); with `grad`, carry the sensitivities too.
/// The law's load factors are ignored.
pub fn bristle_run(
    t: &[f64],
    omega: &[f64],
    law: &LuGre,
    first_torque: f64,
    grad: bool,
) -> Result<BristleRun, FitError> {
    let mut run = BristleRun::default();
    bristle_run_into(&mut run, t, omega, law, first_torque, grad)?;
    Ok(run)
}

/// [`bristle_run`] into `run`, whose vectors are cleared and refilled (their capacity is
/// kept, so a fit that runs the state many times allocates once).
pub fn bristle_run_into(
    run: &mut BristleRun,
    t: &[f64],
    omega: &[f64],
    law: &LuGre,
    first_torque: f64,
    grad: bool,
) -> Result<(), FitError> {
    let n = t.len();
    run.w.clear();
    run.slip.clear();
    run.d_w.clear();
    run.d_slip.clear();
    if n == 0 {
        return Ok(());
    }
    let (mut w, mut dw) = start(law, omega[0], first_torque);
    for k in 0..n {
        if k > 0 {
            let h = t[k] - t[k - 1];
            if grad {
                let step = law.step_interval(omega[k - 1], omega[k], w, h);
                for (d, g) in dw.iter_mut().zip(step.grad) {
                    *d = step.d_w0 * *d + g;
                }
                w = step.w;
            } else {
                w = law.step_interval_state(omega[k - 1], omega[k], w, h);
            }
        }
        let v = omega[k];
        if grad {
            let (rate, d_rate_w, g) = law.slip_rate_grad(v, w);
            let mut ds = g;
            for (d, x) in ds.iter_mut().zip(dw) {
                *d += d_rate_w * x;
            }
            run.slip.push(rate);
            run.d_w.push(dw);
            run.d_slip.push(ds);
        } else {
            run.slip.push(v - v.abs() * w / law.stribeck(v).0);
        }
        run.w.push(w);
    }
    if run.w.iter().chain(&run.slip).any(|x| !x.is_finite()) {
        return Err(FitError::Optimiser(format!(
            "non-finite bristle state with sigma0 = {:e}",
            law.sigma0
        )));
    }
    Ok(())
}
