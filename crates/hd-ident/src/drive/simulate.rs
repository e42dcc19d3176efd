//! The closed loop re-run: the controller acting on the simulated position, the rigid drive
//! advanced exactly over each sample under the held command. Generic over the arithmetic, so
//! the same code gives plain runs (`f64`) and runs with forward sensitivities ([`Dual`]).
//!
//! [`run`] hands each sample's outputs to a callback as the loop advances and keeps only
//! the few samples the controller still reads (its speed filter and its delay), so a fit
//! over a record of millions of samples holds no simulated column; [`simulate`] collects
//! them for reports and plots.
//!
//! [`Dual`]: super::dual::Dual

use super::controller::Controller;
use super::dual::Scalar;
use super::model::{Drive, FrictionLaw, Motion};
use super::record::Experiment;
use std::collections::VecDeque;

/// Simulated outputs at the record's samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Simulated<T> {
    /// Command acting over each sample (after delay, disturbance and saturation)
    /// [command unit].
    pub command: Vec<T>,
    /// Position at each sample [m or rad].
    pub position: Vec<T>,
}

/// Run the loop of record `e` with drive parameters `p` (order of [`FrictionLaw::names`]),
/// from rest at the record's first position. Before the computation delay has filled, the
/// recorded command acts.
pub fn simulate<T: Scalar>(
    law: FrictionLaw,
    p: &[T],
    c: &Controller,
    e: &Experiment,
) -> Simulated<T> {
    let n = e.len();
    let mut out = Simulated { command: Vec::with_capacity(n), position: Vec::with_capacity(n) };
    run(law, p, c, e, |_, u, x| {
        out.command.push(u);
        out.position.push(x);
    });
    out
}

/// [`simulate`] without the columns: `each(k, command, position)` receives sample k's
/// command acting over the sample [command unit] and its position [m or rad], in order.
pub fn run<T: Scalar>(
    law: FrictionLaw,
    p: &[T],
    c: &Controller,
    e: &Experiment,
    mut each: impl FnMut(usize, T, T),
) {
    for (k, (u, x)) in Run::new(law, p, c, e).enumerate() {
        each(k, u, x);
    }
}

/// The loop of a record advanced one sample per [`Iterator::next`], which gives that
/// sample's (command acting over it [command unit], position [m or rad]). Working storage:
/// the controller's speed-filter window and delay line (a few samples), whatever the
/// record's length.
pub struct Run<'a, T> {
    drive: Drive<T>,
    c: &'a Controller,
    e: &'a Experiment,
    /// The next sample.
    k: usize,
    /// The motion at sample k.
    s: Motion<T>,
    /// The newest positions, up to q[k]: the law reads q[k − j] for j up to the filter's
    /// length (samples before the record's first repeat it, as the law's own indexing does).
    q: Vec<T>,
    /// Commands computed at k − delay … k − 1.
    computed: VecDeque<T>,
}

impl<'a, T: Scalar> Run<'a, T> {
    /// The loop of record `e` with drive parameters `p` (order of [`FrictionLaw::names`])
    /// under controller `c`, at rest at the record's first position.
    pub fn new(law: FrictionLaw, p: &[T], c: &'a Controller, e: &'a Experiment) -> Self {
        let s = Motion::rest(T::cst(e.position[0]));
        let mut q = Vec::with_capacity(c.speed_filter.len() + 2);
        q.push(s.x);
        Run {
            drive: law.drive(p),
            c,
            e,
            k: 0,
            s,
            q,
            computed: VecDeque::with_capacity(c.delay + 1),
        }
    }

    /// Closed loop: the controller on the simulated positions, delayed, clamped.
    fn closed(&mut self) -> (T, T) {
        let (c, e, k) = (self.c, self.e, self.k);
        let newest = self.q.len() - 1;
        self.computed.push_back(c.clamp(c.law(e.reference[k], &self.q, newest) + e.disturbance[k]));
        let u = match k >= c.delay {
            true => self.computed.pop_front().unwrap_or_else(|| T::cst(e.command[k])),
            false => T::cst(e.command[k]),
        };
        let x = self.s.x;
        if k + 1 < e.len() {
            self.s = self.drive.step(self.s, self.drive.gain() * u, e.h);
            if self.q.len() == c.speed_filter.len() + 1 {
                self.q.remove(0);
            }
            self.q.push(self.s.x);
        }
        (u, x)
    }

    /// An open-loop record by multiple shooting: the recorded command (plus any
    /// disturbance) drives the model, which restarts every `segment` samples at the
    /// measured position and its low-passed speed ([`Experiment::speed`]; at rest where
    /// that is empty), with the bristle unloaded. Each segment's first position is the
    /// record's own.
    fn open(&mut self, segment: usize) -> (T, T) {
        let (e, k) = (self.e, self.k);
        if k % segment.max(1) == 0 {
            self.s = Motion {
                v: T::cst(e.speed.get(k).copied().unwrap_or(0.0)),
                ..Motion::rest(T::cst(e.position[k]))
            };
        }
        let u = T::cst(e.command[k] + e.disturbance[k]);
        let x = self.s.x;
        self.s = self.drive.step(self.s, self.drive.gain() * u, e.h);
        (u, x)
    }
}

impl<T: Scalar> Iterator for Run<'_, T> {
    type Item = (T, T);

    fn next(&mut self) -> Option<(T, T)> {
        if self.k >= self.e.len() {
            return None;
        }
        let out = match self.c.open_loop {
            Some(segment) => self.open(segment),
            None => self.closed(),
        };
        self.k += 1;
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::tests::controller;

    /// The windowed loop gives, bit for bit, what the loop over whole columns gives (the
    /// controller indexing every earlier position), for delays 0–2 and a three-tap filter.
    #[test]
    fn windowed_loop_matches_whole_columns() {
        let n = 400;
        let h = 1e-3;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * h).collect();
        let r: Vec<f64> = t.iter().map(|t| 0.01 * (7.0 * t).sin()).collect();
        let u: Vec<f64> = t.iter().map(|t| (3.0 * t).cos()).collect();
        let e = Experiment::new("e", "test", t, vec![0.0; n], r, u, Vec::new()).unwrap();
        let law = FrictionLaw::CoulombViscous;
        let p = [2.0, 20.0, 5.0, 0.1, 35.0];
        for delay in 0..3 {
            let c = Controller { speed_filter: vec![0.25, 0.5, 0.25], ..controller(delay) };
            let s = simulate(law, &p, &c, &e);
            // The reference loop: every position kept, the law indexing them all.
            let drive = law.drive(&p[..]);
            let (mut q, mut computed, mut applied) = (Vec::new(), Vec::new(), Vec::new());
            let mut m = Motion::rest(e.position[0]);
            q.push(m.x);
            for k in 0..n {
                computed.push(c.clamp(c.law(e.reference[k], &q, k) + e.disturbance[k]));
                let u = if k >= c.delay { computed[k - c.delay] } else { e.command[k] };
                applied.push(u);
                if k + 1 < n {
                    m = drive.step(m, drive.gain() * u, e.h);
                    q.push(m.x);
                }
            }
            assert_eq!(s.command, applied, "delay {delay}");
            assert_eq!(s.position, q, "delay {delay}");
        }
    }
}
