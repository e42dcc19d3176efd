//! The discrete position controller of a logged closed loop, and how well it reproduces the
//! logged command.
//!
//! Law (cascaded P position loop around a P speed loop, as the EMPS description writes it):
//! `u_k = kp·kv·(r_k − q_k) − kv·v̂_k`, with the speed estimated from the sampled position by
//! a FIR filter and a backward difference, `v̂_k = (q^f_k − q^f_{k−1})/h`,
//! `q^f_k = Σ_j c_j·q_{k−j}`; the output is clamped to ±`saturation`. With a computation
//! delay of d samples, the command acting over sample k is the one computed at k − d.
//! A PD law `u = P·e − D·v̂` is the same with kv = D, kp = P/D ([`Controller::pd`]).

use super::dual::Scalar;

/// A sampled cascade P–P (equivalently PD) position controller.
#[derive(Clone, Debug, PartialEq)]
pub struct Controller {
    /// Position-loop gain [1/s].
    pub kp: f64,
    /// Speed-loop gain [command unit per (m/s) or per (rad/s)].
    pub kv: f64,
    /// Output limit, symmetric [command unit]; infinite for none.
    pub saturation: f64,
    /// Computation delay [samples].
    pub delay: usize,
    /// FIR coefficients of the position filter before the speed difference (sum 1).
    pub speed_filter: Vec<f64>,
    /// Sample period [s].
    pub h: f64,
    /// An open-loop record: no controller acts, the recorded command drives the model, and
    /// the simulation restarts from the record (position and filtered speed) every this
    /// many samples (multiple shooting). None in closed loop.
    pub open_loop: Option<usize>,
}

impl Controller {
    /// A PD law `u = P·e − D·v̂` written as the cascade (kv = D, kp = P/D).
    pub fn pd(p: f64, d: f64, h: f64) -> Controller {
        Controller {
            kp: p / d,
            kv: d,
            saturation: f64::INFINITY,
            delay: 0,
            speed_filter: vec![1.0],
            h,
            open_loop: None,
        }
    }

    /// No controller: the recorded command drives the model, restarted from the record every
    /// `segment` samples.
    pub fn open(segment: usize, h: f64) -> Controller {
        Controller { open_loop: Some(segment), ..Controller::pd(0.0, 1.0, h) }
    }

    /// The law's output at sample k from the reference `r` and the positions `q` up to k
    /// (`q[k]` is the newest; earlier samples before the record's start repeat `q[0]`),
    /// before saturation.
    pub fn law<T: Scalar>(&self, r: f64, q: &[T], k: usize) -> T {
        let at = |j: usize| q[k.saturating_sub(j)];
        let filtered = |back: usize| {
            let mut acc = T::cst(0.0);
            for (j, &c) in self.speed_filter.iter().enumerate() {
                acc = acc + at(back + j) * c;
            }
            acc
        };
        let speed = (filtered(0) - filtered(1)) / self.h;
        (-at(0) + r) * (self.kp * self.kv) - speed * self.kv
    }

    /// Clamp to ±saturation (the derivative vanishes where it clamps).
    pub fn clamp<T: Scalar>(&self, u: T) -> T {
        if u.re() > self.saturation {
            T::cst(self.saturation)
        } else if u.re() < -self.saturation {
            T::cst(-self.saturation)
        } else {
            u
        }
    }
}

/// How well the controller, run on the recorded position and reference, reproduces the
/// recorded command, for one computation delay.
#[derive(Clone, Debug, PartialEq)]
pub struct Reproduction {
    /// The delay tried [samples].
    pub delay: usize,
    /// RMS of recorded − reproduced command [command unit].
    pub rms: f64,
    /// The same as a share of the recorded command's RMS [%].
    pub percent: f64,
}

/// Apply the controller (with each delay in `delays`) to the recorded position `q` and
/// reference `r`, adding `disturbance` to its output, and compare with the recorded command
/// `u`. Samples before the delay has filled are skipped.
pub fn reproduce(
    c: &Controller,
    q: &[f64],
    r: &[f64],
    disturbance: &[f64],
    u: &[f64],
    delays: &[usize],
) -> Vec<Reproduction> {
    let n = q.len();
    let rms_u = (u.iter().map(|x| x * x).sum::<f64>() / n.max(1) as f64).sqrt();
    delays
        .iter()
        .map(|&d| {
            let start = d + c.speed_filter.len();
            let (mut ss, mut count) = (0.0, 0usize);
            for k in start..n {
                let law = c.clamp(c.law(r[k - d], q, k - d) + disturbance[k - d]);
                ss += (u[k] - law).powi(2);
                count += 1;
            }
            let rms = (ss / count.max(1) as f64).sqrt();
            Reproduction { delay: d, rms, percent: 100.0 * rms / rms_u }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a ramp q = c·t the two-tap filter's speed estimate is exact, so the law is
    /// kp·kv·(r − q) − kv·c; a command built with delay 1 is reproduced exactly at delay 1
    /// and not at delay 0.
    #[test]
    fn law_and_delay_on_a_ramp() {
        let c = crate::drive::tests::controller(0);
        let h = c.h;
        let n = 200;
        let q: Vec<f64> = (0..n).map(|k| 0.02 * k as f64 * h).collect();
        let r: Vec<f64> =
            (0..n).map(|k| 0.02 * k as f64 * h + 1e-4 * (k as f64 * 0.1).sin()).collect();
        let k = 50;
        let expect = c.kp * c.kv * (r[k] - q[k]) - c.kv * 0.02;
        assert!((c.law(r[k], &q, k) - expect).abs() < 1e-9);
        let zero = vec![0.0; n];
        let u: Vec<f64> = (0..n)
            .map(|k| if k == 0 { 0.0 } else { c.clamp(c.law(r[k - 1], &q, k - 1)) })
            .collect();
        let rep = reproduce(&c, &q, &r, &zero, &u, &[0, 1]);
        assert!(rep[1].rms < 1e-12, "{rep:?}");
        assert!(rep[0].rms > 1e-3, "{rep:?}");
    }
}
