//! The controller's share of the drive's Jacobian (docs/model.md §6.6).
//!
//! The plant's rows are analytic (`system.rs`). The controller enters them only through
//! the command u, and adds the rows of its own states; both are differentiated here by
//! differences of the controller's own functions — central in the states, forward in
//! time so that a step starting on a breakpoint of the reference sees the new segment.

use crate::control::CtlEval;
use crate::state::*;
use crate::system::{DriveSystem, ctl_states};
use nalgebra::SVector;

type G = SVector<f64, COUPLED>;

/// Gradients of the command and of the controller-state rates.
pub struct ControllerJacobian {
    /// ∂u/∂y over the coupled states [V per state unit].
    pub g_u: G,
    /// ∂u/∂t [V/s].
    pub du_dt: f64,
    /// ∂(rate)/∂y of the integrator, filter, observer and pre-filter states.
    pub rows: [G; 4],
    /// ∂(rate)/∂t of the same states.
    pub drates_dt: [f64; 4],
}

/// The states the controller reads.
const READ: [usize; 7] = [THETA_J, THETA, OMEGA_J, CTL_I, CTL_D, OBS_W, CMP_Q];

impl DriveSystem {
    fn ctl_eval(&self, t: f64, y: &State) -> CtlEval {
        let c = self.ctl.as_ref().expect("closed loop");
        c.eval(t, &self.measured(y), &ctl_states(y), &self.hold)
    }

    /// The controller's derivatives at (t, y); call only with a controller set.
    pub fn controller_jacobian(&self, t: f64, y: &State) -> ControllerJacobian {
        let mut out = ControllerJacobian {
            g_u: G::zeros(),
            du_dt: 0.0,
            rows: [G::zeros(); 4],
            drates_dt: [0.0; 4],
        };
        for &k in &READ {
            let h = 1e-7 * y[k].abs() + 1e-10;
            let (mut yp, mut ym) = (*y, *y);
            yp[k] += h;
            ym[k] -= h;
            let (ep, em) = (self.ctl_eval(t, &yp), self.ctl_eval(t, &ym));
            out.g_u[k] = (ep.u - em.u) / (2.0 * h);
            for r in 0..4 {
                out.rows[r][k] = (ep.rates[r] - em.rates[r]) / (2.0 * h);
            }
        }
        let dt = 1e-7 * t.abs().max(1e-3);
        let (e1, e0) = (self.ctl_eval(t + dt, y), self.ctl_eval(t, y));
        out.du_dt = (e1.u - e0.u) / dt;
        for r in 0..4 {
            out.drates_dt[r] = (e1.rates[r] - e0.rates[r]) / dt;
        }
        out
    }
}
