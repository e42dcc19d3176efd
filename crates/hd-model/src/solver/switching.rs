//! Automatic choice between the explicit and the stiff methods, decided by cost.
//!
//! The drive's LuGre bristles make the system mildly stiff at the seed's parameters and
//! very stiff when σ0 is large or ωs small. The policy: run Dopri5; when its stiffness
//! indicator h·ρ stays above 3.25 for 15 accepted steps, try a stiff method for 30
//! attempts and keep it if the time it advances per attempt (rejected steps count) is more
//! than its cost ratio to a Dopri5 step (plus a margin) times Dopri5's recent step;
//! otherwise go back. The stiff method tried is the implicit–explicit pair when the
//! system's split covers all of its stiffness ([`super::OdeSystem::split_is_complete`]),
//! Rodas4 when it does not (inductance, a friction observer). The pair's steps cost about
//! what Dopri5's do, so it is also tried, without waiting for a stiff run, whenever
//! Dopri5's indicator passes 2 and a recheck is due: on the seed case at rtol 1e-6 that
//! takes 9 911 steps in 11.7 ms where waiting took 13 860 in 14.2 ms. Either way, look
//! again after a while, since stiffness changes along a run (it grows with the sliding
//! speed).
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
/// Rodas4 steps in a trial before its mean step is compared with Dopri5's [–].
const TRIAL_STEPS: u32 = 30;
/// Dopri5 steps after a switch before the implicit–explicit pair may be tried without a
/// stiff run (enough for Dopri5's mean step to settle) [–].
const PROBE_AFTER: u32 = 20;
/// Accepted steps after a trial that kept Dopri5 before stiffness is looked at again [–].
const RECHECK_AFTER_DOPRI: u64 = 300;
/// Accepted stiff-method steps before Dopri5 is tried again (the stiffness may have
/// gone) [–].
const RECHECK_AFTER_STIFF: u64 = 5_000;

/// The switching state of an `auto` solve.
#[derive(Clone, Debug)]
pub(crate) struct Switcher {
    /// Method for the next step.
    pub current: Method,
    /// The stiff method a trial tries; `None` for a system that cannot be stiff.
    stiff: Option<Method>,
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
    trial: Option<(u32, f64, f64)>, // attempts so far, sum of accepted h, Dopri5 reference h
    next_check: u64,
    /// Number of method changes.
    pub switches: u64,
}

impl Switcher {
    /// Start with the explicit method; `stiff` is the method to try when it is held by
    /// stability (Rodas4 or the implicit–explicit pair; none for a system that cannot be
    /// stiff); `rtol` decides whether DOP853 may be tried ([`HIGH_ORDER_RTOL`]).
    pub fn new(stiff: Option<Method>, rtol: f64) -> Self {
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
                // Rodas4's trials are dear, so they wait for a stiff run; the
                // implicit–explicit pair costs about what Dopri5 does, so it is also tried
                // when a recheck is due and Dopri5 is near its stability boundary (where
                // it is accuracy-bound, the higher-order Dopri5 wins).
                let cheap_trial = self.stiff == Some(Method::Imex)
                    && self.dopri_steps >= PROBE_AFTER
                    && stiffness.is_some_and(|s| s > NEAR_STIFF_INDICATOR);
                // Held by accuracy for a while: the eighth-order pair may go further per
                // unit of work.
                if stiffness.is_some_and(|s| s < ACCURACY_INDICATOR) {
                    self.accuracy_run += 1;
                } else {
                    self.accuracy_run = 0;
                }
                if let Some(stiff) = self.stiff
                    && (self.stiff_run >= STIFF_RUN || cheap_trial)
                    && steps >= self.next_check
                {
                    self.trial = Some((0, 0.0, self.recent_h));
                    self.switch_to(stiff);
                } else if self.accuracy_run >= ACCURACY_RUN && steps >= self.high_next_check {
                    self.trial = Some((0, 0.0, self.recent_h));
                    self.switch_to(Method::Dop853);
                }
            }
            Method::Dop853 if dop853_held => {
                // Kept for accuracy, now held by stability (its boundary is about 6):
                // back to Dopri5, which knows what to try next.
                self.high_next_check = steps.saturating_add(self.high_wait);
                self.switch_to(Method::Dopri5);
            }
            _ => match self.trial.as_mut() {
                Some((n, sum, h_dopri)) => {
                    *n += 1;
                    *sum += h;
                    if *n >= TRIAL_STEPS {
                        // Time advanced per attempt: a rejected Rodas4 step costs as much
                        // as an accepted one.
                        let h_stiff = *sum / f64::from(*n);
                        let ratio = match self.current {
                            Method::Imex => IMEX_COST_RATIO,
                            Method::Dop853 => DOP853_COST_RATIO,
                            _ => COST_RATIO,
                        };
                        let keep = h_stiff > ratio * *h_dopri;
                        self.trial = None;
                        if keep {
                            self.next_check = steps + RECHECK_AFTER_STIFF;
                        } else {
                            if self.current == Method::Dop853 {
                                self.high_next_check = steps.saturating_add(self.high_wait);
                                self.high_wait = self.high_wait.saturating_mul(2);
                            } else {
                                self.next_check = steps + RECHECK_AFTER_DOPRI;
                            }
                            self.switch_to(Method::Dopri5);
                        }
                    }
                }
                None if steps >= self.next_check => {
                    // Committed to the stiff method for a while: probe the explicit one again.
                    self.next_check = 0;
                    self.switch_to(Method::Dopri5);
                }
                None => {}
            },
        }
        self.current
    }

    /// Record a rejected step: during a Rodas4 trial it counts as an attempt that
    /// advanced no time.
    pub fn rejected(&mut self) {
        if let Some((n, _, _)) = self.trial.as_mut() {
            *n += 1;
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
