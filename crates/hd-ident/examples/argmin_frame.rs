//! The identifier's Levenberg–Marquardt driven by argmin's `Executor`, one iteration per
//! `Solver::next_iter` (through the engine's pause and resume), beside the same minimiser
//! called directly, on the same problem and start: what argmin's frame costs.
//!
//! Run: `cargo run --release -p hd-ident --example argmin_frame [SAMPLES] [REPS]`.
//! The problem is a sum of two exponential decays fitted over the logarithms of its four
//! parameters, its normal equations formed from exact columns; with few samples an
//! evaluation is cheap, so the frame's own work is as visible as it can be.

use argmin::core::{
    Error, Executor, IterState, KV, Problem, Solver, State, TerminationReason, TerminationStatus,
};
use hd_ident::lm::{
    Formed, LeastSquares, LmOptions, LmOutcome, LmPaused, LmStep, Normal, minimise,
    minimise_paused, resume_until, silent,
};
use std::time::Instant;

type St = IterState<Vec<f64>, (), (), (), (), f64>;

/// The minimiser as an argmin solver: its state between iterations is the engine's pause.
struct Frame {
    opts: LmOptions,
    paused: Option<LmPaused>,
    done: Option<LmOutcome>,
}

impl<O: LeastSquares> Solver<O, St> for Frame {
    fn name(&self) -> &str {
        "hdw Levenberg–Marquardt"
    }

    fn init(&mut self, problem: &mut Problem<O>, state: St) -> Result<(St, Option<KV>), Error> {
        let x0 = state.get_param().cloned().unwrap_or_default();
        let p = problem.problem.as_ref().expect("a problem");
        match minimise_paused(p, &x0, &[], &self.opts, 0)? {
            LmStep::Paused(s) => {
                let c = s.cost();
                self.paused = Some(s);
                Ok((state.param(x0).cost(c), None))
            }
            LmStep::Done(out) => {
                let c = out.cost;
                self.done = Some(out);
                Ok((state.param(x0).cost(c), None))
            }
        }
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<O>,
        state: St,
    ) -> Result<(St, Option<KV>), Error> {
        let p = problem.problem.as_ref().expect("a problem");
        let Some(s) = self.paused.take() else { return Ok((state, None)) };
        let next = s.iterations() + 1;
        match resume_until(p, s, &[], &self.opts, Some(next))? {
            LmStep::Paused(s) => {
                let (x, c) = (s.x().to_vec(), s.cost());
                self.paused = Some(s);
                Ok((state.param(x).cost(c), None))
            }
            LmStep::Done(out) => {
                let (x, c) = (out.x.clone(), out.cost);
                self.done = Some(out);
                Ok((state.param(x).cost(c), None))
            }
        }
    }

    fn terminate(&mut self, _: &St) -> TerminationStatus {
        if self.done.is_some() {
            TerminationStatus::Terminated(TerminationReason::SolverConverged)
        } else {
            TerminationStatus::NotTerminated
        }
    }
}

fn main() -> Result<(), Error> {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().map_or(Ok(2000), |a| a.parse())?;
    let reps: usize = args.next().map_or(Ok(200), |a| a.parse())?;
    let t: Vec<f64> = (0..n).map(|k| 5.0 * k as f64 / n as f64).collect();
    let y: Vec<f64> = t.iter().map(|&t| 3.0 * (-0.7 * t).exp() + 0.5 * (-4.0 * t).exp()).collect();
    let model = |x: &[f64]| -> Result<Normal, hd_ident::FitError> {
        let (a, k, b, m) = (x[0].exp(), x[1].exp(), x[2].exp(), x[3].exp());
        let e1: Vec<f64> = t.iter().map(|&t| (-k * t).exp()).collect();
        let e2: Vec<f64> = t.iter().map(|&t| (-m * t).exp()).collect();
        let r: Vec<f64> = (0..n).map(|i| y[i] - a * e1[i] - b * e2[i]).collect();
        let cols = vec![
            (0..n).map(|i| a * e1[i]).collect(),
            (0..n).map(|i| -a * k * t[i] * e1[i]).collect(),
            (0..n).map(|i| b * e2[i]).collect(),
            (0..n).map(|i| -b * m * t[i] * e2[i]).collect(),
        ];
        Ok(Normal::from_model_columns(&cols, &r))
    };
    let x0 = vec![0.0, 0.5, -1.0, 1.0];
    let opts = LmOptions { max_iterations: 200, ..LmOptions::default() };
    let (mut direct, mut framed) = (f64::INFINITY, f64::INFINITY);
    let (mut a, mut b) = (None, None);
    for _ in 0..reps {
        let s = Instant::now();
        let out = minimise(&Formed(model), &x0, &[], &opts, &silent)?;
        direct = direct.min(s.elapsed().as_secs_f64());
        a = Some(out);
        let s = Instant::now();
        let frame = Frame { opts: opts.clone(), paused: None, done: None };
        let res = Executor::new(Formed(model), frame)
            .configure(|st| st.param(x0.clone()).max_iters(1000))
            .timer(false)
            .run()?;
        framed = framed.min(s.elapsed().as_secs_f64());
        b = res.solver.done;
    }
    let (a, b) = (a.expect("ran"), b.expect("ran to its end"));
    assert_eq!(a, b, "the framed run must end where the direct one does");
    println!(
        "{n} samples, {} iterations, {} evaluations; best of {reps}: direct {:.3} ms, through argmin {:.3} ms ({:+.1} %)",
        a.iterations,
        a.evaluations,
        1e3 * direct,
        1e3 * framed,
        100.0 * (framed / direct - 1.0)
    );
    Ok(())
}
