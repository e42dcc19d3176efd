//! Automatic choice between the explicit and the stiff methods, decided by cost.
//!
//! The drive's LuGre bristles make the system mildly stiff at the seed's parameters and
//! very stiff when σ0 is large or ωs small. The policy: run Dopri5; when its stiffness
//! indicator h·ρ stays above 3.25 for 15 accepted steps, try the stiff candidates, each
//! for 30 counted attempts (60 for the pairs) after 10 that are not counted, and keep
//! the one whose time advanced per attempt (rejected steps count), divided by its cost
//! ratio to a Dopri5 step (plus a margin), is largest, if that beats Dopri5's recent step;
//! otherwise go back. The first candidate runs on the solution; the second pair runs in a
//! shadow from where the first one's stint ended, on a copy of the state that is then
//! dropped, so a losing candidate leaves no trace in the result. The candidates are the two
//! implicit–explicit pairs, fifth order first, when the system's split covers all of its
//! stiffness ([`super::OdeSystem::split_is_complete`]); Rodas4 when it does not
//! (inductance, a friction observer). Neither pair wins everywhere: on the seed case the
//! fifth-order one needs about a fifth fewer evaluations, but with a stiff gear
//! (c = 1e6, a torsional mode near 1 kHz) the fourth-order one needs a third fewer. The
//! pairs' steps cost about what Dopri5's do, so they are also tried, without waiting for a
//! stiff run, whenever Dopri5's indicator passes 2 and a recheck is due: on the seed case
//! at rtol 1e-6 that took 9 911 steps in 11.7 ms where waiting took 13 860 in 14.2 ms.
//! Either way, look again after a while, since stiffness changes along a run (it grows
//! with the sliding speed): after 5 000 steps on the kept method, run Dopri5 for 80
//! attempts and go back unless Dopri5 advanced further per attempt than the kept method
//! did over its whole stay (divided by its cost ratio). Waiting for Dopri5's stiffness
//! indicator instead left the seed case at rtol 1e-7 on Dopri5, which is held by accuracy
//! there, for the rest of the run: 99 283 evaluations where the pair alone takes 76 294
//! (now 76 966).
//!
//! Where Dopri5 is held by accuracy instead (its indicator below 1.5 for 50 steps) and the
//! tolerance is tight (rtol ≤ 1e-7), DOP853 is tried the same way: kept if it advances more
//! than 3.3× as far per attempt, left when its own indicator says it is held by stability,
//! and tried again after a wait that doubles each time it loses.
//!
//! Step costs on the full variant (measured, rejected steps included, 31-entry state):
//! Dopri5 0.70 µs, the implicit–explicit pair 0.68 µs (both were 0.9 and 1.1 µs before
//! the laws were inlined into the stages), Rodas4 2.55 µs.

use super::Method;

/// How much further per attempt Rodas4 must advance than Dopri5 to be kept [–]: the cost
/// ratio of their attempts (3.6 measured: 2.53 µs against 0.70 µs; 2.9 before Dopri5's
/// stages inlined the laws) with a margin of a fifth for Rodas4's rejections at velocity
/// reversals, which a 30-attempt trial in a sliding phase does not see (with no margin
/// the seed case at rtol 1e-5 kept Rodas4 and took 23 ms instead of 15 ms).
pub const COST_RATIO: f64 = 4.3;
/// How much further per attempt the implicit–explicit pair must advance than Dopri5 to be
/// kept [–]: the cost ratio of their attempts with a small margin. Measured 0.96 (0.67–0.69
/// µs against 0.70–0.72 µs on the full variant at c = 1e4…1e6) since the laws are
/// inlined into the pair's stage; it was 1.25 before, and the old ratio of 1.3 kept
/// Dopri5 at c = 1e6 where the pair is 14 % faster.
pub const IMEX_COST_RATIO: f64 = 1.05;
/// The same for the fifth-order pair [–]: its attempt (seven stages and the end point)
/// takes 1.14–1.18 of Dopri5's time (seed case, 1 s, rtol 1e-6 and 1e-5: 512–514 ns
/// against 434–450 ns, and 1.20–1.24 of the fourth-order pair's 412–427 ns), with the
/// same margin as the fourth-order pair's. Its instructions are 1.35 of Dopri5's, and
/// the ratio 1.4 set from them made `auto` keep the fourth-order pair on the seed case at
/// rtol 1e-5 and 2e-6, where the fifth-order one is 20–25 % faster.
pub const IMEX5_COST_RATIO: f64 = 1.25;
/// Dopri5's stiffness indicator h·ρ above which a step counts as held by stability [–];
/// Dopri5's stability boundary on the negative real axis is about 3.3 (range 3–3.3).
pub const STIFF_INDICATOR: f64 = 3.25;
/// Dopri5's stiffness indicator above which the implicit–explicit pair may be tried
/// without a stiff run [–] (range 1.5–3).
pub const NEAR_STIFF_INDICATOR: f64 = 2.0;
/// How much further per attempt DOP853 must advance than Dopri5 to be kept [–]: the cost
/// ratio of their attempts (2.5–3.1 measured: 12 stages and 3 for the dense output against
/// 6) with a margin.
pub const DOP853_COST_RATIO: f64 = 3.3;
/// Dopri5's stiffness indicator below which a step counts as held by accuracy, not
/// stability [–] (well inside the boundary of about 3.3).
pub const ACCURACY_INDICATOR: f64 = 1.5;
/// DOP853's stiffness indicator above which its step counts as held by stability [–]
/// (its boundary on the negative real axis is about 6).
pub const DOP853_STIFF_INDICATOR: f64 = 5.0;
/// Largest relative tolerance at which DOP853 is tried at all [–]. At the default 1e-6 its
/// trials on the `damped` variant (0.2 s) won and then cost 9 % more time than Dopri5
/// (2.09 against 1.92 ms, though 8× more accurate); from 1e-8 on they save 1.3–1.9×.
pub const HIGH_ORDER_RTOL: f64 = 1e-7;
/// Accepted Dopri5 steps in a row held by accuracy before DOP853 is tried [–].
const ACCURACY_RUN: u32 = 50;
/// Accepted steps after a DOP853 trial that kept Dopri5 before the next one; doubled after
/// each such trial, so a run where DOP853 does not pay spends little on trying it [–].
const FIRST_HIGH_ORDER_WAIT: u64 = 500;
/// Accepted steps in a row above [`STIFF_INDICATOR`] before Rodas4 is tried [–].
const STIFF_RUN: u32 = 15;
/// Attempts of a candidate in a trial before its mean step is compared [–].
const TRIAL_STEPS: u32 = 30;
/// The same when the two implicit–explicit pairs are compared [–]: their steps differ by
/// less than a landing on a velocity reversal (one every 60–100 steps on the seed case)
/// moves a short window's mean. Measured on the seed case (1 s) and Table 4's
/// `full-sine` (1 600 runs of 0.2 s), evaluations in all: 30 attempts, 57 035 and
/// 21.6 M at rtol 1e-6; 60, 50 914 and 21.2 M; 200, 53 041 and 22.0 M (longer trials
/// waste more on the losing pair in short runs). The fourth-order pair alone: 59 413 and
/// 21.6 M.
const PAIR_TRIAL_STEPS: u32 = 60;
/// How much more a candidate tried in shadow must score than the one on the solution to
/// replace it [–] (range 1–1.1). Ties go to the candidate on the solution: it is first
/// for being the more accurate one at equal tolerance, and the shadow's score starts from
/// a fresh controller where the solution's carries its memory (the same fourth-order
/// stint scored 1.764e-4 s per attempt in shadow and 1.689e-4 s on the solution, seed
/// case at rtol 1e-5, against the fifth-order pair's 1.644e-4 s after cost ratios).
const SHADOW_MARGIN: f64 = 1.05;
/// Attempts at the start of each candidate's trial that are not counted [–]: the step
/// size grows from the previous method's over a few steps (from Dopri5's, held by
/// stability, to the pair's), and counting them favoured whichever candidate came
/// second (on the seed case the fourth-order pair beat the fifth-order one, which needs
/// 36 % fewer attempts there).
const TRIAL_WARMUP: u32 = 10;
/// Dopri5 steps after a switch before the implicit–explicit pair may be tried without a
/// stiff run (enough for Dopri5's mean step to settle) [–].
const PROBE_AFTER: u32 = 20;
/// Accepted steps after a trial that kept Dopri5 before stiffness is looked at again [–].
const RECHECK_AFTER_DOPRI: u64 = 300;
/// Accepted stiff-method steps before Dopri5 is tried again (the stiffness may have
/// gone) [–].
const RECHECK_AFTER_STIFF: u64 = 5_000;

/// Dopri5 attempts after a recheck that are not counted, then the counted ones, before
/// Dopri5 is compared with the method it replaced [–]. About a third of the seed case's
/// 50 Hz period at rtol 1e-6: a longer window costs more where Dopri5 loses (evaluations
/// at rtol 1e-5 / 1e-6 / 1e-7 against no probe: 60 counted +0.9 / −0.2 / −22 %, 120
/// +1.8 / +0.7 / −22 %, 300 +3.8 / +2.1 / −22 %), and a short one that happens to favour
/// Dopri5 only hands the choice back to its stiffness test.
const PROBE_WARMUP: u32 = 20;
const PROBE_STEPS: u32 = 60;

/// The stiff methods tried when the split covers all of the system's stiffness.
pub const PAIRS: &[Method] = &[Method::Imex5, Method::Imex];
/// The stiff method tried otherwise.
pub const ROSENBROCK: &[Method] = &[Method::Rodas4];
const HIGH_ORDER: &[Method] = &[Method::Dop853];

/// A running comparison: each candidate tried for [`TRIAL_WARMUP`] and then
/// [`trial_steps`] attempts, the first on the solution and the others in shadow.
#[derive(Clone, Debug)]
struct Trial {
    candidates: &'static [Method],
    /// Attempts so far and the sum of accepted step sizes [s] of this candidate.
    attempts: u32,
    sum: f64,
    /// Dopri5's recent step [s]: the score to beat.
    h_dopri: f64,
    /// The best candidate so far and its score: step per attempt over cost ratio [s].
    best: Option<(Method, f64)>,
    /// Whether the candidates after the first still wait for their shadow runs.
    shadow_due: bool,
}

impl Trial {
    /// Keep `m` as the best candidate if its `score` [s] beats the best so far.
    fn offer(&mut self, m: Method, score: f64) {
        if self.best.is_none_or(|(_, b)| score > b) {
            self.best = Some((m, score));
        }
    }
}

/// A shadow run the driver owes a trial: the candidates after the first are run from
/// where the first one's stint ended, for `warmup` and then `counted` attempts, on a copy
/// of the state that is then dropped ([`Switcher::shadow_result`] takes their scores).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Shadow {
    pub methods: &'static [Method],
    pub warmup: u32,
    pub counted: u32,
}

/// Counted attempts of each candidate in a trial of `candidates`.
fn trial_steps(candidates: &[Method]) -> u32 {
    if candidates == PAIRS { PAIR_TRIAL_STEPS } else { TRIAL_STEPS }
}

/// How much further per attempt than Dopri5 a method must advance to be worth its steps.
fn cost_ratio(m: Method) -> f64 {
    match m {
        Method::Imex => IMEX_COST_RATIO,
        Method::Imex5 => IMEX5_COST_RATIO,
        Method::Dop853 => DOP853_COST_RATIO,
        _ => COST_RATIO,
    }
}

/// Dopri5 after a recheck: its run so far, against the method it replaced.
#[derive(Clone, Debug)]
struct Probe {
    /// The method kept before the recheck and its score over its whole stay: time
    /// advanced per attempt over its cost ratio [s].
    incumbent: Method,
    score: f64,
    /// Dopri5's attempts since the recheck and the time they advanced after the warm-up [s].
    attempts: u32,
    sum: f64,
}

/// The switching state of an `auto` solve.
#[derive(Clone, Debug)]
pub(crate) struct Switcher {
    /// Method for the next step.
    pub current: Method,
    /// The stiff methods a trial tries, in order; empty for a system that cannot be stiff.
    stiff: &'static [Method],
    stiff_run: u32,
    /// Dopri5 steps in a row held by accuracy.
    accuracy_run: u32,
    /// Accepted steps before DOP853 may be tried (again), and the wait after a failed try.
    high_next_check: u64,
    high_wait: u64,
    calm_run: u32,
    recent_h: f64,
    /// Dopri5 steps since the last switch.
    dopri_steps: u32,
    trial: Option<Trial>,
    /// The kept method's attempts and the time they advanced [s] since a trial kept it.
    stay: (u64, f64),
    probe: Option<Probe>,
    next_check: u64,
    /// Number of method changes.
    pub switches: u64,
}

impl Switcher {
    /// Start with the explicit method; `stiff` are the methods to try when it is held by
    /// stability ([`PAIRS`] or [`ROSENBROCK`]; none for a system that cannot be stiff);
    /// `rtol` decides whether DOP853 may be tried ([`HIGH_ORDER_RTOL`]).
    pub fn new(stiff: &'static [Method], rtol: f64) -> Self {
        Self {
            current: Method::Dopri5,
            stiff,
            stiff_run: 0,
            accuracy_run: 0,
            high_next_check: if rtol <= HIGH_ORDER_RTOL { 0 } else { u64::MAX },
            high_wait: FIRST_HIGH_ORDER_WAIT,
            calm_run: 0,
            recent_h: 0.0,
            dopri_steps: 0,
            trial: None,
            stay: (0, 0.0),
            probe: None,
            next_check: 0,
            switches: 0,
        }
    }

    /// Record an accepted step of size `h` (with Dopri5's stiffness indicator, if any);
    /// `steps` counts accepted steps so far. Returns the method for the next step.
    pub fn accepted(&mut self, h: f64, stiffness: Option<f64>, steps: u64) -> Method {
        let dop853_held = self.current == Method::Dop853
            && self.trial.is_none()
            && self.held_by_stability(stiffness);
        if self.current != Method::Dopri5 && self.trial.is_none() {
            self.stay.0 += 1;
            self.stay.1 += h;
        }
        match self.current {
            Method::Dopri5 => {
                self.recent_h =
                    if self.recent_h == 0.0 { h } else { 0.8 * self.recent_h + 0.2 * h };
                // Hairer's counting: 15 stiff-looking steps make a stiff run; it is only
                // broken by 6 calm steps in a row.
                if stiffness.is_some_and(|s| s > STIFF_INDICATOR) {
                    self.stiff_run += 1;
                    self.calm_run = 0;
                } else {
                    self.calm_run += 1;
                    if self.calm_run >= 6 {
                        self.stiff_run = 0;
                    }
                }
                self.dopri_steps += 1;
                if let Some(p) = self.probe.as_mut() {
                    // After a recheck: compare Dopri5's run with the replaced method's
                    // whole stay, both measured in the same terms (actual steps, long
                    // windows), before anything else is tried.
                    p.attempts += 1;
                    if p.attempts > PROBE_WARMUP {
                        p.sum += h;
                    }
                    if p.attempts < PROBE_WARMUP + PROBE_STEPS {
                        return self.current;
                    }
                    let (incumbent, score) = (p.incumbent, p.score);
                    let dopri = p.sum / f64::from(PROBE_STEPS);
                    self.probe = None;
                    if score > dopri {
                        self.keep(incumbent, steps);
                        return self.current;
                    }
                }
                // Rodas4's trials are dear, so they wait for a stiff run; the
                // implicit–explicit pair costs about what Dopri5 does, so it is also tried
                // when a recheck is due and Dopri5 is near its stability boundary (where
                // it is accuracy-bound, the higher-order Dopri5 wins).
                let cheap_trial = self.stiff == PAIRS
                    && self.dopri_steps >= PROBE_AFTER
                    && stiffness.is_some_and(|s| s > NEAR_STIFF_INDICATOR);
                // Held by accuracy for a while: the eighth-order pair may go further per
                // unit of work.
                if stiffness.is_some_and(|s| s < ACCURACY_INDICATOR) {
                    self.accuracy_run += 1;
                } else {
                    self.accuracy_run = 0;
                }
                if !self.stiff.is_empty()
                    && (self.stiff_run >= STIFF_RUN || cheap_trial)
                    && steps >= self.next_check
                {
                    self.start_trial(self.stiff);
                } else if self.accuracy_run >= ACCURACY_RUN && steps >= self.high_next_check {
                    self.start_trial(HIGH_ORDER);
                }
            }
            Method::Dop853 if dop853_held => {
                // Kept for accuracy, now held by stability (its boundary is about 6):
                // back to Dopri5, which knows what to try next.
                self.high_next_check = steps.saturating_add(self.high_wait);
                self.switch_to(Method::Dopri5);
            }
            _ => match self.trial.as_mut() {
                Some(trial) => {
                    trial.attempts += 1;
                    if trial.attempts > TRIAL_WARMUP {
                        trial.sum += h;
                    }
                    let counted = trial_steps(trial.candidates);
                    if trial.attempts >= TRIAL_WARMUP + counted {
                        // Time advanced per attempt over the attempt's cost: a rejected
                        // step costs as much as an accepted one.
                        let per_attempt = trial.sum / f64::from(counted);
                        trial.offer(self.current, per_attempt / cost_ratio(self.current));
                        if trial.candidates.len() > 1 {
                            // The others are tried in shadow from here (the driver runs
                            // them, then calls `finish_trial`).
                            trial.shadow_due = true;
                            return self.current;
                        }
                        self.finish_trial(steps);
                    }
                }
                None if steps >= self.next_check => {
                    // Committed to the method for a while: run the explicit one again
                    // (the stiffness may have gone), then compare.
                    let (n, advanced) = self.stay;
                    let score = advanced / n.max(1) as f64 / cost_ratio(self.current);
                    self.probe =
                        Some(Probe { incumbent: self.current, score, attempts: 0, sum: 0.0 });
                    self.next_check = 0;
                    self.switch_to(Method::Dopri5);
                }
                None => {}
            },
        }
        self.current
    }

    /// Record a rejected step: during a trial it counts as an attempt that advanced no
    /// time.
    pub fn rejected(&mut self) {
        if let Some(trial) = self.trial.as_mut() {
            trial.attempts += 1;
        } else if let Some(p) = self.probe.as_mut() {
            p.attempts += 1;
        } else if self.current != Method::Dopri5 {
            self.stay.0 += 1;
        }
    }

    /// Stay with `m` (kept by a trial or by a recheck) until the next recheck.
    fn keep(&mut self, m: Method, steps: u64) {
        self.next_check = steps + RECHECK_AFTER_STIFF;
        self.stay = (0, 0.0);
        if m != self.current {
            self.switch_to(m);
        }
    }

    /// Try `candidates` against Dopri5's recent step: the first one on the solution, then
    /// the others in shadow runs from where its trial ended ([`Switcher::take_shadow`]).
    fn start_trial(&mut self, candidates: &'static [Method]) {
        self.trial = Some(Trial {
            candidates,
            attempts: 0,
            sum: 0.0,
            h_dopri: self.recent_h,
            best: None,
            shadow_due: false,
        });
        self.switch_to(candidates[0]);
    }

    /// After the trial's last candidate: keep the best one if it beats Dopri5's recent
    /// step, otherwise go back to Dopri5. Returns the method for the next step.
    pub(crate) fn finish_trial(&mut self, steps: u64) -> Method {
        let Some(trial) = self.trial.take() else { return self.current };
        let (best, score) = trial.best.expect("a candidate was scored");
        if score > trial.h_dopri {
            self.keep(best, steps);
        } else {
            if trial.candidates == HIGH_ORDER {
                self.high_next_check = steps.saturating_add(self.high_wait);
                self.high_wait = self.high_wait.saturating_mul(2);
            } else {
                self.next_check = steps + RECHECK_AFTER_DOPRI;
            }
            self.switch_to(Method::Dopri5);
        }
        self.current
    }

    /// The shadow runs a trial owes once its first candidate's stint is over. The driver
    /// runs each of [`Shadow::methods`] from the current point with the step the first
    /// candidate would take next, on a copy of the state, hands back the time each
    /// advanced per counted attempt ([`Switcher::shadow_result`]) and then calls
    /// [`Switcher::finish_trial`].
    ///
    /// Why not on the solution, as the first candidate: a losing candidate's stint stays in
    /// the result. On the seed case the fourth-order pair's 70 attempts, taken on the
    /// solution at rtol 5e-6 after the fifth-order pair's, left an error of 1.04e-6 of the
    /// amplitude, where the fifth-order pair alone reaches 4.7e-7: at equal rtol the
    /// fourth-order pair's error is 5–10× larger there (in the gear's torsional mode).
    pub(crate) fn take_shadow(&mut self) -> Option<Shadow> {
        let trial = self.trial.as_mut()?;
        if !std::mem::take(&mut trial.shadow_due) {
            return None;
        }
        Some(Shadow {
            methods: &trial.candidates[1..],
            warmup: TRIAL_WARMUP,
            counted: trial_steps(trial.candidates),
        })
    }

    /// Score a shadow run of `m`: `per_attempt` is the time it advanced per counted
    /// attempt [s] (0 when it failed).
    pub(crate) fn shadow_result(&mut self, m: Method, per_attempt: f64) {
        if let Some(trial) = self.trial.as_mut() {
            trial.offer(m, per_attempt / cost_ratio(m) / SHADOW_MARGIN);
        }
    }

    /// Count DOP853's steps near its stability boundary; true after a run of them.
    fn held_by_stability(&mut self, stiffness: Option<f64>) -> bool {
        if stiffness.is_some_and(|s| s > DOP853_STIFF_INDICATOR) {
            self.stiff_run += 1;
        } else {
            self.stiff_run = 0;
        }
        self.stiff_run >= STIFF_RUN
    }

    fn switch_to(&mut self, m: Method) {
        self.current = m;
        self.dopri_steps = 0;
        self.stiff_run = 0;
        self.calm_run = 0;
        self.accuracy_run = 0;
        self.recent_h = 0.0;
        self.switches += 1;
    }
}
