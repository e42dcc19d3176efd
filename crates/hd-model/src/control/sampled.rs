//! The sampled controller: at each sampling instant it reads quantised encoders,
//! updates its discrete states exactly for a zero-order-held input, and holds the new
//! command until the next instant (docs/model.md §6.5).

use super::Controller;
use super::law::Measured;
use crate::laws::friction::FrictionLaw;

/// What a sampled controller holds between two sampling instants.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Hold {
    /// Integrator at the next instant [rad·s].
    pub i: f64,
    /// Derivative-filter state at the next instant [rad].
    pub x: f64,
    /// Observer bristle torque at this instant [N·m].
    pub w_hat: f64,
    /// Quantised motor angle read at this instant [rad].
    pub enc_j: f64,
    /// Held command [V].
    pub u: f64,
    /// Held command before saturation [V].
    pub u_raw: f64,
    /// Held friction feedforward [V].
    pub u_ff: f64,
    /// Friction estimate at this instant [N·m].
    pub tf_hat: f64,
}

/// `x` rounded to a multiple of the resolution `res` (unchanged for `res = 0`) [rad]: an
/// encoder's reading. A rounded −0 reads 0.
pub fn quantise(x: f64, res: f64) -> f64 {
    if res > 0.0 { (x / res).round() * res + 0.0 } else { x }
}

impl Controller {
    /// The controller's update at a sampling instant t [s], with the true angles in `m`,
    /// pre-filter state q [N·m] and the previous hold `prev` (the first instant passes
    /// `Hold::default()`, the rest state). Returns the hold for the coming period.
    ///
    /// The motor speed is the backward difference of the quantised motor angle, i.e. the
    /// mean speed over the period just ended; the observer is advanced over that period
    /// at that speed with the friction law's exact constant-speed step. Integrator and
    /// derivative filter are advanced over the coming period exactly for the held error.
    pub fn sample(&self, t: f64, m: &Measured, q: f64, prev: &Hold, first: bool) -> Hold {
        let c = &self.cfg;
        let period = c.period;
        let theta_z = quantise(m.theta_z, c.enc_res);
        let theta_j = quantise(m.theta_j, c.enc_res);
        let v = if first { 0.0 } else { (theta_j - prev.enc_j) / (period * self.n) };
        let w_hat =
            if first { prev.w_hat } else { self.friction.step_at_speed(v, prev.w_hat, period) };
        let tf_hat = self.friction.eval(v, w_hat).torque;
        let (r_fb, _, _) = self.feedback_reference(t, q);
        let e = r_fb - self.feedback_angle(theta_z, theta_j);
        let u_ff = self.friction_feedforward(tf_hat);
        let u_raw = self.pid(u_ff, e, prev.i, prev.x);
        let u = self.saturate(u_raw);
        let decay = (-period / c.tau_d).exp();
        Hold {
            i: prev.i + period * self.integrator_rate(e, u, u_raw),
            x: e + (prev.x - e) * decay,
            w_hat,
            enc_j: theta_j,
            u,
            u_raw,
            u_ff,
            tf_hat,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::quantise;

    #[test]
    fn quantisation_rounds_to_the_resolution() {
        assert!((quantise(0.37, 0.1) - 0.4).abs() < 1e-15);
        assert!((quantise(-0.26, 0.1) + 0.3).abs() < 1e-15);
        assert_eq!(quantise(0.123, 0.0), 0.123);
    }
}
