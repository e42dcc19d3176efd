//! Accumulates what the metrics need while the integrator runs, so no trace has to be
//! kept: exact θz extrema per step, uniform samples on the metric grids, and the
//! quadrature states at the start of the periodic window.

use super::tracking::{TrackingSamples, Windows, tracking_metrics};
use super::{
    MetricSettings, Metrics, buffers,
    extrema::{cubic_extrema, hermite_range},
    limit_cycle, periodic, step,
};
use crate::laws::friction::FrictionLaw;
use crate::laws::input::Input;
use crate::solver::OdeSystem;
use crate::solver::Step;
use crate::state::*;
use crate::system::DriveSystem;

/// Metric accumulator for one run; feed it every accepted step, then call `finish`.
pub struct Collector {
    settings: MetricSettings,
    t_end: f64,
    /// Periodic window: drive frequency [Hz], window start [s] and whole cycles used.
    periodic: Option<(f64, f64, usize)>,
    y_window: Option<State>,
    window_lo: f64,
    window_hi: f64,
    /// θz [rad] on the window's uniform grid, `samples_per_cycle` to a cycle from its
    /// start (the times follow from the index).
    window_thz: Vec<f64>,
    /// The drive over the window: u [V] open loop, θz_ref [rad] closed loop; not sampled
    /// for an open-loop sine, whose fit is known.
    window_drive: Vec<f64>,
    /// The amplitude [V] of an open-loop sine input.
    drive_sine: Option<f64>,
    run_dt: f64,
    run_t: Vec<f64>,
    run_wz: Vec<f64>,
    run_theta: Vec<f64>,
    thz_peak: f64,
    tb_peak: f64,
    tf_peak: f64,
    s_peak: f64,
    y_start: State,
    /// Closed-loop samples and windows (closed loop only).
    tracking: Option<(TrackingSamples, Windows)>,
    ctl_dt: f64,
    is_step: bool,
    step_time: Option<f64>,
    /// Lowest and highest open-loop input over the final window of a non-periodic run [V]:
    /// an oscillation under a varying input is forced, not a limit cycle.
    drive_range: (f64, f64),
}

impl Collector {
    /// A collector for a run of `sys` from `y_start` at t = 0 to `t_end`.
    pub fn new(sys: &DriveSystem, settings: MetricSettings, y_start: State, t_end: f64) -> Self {
        let open_input = sys.ctl.is_none().then_some(&sys.input);
        let periodic = super::window::periodic_window(
            sys.drive_frequency(),
            open_input,
            t_end,
            settings.cycles,
        )
        .ok();
        let run_samples = if periodic.is_some() { 0 } else { settings.run_samples.max(2) };
        let window_samples =
            periodic.map_or(0, |(_, _, cycles)| cycles * settings.samples_per_cycle.max(8));
        let drive_sine = match sys.input {
            Input::Sine { amplitude, .. } if sys.ctl.is_none() => Some(amplitude),
            _ => None,
        };
        let tracking = sys.ctl.as_ref().map(|c| {
            let r = c.reference();
            let window = if settings.reversal_window > 0.0 {
                settings.reversal_window
            } else {
                r.period().map_or(0.1, |p| p / 10.0)
            };
            (
                TrackingSamples::default(),
                Windows {
                    settled_from: r.settled_from(),
                    reversal_window: window,
                    final_from: t_end * (1.0 - settings.final_fraction),
                    regulation: r.is_regulation(),
                },
            )
        });
        Self {
            tracking,
            ctl_dt: t_end / (settings.run_samples.max(2) - 1) as f64,
            is_step: matches!(sys.input, Input::Step { .. }) && sys.ctl.is_none(),
            step_time: match sys.input {
                Input::Step { t0, .. } if sys.ctl.is_none() => Some(t0),
                Input::Constant { .. } if sys.ctl.is_none() => Some(0.0),
                _ => None,
            },
            drive_range: (f64::INFINITY, f64::NEG_INFINITY),
            settings,
            t_end,
            periodic,
            y_window: None,
            window_lo: f64::INFINITY,
            window_hi: f64::NEG_INFINITY,
            window_thz: buffers::take(window_samples),
            window_drive: buffers::take(if drive_sine.is_some() { 0 } else { window_samples }),
            drive_sine,
            run_dt: if run_samples > 0 { t_end / (run_samples - 1) as f64 } else { 0.0 },
            run_t: buffers::take(run_samples),
            run_wz: buffers::take(run_samples),
            run_theta: buffers::take(run_samples),
            thz_peak: 0.0,
            tb_peak: 0.0,
            tf_peak: 0.0,
            s_peak: 0.0,
            y_start,
        }
    }

    /// Record one accepted step of `sys`.
    pub fn on_step(&mut self, sys: &DriveSystem, s: &Step<DIM>) {
        self.on_step_tracking(sys, s);
        let (thz0, thz1) = (sys.theta_z(s.y0), sys.theta_z(s.y1));
        let h = s.t1 - s.t0;
        let (m0, m1) = (s.y0[OMEGA_Z], s.y1[OMEGA_Z]);
        // The exact extrema only where they could move the peak or the window's range:
        // after the start the cheap range mostly lies inside both.
        let (blo, bhi) = hermite_range(thz0, thz1, m0, m1, h);
        let in_window = self.periodic.is_some_and(|(_, tw, _)| s.t1 >= tw);
        let inside = blo.abs().max(bhi.abs()) <= self.thz_peak
            && (!in_window || (self.window_lo <= blo && bhi <= self.window_hi));
        let (lo, hi) = if inside { (blo, bhi) } else { cubic_extrema(thz0, thz1, m0, m1, h) };
        self.thz_peak = self.thz_peak.max(lo.abs()).max(hi.abs());
        let (tb, tf) = sys.gear_torque_pair(s.y1, s.f1);
        self.tb_peak = self.tb_peak.max(tb.abs());
        self.tf_peak = self.tf_peak.max(tf.abs());
        self.s_peak = self.s_peak.max(sys.friction.deflection(s.y1[W]).abs());

        if let Some((f, tw, cycles)) = self.periodic {
            if s.t1 >= tw {
                if self.y_window.is_none() {
                    self.y_window = Some(s.interpolate(tw));
                }
                // Extrema over the part of the step inside the window.
                let (lo, hi) = if s.t0 < tw {
                    let ya = s.interpolate(tw);
                    cubic_extrema(sys.theta_z(&ya), thz1, ya[OMEGA_Z], s.y1[OMEGA_Z], s.t1 - tw)
                } else {
                    (lo, hi)
                };
                self.window_lo = self.window_lo.min(lo);
                self.window_hi = self.window_hi.max(hi);
                let spc = self.settings.samples_per_cycle.max(8);
                let total = cycles * spc;
                let dt = 1.0 / (f * spc as f64);
                while self.window_thz.len() < total {
                    let tk = tw + self.window_thz.len() as f64 * dt;
                    if tk > s.t1 {
                        break;
                    }
                    let [thj, th] = s.components(tk.max(s.t0), [THETA_J, THETA]);
                    self.window_thz.push(thj / sys.n - th);
                    if self.drive_sine.is_none() {
                        self.window_drive.push(match &sys.ctl {
                            Some(c) => c.reference().eval(tk)[0],
                            None => sys.input.value(tk),
                        });
                    }
                }
            }
        } else {
            // Non-periodic runs: the state where the final window starts, for the
            // efficiency over that window.
            let t_final = self.t_end * (1.0 - self.settings.final_fraction);
            if s.t1 >= t_final && self.y_window.is_none() {
                self.y_window = Some(if t_final <= s.t0 { *s.y0 } else { s.interpolate(t_final) });
            }
            loop {
                let tk = self.run_t.len() as f64 * self.run_dt;
                if self.run_t.len() >= self.settings.run_samples.max(2) || tk > s.t1 {
                    break;
                }
                let [wz, th] = if tk <= s.t0 {
                    [s.y0[OMEGA_Z], s.y0[THETA]]
                } else {
                    s.components(tk, [OMEGA_Z, THETA])
                };
                if tk >= t_final && sys.ctl.is_none() {
                    let u = sys.input.value(tk);
                    self.drive_range = (self.drive_range.0.min(u), self.drive_range.1.max(u));
                }
                self.run_t.push(tk);
                self.run_wz.push(wz);
                self.run_theta.push(th);
            }
        }
    }

    /// Whether the open-loop input holds still over the final window (to 1e-9 of its
    /// level), so that an oscillation there is the drive's own; closed loop: always.
    fn input_steady(&self) -> bool {
        let (lo, hi) = self.drive_range;
        lo > hi || hi - lo <= 1e-9 * lo.abs().max(hi.abs()).max(1e-300)
    }

    /// Sample the closed-loop signals on the uniform grid inside step `s`.
    fn on_step_tracking(&mut self, sys: &DriveSystem, s: &Step<DIM>) {
        let (Some((samples, _)), Some(ctl)) = (self.tracking.as_mut(), sys.ctl.as_ref()) else {
            return;
        };
        loop {
            let tk = samples.t.len() as f64 * self.ctl_dt;
            if samples.t.len() >= self.settings.run_samples.max(2) || tk > s.t1 {
                break;
            }
            let y = if tk <= s.t0 { *s.y0 } else { s.interpolate(tk) };
            let p = sys.parts(tk, &y);
            let c = p.ctl.expect("closed loop");
            let wj_dot = sys.rhs(tk, &y)[OMEGA_J];
            let tb_hat = ctl.torque_estimate(p.i, y[OMEGA_J], wj_dot, 0.0);
            samples.t.push(tk);
            samples.error.push(c.error);
            samples.ref_speed.push(c.ref_speed);
            samples.u.push(c.u);
            samples.saturated.push(c.u != c.u_raw);
            samples.tb_err.push(tb_hat - c.tf_hat - p.st.torque);
            samples.tb_err_nofric.push(tb_hat - p.st.torque);
        }
    }

    /// Compute the metrics from what was collected and the final state of `sys`.
    pub fn finish(self, sys: &DriveSystem, y_end: &State) -> Metrics {
        let mut m = Metrics::undefined();
        if let Some((samples, windows)) = &self.tracking {
            let v = tracking_metrics(samples, windows);
            [
                &mut m.track_rms,
                &mut m.track_max,
                &mut m.reversal_peak,
                &mut m.u_rms,
                &mut m.saturation_fraction,
                &mut m.torque_est_rms,
                &mut m.torque_est_rms_nofric,
                &mut m.steady_error,
                &mut m.hunting,
                &mut m.hunt_amplitude,
                &mut m.hunt_period,
            ]
            .into_iter()
            .zip(v)
            .for_each(|(slot, x)| *slot = x);
        }
        m.thz_peak = self.thz_peak;
        m.tb_peak = self.tb_peak;
        m.tf_peak = self.tf_peak;
        m.s_peak = self.s_peak;
        m.energy_residual = self.energy_residual(sys, y_end);
        if let (None, Some(yw)) = (self.periodic, self.y_window) {
            let work_in = y_end[Q_IN] - yw[Q_IN];
            m.efficiency =
                if work_in > 0.0 { (y_end[Q_OUT] - yw[Q_OUT]) / work_in } else { f64::NAN };
        }
        if let (Some((f, tw, cycles)), Some(yw)) = (self.periodic, self.y_window) {
            let n = cycles as f64;
            m.cycles_used = n;
            m.thz_amp = 0.5 * (self.window_hi - self.window_lo);
            let spc = self.settings.samples_per_cycle.max(8);
            let basis = periodic::Fundamental::uniform(tw, f, spc, self.window_thz.len());
            let thz_fit = basis.fit(&self.window_thz);
            let (mean, _, _, rms) = thz_fit;
            m.thz_mean = mean;
            m.thz_ripple = rms;
            // A sine input's fit is known exactly: amplitude on the sine, nothing else.
            let drive_fit = match self.drive_sine {
                Some(amplitude) => (0.0, amplitude, 0.0, 0.0),
                None => basis.fit(&self.window_drive),
            };
            let (gain, phase) = super::gain_phase_of(drive_fit, thz_fit);
            m.gain_db = super::to_db(gain);
            m.phase_deg = phase.to_degrees();
            m.hyst_loss_per_cycle = (y_end[Q_HYST] - yw[Q_HYST]) / n;
            m.friction_loss_per_cycle = (y_end[Q_FRIC] - yw[Q_FRIC]) / n;
            let work_in = y_end[Q_IN] - yw[Q_IN];
            m.efficiency =
                if work_in > 0.0 { (y_end[Q_OUT] - yw[Q_OUT]) / work_in } else { f64::NAN };
        }
        if !self.run_t.is_empty() {
            let t_final = self.t_end * (1.0 - self.settings.final_fraction);
            let k0 = self.run_t.partition_point(|&t| t < t_final);
            let tail_t = &self.run_t[k0..];
            if self.input_steady() {
                let [flag, amp, period] = limit_cycle::detect(tail_t, &self.run_wz[k0..]);
                m.limit_cycle = flag;
                m.lc_amplitude = amp;
                m.lc_period = period;
            }
            if let Some(t_step) = self.step_time {
                let [rise, over, settle, fin] = step::step_metrics(
                    &self.run_t,
                    &self.run_wz,
                    t_step,
                    t_final,
                    self.settings.settle_band,
                );
                m.final_speed = fin;
                if self.is_step {
                    m.rise_time = rise;
                    m.overshoot = over;
                    m.settling_time = settle;
                    let tail = &self.run_theta[k0..];
                    let theta_final = tail.iter().sum::<f64>() / tail.len().max(1) as f64;
                    let k_step = self.run_t.partition_point(|&t| t < t_step);
                    m.damping_ratio =
                        step::damping_from_decrement(&self.run_theta[k_step..], theta_final);
                }
            }
        }
        m
    }

    /// |electrical in − (Δstored + dissipated)| relative to the energy turned over.
    fn energy_residual(&self, sys: &DriveSystem, y: &State) -> f64 {
        let stored = sys.stored_energy(y) - sys.stored_energy(&self.y_start);
        let d_in = y[Q_ELEC] - self.y_start[Q_ELEC];
        let d_diss = y[Q_DISS] - self.y_start[Q_DISS];
        let d_fric = y[Q_FRIC] - self.y_start[Q_FRIC];
        let d_load = y[Q_LOAD] - self.y_start[Q_LOAD];
        let d_slip = y[Q_SLIP] - self.y_start[Q_SLIP];
        let out = stored.abs() + d_diss.abs() + d_fric.abs() + d_load.abs() + d_slip.abs();
        let turned_over = d_in.abs().max(out);
        let residual = d_in - stored - d_diss - d_fric - d_load - d_slip;
        if turned_over > 0.0 { residual.abs() / turned_over } else { 0.0 }
    }
}

impl Drop for Collector {
    /// Hand the sample buffers back for the thread's next run.
    fn drop(&mut self) {
        for v in [
            &mut self.run_t,
            &mut self.run_wz,
            &mut self.run_theta,
            &mut self.window_thz,
            &mut self.window_drive,
        ] {
            buffers::give(std::mem::take(v));
        }
    }
}
