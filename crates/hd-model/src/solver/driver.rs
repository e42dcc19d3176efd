//! The adaptive driver: segments between input breakpoints, step-size control, the
//! observer callback and solver statistics.

use super::imex_tables::{ARK436, ARK548};
use super::shadow;
use super::switching::{self, Switcher};
use super::{
    Dense, Method, OdeSystem, SolverOptions, SolverStats, all_finite, control, dop853, dopri5,
    error_norm, events, hair, imex, rodas4,
};
use crate::error::SolverError;
use nalgebra::SVector;

/// One accepted step, handed to the observer. Values inside the step come from the
/// method's own continuous extension when it has one (DOP853's, of order 7), and from
/// cubic Hermite interpolation of the end points and their derivatives otherwise.
pub struct Step<'a, const D: usize> {
    /// Start time [s].
    pub t0: f64,
    /// End time [s].
    pub t1: f64,
    /// State at `t0`.
    pub y0: &'a SVector<f64, D>,
    /// State at `t1`.
    pub y1: &'a SVector<f64, D>,
    /// Derivative at `t0`.
    pub f0: &'a SVector<f64, D>,
    /// Derivative at `t1`.
    pub f1: &'a SVector<f64, D>,
    /// The method's continuous extension over the step, if it has one.
    pub dense: Option<&'a Dense<D>>,
}

impl<const D: usize> Step<'_, D> {
    /// Interpolated state at `t` in `[t0, t1]`.
    pub fn interpolate(&self, t: f64) -> SVector<f64, D> {
        let h = self.t1 - self.t0;
        if h <= 0.0 {
            return *self.y1;
        }
        if let Some(d) = self.dense {
            return d.state((t - self.t0) / h);
        }
        let [h00, h10, h01, h11] = crate::interp::hermite_basis((t - self.t0) / h);
        h00 * self.y0 + (h10 * h) * self.f0 + h01 * self.y1 + (h11 * h) * self.f1
    }

    /// The interpolated components `idx` of the state at `t` in `[t0, t1]` (the same
    /// values as [`Step::interpolate`], without forming the whole state).
    pub fn components<const K: usize>(&self, t: f64, idx: [usize; K]) -> [f64; K] {
        let h = self.t1 - self.t0;
        if h <= 0.0 {
            return idx.map(|i| self.y1[i]);
        }
        if let Some(d) = self.dense {
            let s = (t - self.t0) / h;
            return idx.map(|i| d.component(s, i));
        }
        let [h00, h10, h01, h11] = crate::interp::hermite_basis((t - self.t0) / h);
        idx.map(|i| {
            h00 * self.y0[i] + (h10 * h) * self.f0[i] + h01 * self.y1[i] + (h11 * h) * self.f1[i]
        })
    }
}

/// Integrate `sys` from `(t0, y0)` to `t_end`, restarting at each of `breakpoints` inside
/// the interval, and call `observer` after every accepted step. Returns the final state
/// and the work done. With `Method::Auto` the driver switches between Dopri5 and the stiff
/// or higher-order methods by cost (see [`super::switching`]).
pub fn solve<const D: usize, S: OdeSystem<D>>(
    sys: &S,
    t0: f64,
    y0: SVector<f64, D>,
    t_end: f64,
    breakpoints: &[f64],
    opts: &SolverOptions,
    observer: &mut dyn FnMut(&Step<D>),
) -> Result<(SVector<f64, D>, SolverStats), SolverError> {
    integrate(sys, t0, y0, t_end, breakpoints, opts, observer, None)
        .map(|done| (done.y, done.stats))
}

/// Where an integration stopped.
pub(super) struct Done<const D: usize> {
    /// Final time [s] and state.
    pub t: f64,
    pub y: SVector<f64, D>,
    pub stats: SolverStats,
    /// Time reached when the attempt budget's warm-up ran out [s] (the start if it never did).
    pub t_warm: f64,
}

/// An attempt budget: stop after `total` attempts (accepted or rejected), noting the time
/// reached after the first `warmup`.
#[derive(Clone, Copy)]
pub(super) struct Budget {
    pub warmup: u64,
    pub total: u64,
}

/// [`solve`], optionally stopped by an attempt budget.
#[allow(clippy::too_many_arguments)]
pub(super) fn integrate<const D: usize, S: OdeSystem<D>>(
    sys: &S,
    t0: f64,
    y0: SVector<f64, D>,
    t_end: f64,
    breakpoints: &[f64],
    opts: &SolverOptions,
    observer: &mut dyn FnMut(&Step<D>),
    budget: Option<Budget>,
) -> Result<Done<D>, SolverError> {
    let auto = opts.method == Method::Auto;
    let mut switcher = Switcher::new(
        if !sys.may_be_stiff() {
            &[]
        } else if sys.split_is_complete() {
            switching::PAIRS
        } else {
            switching::ROSENBROCK
        },
        opts.rtol,
    );
    let mut method = if auto { switcher.current } else { opts.method };
    let mut stats = SolverStats { method: opts.method, ..Default::default() };
    let mut stops: Vec<f64> =
        breakpoints.iter().copied().filter(|&b| b > t0 && b < t_end).collect();
    stops.sort_by(f64::total_cmp);
    stops.dedup();
    stops.push(t_end);

    let scale = sys.abs_scale();
    let mut t = t0;
    let mut y = y0;
    let mut t_warm = t0;
    let mut h_next = 0.0;
    // The explicit and IMEX stages' rates, cleared once per solve rather than per step.
    let mut dopri_rates: dopri5::Rates<D> = [SVector::zeros(); 7];
    let mut imex_rates: imex::Rates<D, 6> = [SVector::zeros(); 6];
    let mut imex5_rates: imex::Rates<D, 8> = [SVector::zeros(); 8];
    for &seg_end in &stops {
        let mut f = sys.rhs(t, &y);
        stats.rhs_evals += 1;
        check_finite(&f, t)?;
        if h_next <= 0.0 {
            h_next = if opts.h_init > 0.0 {
                opts.h_init
            } else {
                initial_step(sys, t, &y, &f, &scale, opts, method, &mut stats)
            };
        }
        let mut jac_cache = None;
        let mut last_rejected = false;
        // The switching function and its rate at the step's start, and the step size a
        // landing on a kink interrupted (0 when none).
        let mut s_start = sys.switch_value(t, &y);
        let mut ds_start = s_start.and_then(|_| sys.switch_rate(t, &y, &f));
        // The implicit–explicit split at (t, y), when the last evaluation provided it.
        let mut imex_split: Option<(usize, f64)> = None;
        let mut imex_next: Option<(usize, f64)> = None;
        let mut h_resume: f64 = 0.0;
        // Accepted steps left after a landing aimed from a rejected step (0: none).
        let mut aimed: u8 = 0;
        // Whether the next step is cut to end on a kink's crossing (located or aimed at).
        let mut on_kink = false;
        // Whether the next step finishes a landing that fell a hair short (tried with
        // Heun's two-evaluation step first, see [`hair`]).
        let mut hair_next = false;
        // Whether the step after the next may not be longer than it (set when the next
        // one is aimed at a predicted kink).
        let mut hold = false;
        // ln of the previous accepted step's error norm (the PI controller's memory).
        let mut ln_err_prev: f64 = control::ERROR_FLOOR.ln();
        while t < seg_end {
            if let Some(b) = budget {
                let attempts = stats.steps + stats.rejected;
                if attempts == b.warmup {
                    t_warm = t;
                }
                if attempts >= b.total {
                    return Ok(Done { t, y, stats, t_warm });
                }
            }
            if stats.steps + stats.rejected >= opts.max_steps {
                return Err(SolverError::TooManySteps { time: t, steps: opts.max_steps });
            }
            let remaining = seg_end - t;
            let mut h = h_next.min(opts.h_max);
            // Land exactly on the segment end; avoid a sliver step just before it, except
            // when the step was cut to end on a kink: stretched, it would straddle the
            // kink again and be cut again, for ever (a stuck drive takes steps of
            // seconds, so its sliver before the end is milliseconds wide).
            let last = h >= remaining || (!on_kink && remaining - h < control::SLIVER * h);
            on_kink = false;
            if last {
                h = remaining;
            }
            if h <= control::MIN_STEP_EPS * f64::EPSILON * t.abs().max(1e-300) {
                return Err(SolverError::StepSizeTooSmall { time: t, step: h });
            }
            let mut stiffness = None;
            let mut dop853_stages = None;
            // The hair's Heun step, when its error passes; the running method otherwise.
            let heun = if std::mem::take(&mut hair_next) {
                stats.rhs_evals += 2;
                let split = if method.is_imex() {
                    imex_split.or_else(|| sys.stiff_split(t, &y)).map(|(k, _)| k)
                } else {
                    None
                };
                hair::attempt(sys, t, &y, &f, h, split, &scale, opts).map(|(tr, e)| (tr, split, e))
            } else {
                None
            };
            let (mut y1, f1, err_norm) = match (heun, method) {
                (Some((trial, split, e)), _) => {
                    if let (Some(k), Some(d1)) = (split, trial.d1) {
                        imex_next = Some((k, d1));
                    }
                    (trial.y1, Some(trial.f1), e)
                }
                (None, Method::Dopri5 | Method::Auto) => {
                    let trial = dopri5::step(sys, t, &y, &f, h, &mut dopri_rates);
                    stats.rhs_evals += 6;
                    stiffness = Some(trial.stiffness);
                    let e = error_norm(&trial.err, &y, &trial.y1, &scale, opts, sys.coupled());
                    (trial.y1, Some(trial.f1), e)
                }
                (None, Method::Dop853) => {
                    let trial = dop853::step(sys, t, &y, &f, h);
                    stats.rhs_evals += dop853::STAGES as u64;
                    stiffness = Some(trial.stiffness);
                    let m = sys.coupled();
                    let n5 = error_norm(&trial.err5, &y, &trial.y1, &scale, opts, m);
                    let n3 = error_norm(&trial.err3, &y, &trial.y1, &scale, opts, m);
                    dop853_stages = Some(trial.k);
                    (trial.y1, Some(trial.f1), dop853::combined_norm(n5, n3))
                }
                (None, Method::Imex | Method::Imex5) => match imex_split
                    .or_else(|| sys.stiff_split(t, &y))
                {
                    Some((k, d0)) => {
                        imex_split = Some((k, d0));
                        let trial = if method == Method::Imex {
                            imex::step(&ARK436, sys, t, &y, &f, k, d0, h, &mut imex_rates)
                        } else {
                            imex::step(&ARK548, sys, t, &y, &f, k, d0, h, &mut imex5_rates)
                        };
                        stats.rhs_evals += trial.evals;
                        let e = error_norm(&trial.err, &y, &trial.y1, &scale, opts, sys.coupled());
                        (trial.y1, None, e)
                    }
                    None => {
                        // No stiff split here: an explicit step (Dopri5) does.
                        let trial = dopri5::step(sys, t, &y, &f, h, &mut dopri_rates);
                        stats.rhs_evals += 6;
                        let e = error_norm(&trial.err, &y, &trial.y1, &scale, opts, sys.coupled());
                        (trial.y1, Some(trial.f1), e)
                    }
                },
                (None, Method::Rodas4) => {
                    let (jac, dfdt) = match jac_cache {
                        Some(c) => c,
                        None => {
                            stats.jac_evals += 1;
                            let c = sys.jacobian(t, &y);
                            jac_cache = Some(c);
                            c
                        }
                    };
                    stats.lu_decomps += 1;
                    stats.rhs_evals += 5;
                    match rodas4::step(sys, t, &y, &f, &jac, &dfdt, h) {
                        Ok(trial) => {
                            let e =
                                error_norm(&trial.err, &y, &trial.y1, &scale, opts, sys.coupled());
                            (trial.y1, None, e)
                        }
                        Err(rodas4::Singular) => (y, None, f64::INFINITY),
                    }
                }
            };
            let (order_exp, (alpha, beta)) = control::gains(method);
            if err_norm <= 1.0 && all_finite(&y1) {
                let t1 = if last { seg_end } else { t + h };
                let f1 = match (f1, imex_split) {
                    (Some(f1), _) => f1,
                    (None, Some((k, _))) if method.is_imex() => {
                        // The rate and the split's d at the new point in one evaluation
                        // (a zero implicit weight leaves y1 as it is).
                        stats.rhs_evals += 1;
                        let mut f1 = SVector::zeros();
                        let d1 = sys.implicit_stage(t1, &mut y1, k, 0.0, &mut f1);
                        imex_next = Some((k, d1));
                        f1
                    }
                    (None, _) => {
                        stats.rhs_evals += 1;
                        sys.rhs(t1, &y1)
                    }
                };
                check_finite(&f1, t1)?;
                // DOP853's continuous extension (three more evaluations): it places a
                // kink's crossing and gives the values inside the step. It is built from
                // the state before `commit`, which only rewrites states held constant
                // inside a step.
                let dense = dop853_stages.map(|k| {
                    stats.rhs_evals += 3;
                    Dense::new(sys, t, t1 - t, &y, &k, &y1, &f1)
                });
                let s_end = sys.switch_value(t1, &y1);
                if let (Some(s0), Some(s1)) = (s_start, s_end)
                    && events::straddles(s0, s1)
                {
                    // The step straddles a kink: retry it ending on the crossing. A
                    // crossing within a sliver of the start (after a landing, the next
                    // step may start a hair before it) or within the root's own precision
                    // of the end is left inside the step. So is one within the landing
                    // floor of the end: a hair landing (a step of about 1e-9 s) whose
                    // Newton step overshot by a few units of t's last place would
                    // otherwise be rejected and taken again, a whole step for nothing.
                    let step =
                        Step { t0: t, t1, y0: &y, y1: &y1, f0: &f, f1: &f1, dense: dense.as_ref() };
                    let hs = events::crossing(sys, &step, s0, s1) - t;
                    if hs > landing_sliver(aimed, h, t1)
                        && hs < h - (control::LAND_END_SLIVER * h).max(landing_floor(t1))
                    {
                        stats.rejected += 1;
                        // A second landing (the first one's root fell a hair short)
                        // keeps the step the first one cut short.
                        h_resume = h_resume.max(h);
                        h_next = hs;
                        on_kink = true;
                        continue;
                    }
                }
                sys.commit(t, t1, &y, &f, &mut y1, &f1);
                // The split at the new point; a commit that moved states other than the
                // coupled ones leaves it valid only when nothing there feeds back into d,
                // so it is recomputed unless the system has no commit-time states.
                imex_split = if y1.as_slice()[sys.live()..] == y.as_slice()[sys.live()..] {
                    imex_next.take()
                } else {
                    imex_next = None;
                    None
                };
                observer(&Step {
                    t0: t,
                    t1,
                    y0: &y,
                    y1: &y1,
                    f0: &f,
                    f1: &f1,
                    dense: dense.as_ref(),
                });
                stats.steps += 1;
                if method == Method::Rodas4 || method.is_imex() {
                    stats.implicit_steps += 1;
                }
                t = t1;
                y = y1;
                f = f1;
                jac_cache = None;
                // err^−α · err_prev^β, with one logarithm and one exponential.
                let ln_err = err_norm.ln(); // −∞ for a zero error
                let fac = if err_norm == 0.0 {
                    control::GROW_MAX
                } else {
                    control::SAFETY * (beta * ln_err_prev - alpha * ln_err).exp()
                };
                ln_err_prev = ln_err.max(control::ERROR_FLOOR.ln());
                let fac =
                    if last_rejected || std::mem::take(&mut hold) { fac.min(1.0) } else { fac };
                h_next = h * fac.clamp(control::SHRINK_ACCEPTED_MIN, control::GROW_MAX);
                if h_resume > 0.0 {
                    // After landing on a kink, resume with the step it cut short.
                    h_next = h_next.max(h_resume);
                    h_resume = 0.0;
                }
                // The switching function's value and rate at both ends of this step: the
                // start's for extrapolating past the end, the end's (taken once) for that,
                // for the Newton step below and as the next step's start.
                let switch_start = s_start.zip(ds_start);
                let ds_end = s_end.and_then(|_| sys.switch_rate(t, &y, &f));
                s_start = s_end;
                ds_start = ds_end;
                last_rejected = false;
                aimed = aimed.saturating_sub(1);
                // A step that ended a hair short of a kink (a landing's root or secant can
                // fall short by 1e-5 of the step), yet far enough for the next step's
                // straddle to land on it at the cost of a rejection: one Newton step on the
                // switching function finds the crossing, and the next step lands on it.
                if let Some(hs) = kink_ahead(s_end, ds_end)
                    && hs > landing_sliver(aimed, h_next, t)
                    && hs < control::HAIR * h_next
                {
                    h_resume = h_resume.max(h_next);
                    h_next = hs;
                    on_kink = true;
                    hair_next = true;
                } else if let Some(start) = switch_start
                    && let Some(end) = s_end.zip(ds_end)
                    && let Some(hp) = events::predicted_crossing(h, start, end, h_next)
                {
                    // A crossing within the next step, placed by extrapolating the
                    // switching function over this one: aim a hair short of it, so that
                    // the step keeps its order and the hair landing above finishes it,
                    // instead of straddling the kink and failing its error test.
                    let aim = hp * (1.0 - control::PREDICT_SHORT);
                    if aim > landing_sliver(2, h_next, t) {
                        h_next = aim;
                        on_kink = true;
                        aimed = 2;
                        // Past the kink the rates change their course: the step after
                        // this one may not be longer (as after a rejected straddle).
                        hold = true;
                    }
                }
                if auto {
                    let next = switcher.accepted(h, stiffness, stats.steps);
                    if next != method {
                        method = next;
                        stats.switches = switcher.switches;
                    }
                    if let Some(shadow) = switcher.take_shadow() {
                        for &m in shadow.methods {
                            let per_attempt = shadow::run(
                                sys, t, &y, h_next, t_end, &stops, opts, m, shadow, &mut stats,
                            );
                            switcher.shadow_result(m, per_attempt);
                        }
                        let next = switcher.finish_trial(stats.steps);
                        if next != method {
                            method = next;
                            stats.switches = switcher.switches;
                        }
                    }
                }
            } else {
                stats.rejected += 1;
                if auto {
                    switcher.rejected();
                }
                let fac = if err_norm.is_finite() {
                    control::SAFETY * err_norm.powf(-order_exp)
                } else {
                    control::SHRINK_FAILED
                };
                let (lo, hi) = control::SHRINK_REJECTED;
                h_next = h * fac.clamp(lo, hi);
                last_rejected = true;
                // A step across a kink fails its error test and would creep up to the kink
                // in ever shorter steps: go straight to the crossing instead. DOP853 places
                // it on its continuous extension; the other methods take the secant of the
                // switching function between the step's ends. A secant that falls short
                // leaves the kink just inside the next step, whose own check then lands on
                // it exactly (down to [`control::AIMED_SLIVER`] for the next two steps).
                if let Some(s0) = s_start
                    && err_norm.is_finite()
                    && let Some(s1) = sys.switch_value(t + h, &y1)
                    && events::straddles(s0, s1)
                {
                    let hs = match (f1, dop853_stages) {
                        (Some(f1), Some(k)) => {
                            stats.rhs_evals += 3;
                            let dense = Dense::new(sys, t, h, &y, &k, &y1, &f1);
                            let step = Step {
                                t0: t,
                                t1: t + h,
                                y0: &y,
                                y1: &y1,
                                f0: &f,
                                f1: &f1,
                                dense: Some(&dense),
                            };
                            events::crossing(sys, &step, s0, s1) - t
                        }
                        _ => h * s0 / (s0 - s1),
                    };
                    // Only a crossing well inside the step: one at its very end would retry
                    // the same step.
                    if hs > h_next
                        && hs > (control::LAND_SLIVER * h).max(landing_floor(t + h))
                        && hs < (1.0 - control::LAND_SLIVER) * h
                    {
                        h_resume = h_next.max(h_resume);
                        h_next = hs;
                        on_kink = true;
                        aimed = 2;
                    }
                }
            }
        }
    }
    Ok(Done { t, y, stats, t_warm })
}

/// How far ahead [s] the switching function, value `s` and rate `ds` [its unit per s]
/// ([`OdeSystem::switch_rate`]), reaches zero on its tangent; `None` when it moves away
/// from zero, is zero already or has no rate.
pub(super) fn kink_ahead(s: Option<f64>, ds: Option<f64>) -> Option<f64> {
    let s = s.filter(|&s| s != 0.0)?;
    let hs = -s / ds?;
    (hs > 0.0 && hs.is_finite()).then_some(hs)
}

/// How far inside a step of size h ending near time t [s] a kink's crossing must lie to be
/// landed on [s]: a relative sliver (the narrower one while `aimed` steps remain after a
/// landing aimed from a rejected step), and never less than [`landing_floor`].
fn landing_sliver(aimed: u8, h: f64, t: f64) -> f64 {
    let rel = if aimed > 0 { control::AIMED_SLIVER } else { control::LAND_SLIVER };
    (rel * h).max(landing_floor(t))
}

/// The shortest step a landing on a kink may take at time t [s]: well above the smallest
/// step the solve accepts (`MIN_STEP_EPS` units of t's last place). A crossing closer than
/// this to a step's start stays inside the step, where it cannot cost measurable accuracy;
/// landing on it would end in a step too small to take (as a stuck drive's chain of
/// landings 1e-12 s apart once did at t = 95 s).
fn landing_floor(t: f64) -> f64 {
    64.0 * control::MIN_STEP_EPS * f64::EPSILON * t.abs()
}

fn check_finite<const D: usize>(f: &SVector<f64, D>, t: f64) -> Result<(), SolverError> {
    if all_finite(f) { Ok(()) } else { Err(SolverError::NonFinite { time: t }) }
}

/// Initial step from the size of y and f (Hairer, Nørsett & Wanner, §II.4), with one
/// explicit Euler probe for the second derivative.
#[allow(clippy::too_many_arguments)]
fn initial_step<const D: usize, S: OdeSystem<D>>(
    sys: &S,
    t: f64,
    y: &SVector<f64, D>,
    f: &SVector<f64, D>,
    scale: &SVector<f64, D>,
    opts: &SolverOptions,
    method: Method,
    stats: &mut SolverStats,
) -> f64 {
    let order = 1.0 / control::gains(method).0;
    let sc = |i: usize| opts.atol * scale[i] + opts.rtol * y[i].abs();
    let m = sys.coupled();
    let norm = |v: &SVector<f64, D>| {
        ((0..m).map(|i| (v[i] / sc(i)).powi(2)).sum::<f64>() / m as f64).sqrt()
    };
    let d0 = norm(y);
    let d1 = norm(f);
    let h0 = if d0 < 1e-5 || d1 < 1e-5 { 1e-6 } else { 0.01 * d0 / d1 };
    let h0 = h0.min(opts.h_max);
    let y1 = y + h0 * f;
    let f1 = sys.rhs(t + h0, &y1);
    stats.rhs_evals += 1;
    let d2 = norm(&(f1 - f)) / h0;
    let h1 = if d1.max(d2) <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / order)
    };
    (100.0 * h0).min(h1).min(opts.h_max)
}
