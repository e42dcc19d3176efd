//! A voltage test of a drive, logged as a rig logs it: the applied voltage, the motor and
//! load encoders and, where measured, the armature current, sampled uniformly.

use super::closed_loop::ClosedLoop;
use crate::drive::error::DriveError;

/// How the voltage runs between two samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Between {
    /// Held from each sample to the next (a digital amplifier's zero-order hold).
    Hold,
    /// Straight from each sample to the next.
    #[default]
    Linear,
    /// Cubic through the four nearest samples (Catmull–Rom): a smooth test signal sampled
    /// well above its highest frequency.
    Cubic,
}

impl Between {
    /// Parse `hold`, `linear` or `cubic`.
    pub fn parse(s: &str) -> Option<Between> {
        match s {
            "hold" => Some(Between::Hold),
            "linear" => Some(Between::Linear),
            "cubic" => Some(Between::Cubic),
            _ => None,
        }
    }

    /// The configuration name.
    pub fn name(self) -> &'static str {
        match self {
            Between::Hold => "hold",
            Between::Linear => "linear",
            Between::Cubic => "cubic",
        }
    }
}

/// Which instant a logged current sample refers to, relative to the voltage (or command)
/// that changes at that sample ([`VoltageRecord::current_sampled`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CurrentSampled {
    /// Just after the new voltage is applied (the logger reads the current in the same tick
    /// as it writes the voltage, after it): the current at sample k follows the voltage of
    /// sample k. What `hdw synth drive` logs.
    #[default]
    After,
    /// Just before the new voltage is applied (the current read at the start of the tick,
    /// then the new voltage written): the current at sample k still follows the voltage
    /// of the interval that ends there, sample k − 1's when held.
    Before,
}

impl CurrentSampled {
    /// Parse `after` or `before`.
    pub fn parse(s: &str) -> Option<CurrentSampled> {
        match s {
            "after" => Some(CurrentSampled::After),
            "before" => Some(CurrentSampled::Before),
            _ => None,
        }
    }

    /// The configuration name.
    pub fn name(self) -> &'static str {
        match self {
            CurrentSampled::After => "after",
            CurrentSampled::Before => "before",
        }
    }

    /// The other instant.
    pub fn other(self) -> CurrentSampled {
        match self {
            CurrentSampled::After => CurrentSampled::Before,
            CurrentSampled::Before => CurrentSampled::After,
        }
    }
}

/// One logged voltage test.
#[derive(Clone, Debug, PartialEq)]
pub struct VoltageRecord {
    /// Name in reports.
    pub name: String,
    /// The file it came from, for messages.
    pub source: String,
    /// Sample period [s].
    pub h: f64,
    /// Sample times [s].
    pub t: Vec<f64>,
    /// Applied voltage [V].
    pub u: Vec<f64>,
    /// Motor encoder θj [rad].
    pub theta_m: Vec<f64>,
    /// Load encoder θz [rad].
    pub theta_l: Vec<f64>,
    /// Armature current [A], if logged.
    pub current: Option<Vec<f64>>,
    /// The loop the record was logged in, if any; `u` is then the recorded command
    /// (the controller's output, [V] or [A]) ([`VoltageRecord::in_loop`]).
    pub closed: Option<ClosedLoop>,
    /// Which instant the logged current refers to (default just after the new voltage).
    pub current_sampled: CurrentSampled,
}

impl VoltageRecord {
    /// Check and assemble a record: equal lengths, at least 10 samples, finite values,
    /// strictly increasing and uniform time.
    pub fn new(
        name: &str,
        source: &str,
        t: Vec<f64>,
        u: Vec<f64>,
        theta_m: Vec<f64>,
        theta_l: Vec<f64>,
        current: Option<Vec<f64>>,
    ) -> Result<VoltageRecord, DriveError> {
        let err = |m: String| DriveError::data(source, m);
        let n = t.len();
        if n < 10 {
            return Err(err(format!("{n} samples; a drive record needs at least 10")));
        }
        let mut cols = vec![("time", &t), ("voltage", &u), ("motor", &theta_m), ("load", &theta_l)];
        if let Some(i) = &current {
            cols.push(("current", i));
        }
        for (what, col) in &cols {
            if col.len() != n {
                return Err(err(format!(
                    "the {what} column has {} samples but time has {n}",
                    col.len()
                )));
            }
            if let Some(k) = col.iter().position(|v| !v.is_finite()) {
                return Err(err(format!(
                    "{what}, row {}: {} is not a finite number",
                    k + 2,
                    col[k]
                )));
            }
        }
        let h = crate::drive::record::uniform_period(&t, source, "the fit")?;
        Ok(VoltageRecord {
            name: name.into(),
            source: source.into(),
            h,
            t,
            u,
            theta_m,
            theta_l,
            current,
            closed: None,
            current_sampled: CurrentSampled::After,
        })
    }

    /// The record as logged in loop `cl`: its `u` is the recorded command. The reference
    /// must have one finite value per sample, and the controller the record's sample period.
    pub fn in_loop(mut self, mut cl: ClosedLoop) -> Result<VoltageRecord, DriveError> {
        let err = |m: String| DriveError::data(&self.source, m);
        let n = self.len();
        if cl.reference.len() != n {
            return Err(err(format!(
                "the reference column has {} samples but time has {n}",
                cl.reference.len()
            )));
        }
        if let Some(k) = cl.reference.iter().position(|v| !v.is_finite()) {
            return Err(err(format!(
                "reference, row {}: {} is not a finite number",
                k + 2,
                cl.reference[k]
            )));
        }
        cl.controller.h = self.h;
        cl.controller.open_loop = None;
        self.closed = Some(cl);
        Ok(self)
    }

    /// The record with its current read at instant `s`.
    pub fn with_current_sampled(self, s: CurrentSampled) -> VoltageRecord {
        VoltageRecord { current_sampled: s, ..self }
    }

    /// The voltage the current of sample `k` follows [V]: the voltage at sample `k`, or,
    /// read just before the new voltage, the end of the interval before it.
    pub fn voltage_at_current(&self, k: usize, between: Between) -> f64 {
        match (self.current_sampled, k) {
            (CurrentSampled::Before, k) if k > 0 => self.voltage(k - 1, 1.0, between),
            _ => self.u[k],
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether it has no samples (never, once built).
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The voltage at fraction `tau` ∈ [0, 1] of the interval from sample `k` [V].
    pub fn voltage(&self, k: usize, tau: f64, between: Between) -> f64 {
        let n = self.u.len();
        let at = |j: isize| self.u[j.clamp(0, n as isize - 1) as usize];
        let k = k as isize;
        match between {
            Between::Hold => at(k),
            Between::Linear => at(k) + (at(k + 1) - at(k)) * tau,
            Between::Cubic => {
                let (p0, p1, p2, p3) = (at(k - 1), at(k), at(k + 1), at(k + 2));
                let t2 = tau * tau;
                let t3 = t2 * tau;
                0.5 * (2.0 * p1
                    + (p2 - p0) * tau
                    + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
                    + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t3)
            }
        }
    }
}
