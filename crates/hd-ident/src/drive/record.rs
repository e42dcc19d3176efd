//! One recorded experiment of a drive in its loop: position, reference, command (and an
//! optional additive disturbance on the command), sampled uniformly.

use super::error::DriveError;

/// A logged closed-loop run, in the axis's units (position [m or rad], command [V or the
/// command's unit]).
#[derive(Clone, Debug, PartialEq)]
pub struct Experiment {
    /// Name used in reports (`estimation`, `validation`, …).
    pub name: String,
    /// Where it came from (the file), for messages.
    pub source: String,
    /// Sample period [s].
    pub h: f64,
    /// Sample times [s].
    pub t: Vec<f64>,
    /// Measured position [m or rad].
    pub position: Vec<f64>,
    /// Position reference of the controller [m or rad].
    pub reference: Vec<f64>,
    /// Recorded command (the controller's output) [command unit].
    pub command: Vec<f64>,
    /// Disturbance added to the controller's output [command unit]; zeros when the record
    /// has none.
    pub disturbance: Vec<f64>,
    /// The measured position's speed, low-passed without lag [m/s or rad/s]: where an
    /// open-loop fit restarts its segments (empty until [`Experiment::estimate_speed`]).
    pub speed: Vec<f64>,
}

/// Largest relative deviation of a sample interval from the typical one before the record counts
/// as not uniformly sampled.
const JITTER: f64 = 1e-3;

/// How many of the first intervals give the typical one (their median).
const TYPICAL: usize = 10_001;

/// The sample period [s] of a time column that increases strictly and uniformly (within
/// [`JITTER`]); the error names `source`, the row and what `needs` uniform sampling.
pub fn uniform_period(t: &[f64], source: &str, needs: &str) -> Result<f64, DriveError> {
    let err = |m: String| DriveError::data(source, m);
    let n = t.len();
    if let Some(k) = t.windows(2).position(|w| w[1] <= w[0]) {
        return Err(err(format!(
            "time, row {}: {} s does not come after {} s; time must increase strictly",
            k + 2,
            t[k + 1],
            t[k]
        )));
    }
    // The row named is the first whose interval departs from the typical one (the median
    // of the first intervals), so a gap is named where it is, not at row 2 (a gap raises
    // the mean above every regular interval).
    let mut first: Vec<f64> = t.windows(2).take(TYPICAL).map(|w| w[1] - w[0]).collect();
    let mid = first.len() / 2;
    let typical =
        if first.is_empty() { 0.0 } else { *first.select_nth_unstable_by(mid, f64::total_cmp).1 };
    if let Some(k) = t.windows(2).position(|w| ((w[1] - w[0]) / typical - 1.0).abs() > JITTER) {
        return Err(err(format!(
            "time, row {}: interval {} s differs from the record's sample period {typical} s (a gap, a repeated sample or jitter); {needs} needs uniform sampling",
            k + 2,
            t[k + 1] - t[k]
        )));
    }
    let h = (t[n - 1] - t[0]) / (n.max(2) - 1) as f64;
    Ok(h)
}

impl Experiment {
    /// Check and assemble a record: equal lengths, at least 10 samples, strictly increasing
    /// and uniform time (the controller is discrete). `disturbance` may be empty (zeros).
    pub fn new(
        name: &str,
        source: &str,
        t: Vec<f64>,
        position: Vec<f64>,
        reference: Vec<f64>,
        command: Vec<f64>,
        disturbance: Vec<f64>,
    ) -> Result<Experiment, DriveError> {
        let err = |m: String| DriveError::data(source, m);
        let n = t.len();
        if n < 10 {
            return Err(err(format!("{n} samples; a drive record needs at least 10")));
        }
        let disturbance = if disturbance.is_empty() { vec![0.0; n] } else { disturbance };
        for (what, len) in [
            ("position", position.len()),
            ("reference", reference.len()),
            ("command", command.len()),
            ("disturbance", disturbance.len()),
        ] {
            if len != n {
                return Err(err(format!("the {what} column has {len} samples but time has {n}")));
            }
        }
        let h = uniform_period(&t, source, "a discrete controller")?;
        Ok(Experiment {
            name: name.to_string(),
            source: source.to_string(),
            h,
            t,
            position,
            reference,
            command,
            disturbance,
            speed: Vec::new(),
        })
    }

    /// Fill [`Experiment::speed`]: the position low-passed forwards and backwards by a
    /// Butterworth filter of `order` at `cutoff_hz`, differenced centrally.
    pub fn estimate_speed(&mut self, order: usize, cutoff_hz: f64) {
        let sections = super::filter::butterworth(order, cutoff_hz, 1.0 / self.h);
        let smooth = super::filter::filtfilt(&sections, &self.position);
        self.speed = super::filter::central_difference(&smooth, self.h);
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether it has no samples (never, once built).
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
}
