//! A bounded copy of a long trace for its plot: the samples are grouped into time buckets,
//! and each bucket keeps its first and last sample and those with the smallest and largest
//! load angle, so the plotted envelope of θz is exact while memory stays fixed.

use hd_model::Trace;
use hd_model::signals::Sample;

/// Buckets over the run (about the pixel width of a plot, times four).
pub const BUCKETS: usize = 4000;

/// Keeps the envelope of a stream of samples over `[0, t_end]`.
pub struct Envelope {
    t_end: f64,
    bucket: Option<usize>,
    picks: [Option<Sample>; 4], // first, lowest θz, highest θz, last
    out: Trace,
}

impl Envelope {
    /// An empty envelope for a run of `t_end` [s].
    pub fn new(t_end: f64) -> Self {
        Self { t_end, bucket: None, picks: [None; 4], out: Trace::default() }
    }

    /// Take one sample (in time order).
    pub fn push(&mut self, s: &Sample) {
        let b = ((s.t / self.t_end) * BUCKETS as f64).floor().clamp(0.0, BUCKETS as f64) as usize;
        if self.bucket != Some(b) {
            self.close();
            self.bucket = Some(b);
        }
        let [first, low, high, last] = &mut self.picks;
        first.get_or_insert(*s);
        if low.is_none_or(|l| s.theta_z < l.theta_z) {
            *low = Some(*s);
        }
        if high.is_none_or(|h| s.theta_z > h.theta_z) {
            *high = Some(*s);
        }
        *last = Some(*s);
    }

    /// Move the open bucket's picks, in time order and without repeats, to the output.
    fn close(&mut self) {
        let mut picks: Vec<Sample> = self.picks.iter().flatten().copied().collect();
        picks.sort_by(|a, b| a.t.total_cmp(&b.t));
        picks.dedup_by(|a, b| a.t == b.t);
        for p in &picks {
            self.out.push(p);
        }
        self.picks = [None; 4];
    }

    /// The kept samples.
    pub fn finish(mut self) -> Trace {
        self.close();
        self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_extremes_of_every_bucket_in_bounded_size() {
        let mut env = Envelope::new(10.0);
        let n = 1_000_000;
        let mut s = hd_model::signals::Sample {
            t: 0.0,
            u: 0.0,
            i: 0.0,
            theta_j: 0.0,
            omega_j: 0.0,
            theta_z: 0.0,
            omega_z: 0.0,
            theta: 0.0,
            z: 0.0,
            s: 0.0,
            tb: 0.0,
            tf: 0.0,
            k: 0.0,
            c0: 0.0,
            reference: 0.0,
            error: 0.0,
            u_ff: 0.0,
            tf_hat: 0.0,
            tb_hat: 0.0,
        };
        for k in 0..=n {
            s.t = 10.0 * k as f64 / n as f64;
            s.theta_z = (2.0 * std::f64::consts::PI * 50.0 * s.t).sin();
            env.push(&s);
        }
        let out = env.finish();
        assert!(out.len() <= 4 * (BUCKETS + 1), "{}", out.len());
        let max = out.theta_z.iter().copied().fold(f64::MIN, f64::max);
        let min = out.theta_z.iter().copied().fold(f64::MAX, f64::min);
        assert!(max > 0.9999 && min < -0.9999, "{min} {max}");
        assert!(out.t.windows(2).all(|w| w[0] < w[1]));
    }
}
