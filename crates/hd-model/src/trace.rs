//! The sampled time series of a run (the columns of `trace.parquet`).

use serde::{Deserialize, Serialize};

/// One trace column: name, unit, description and the vector of [`Trace`] it reads.
#[derive(Clone, Copy, Debug)]
pub struct TraceColumn {
    /// Column name.
    pub name: &'static str,
    /// SI unit.
    pub unit: &'static str,
    /// One-line description.
    pub doc: &'static str,
    col: fn(&Trace) -> &Vec<f64>,
    col_mut: fn(&mut Trace) -> &mut Vec<f64>,
}

impl TraceColumn {
    /// This column's samples in `t`.
    pub fn of<'a>(&self, t: &'a Trace) -> &'a [f64] {
        (self.col)(t)
    }

    /// This column's samples in `t`, to fill.
    pub fn of_mut<'a>(&self, t: &'a mut Trace) -> &'a mut Vec<f64> {
        (self.col_mut)(t)
    }
}

macro_rules! c {
    ($name:literal, $field:ident, $unit:literal, $doc:literal) => {
        TraceColumn {
            name: $name,
            unit: $unit,
            doc: $doc,
            col: |t| &t.$field,
            col_mut: |t| &mut t.$field,
        }
    };
}

/// The one table of trace columns (`trace.parquet`, `traces.parquet`), in output order.
pub static TRACE_COLUMNS: &[TraceColumn] = &[
    c!("t", t, "s", "time"),
    c!("u", u, "V", "armature voltage"),
    c!("i", i, "A", "armature current"),
    c!("theta_j", theta_j, "rad", "motor angle"),
    c!("omega_j", omega_j, "rad/s", "motor speed"),
    c!("theta_z", theta_z, "rad", "load angle"),
    c!("omega_z", omega_z, "rad/s", "load speed"),
    c!("theta", theta, "rad", "gear deflection θj/N − θz"),
    c!("z", z, "N·m", "hysteretic torque (memory z, Bouc–Wen α·w, or the slip elements' Σkᵢeᵢ)"),
    c!("s", s, "rad", "LuGre mean bristle deflection"),
    c!("Tb", tb, "N·m", "transmitted torque"),
    c!("Tf", tf, "N·m", "friction torque"),
    c!("K", k, "N·m/rad", "stiffness dTb/dθ; null where undefined"),
    c!("C0", c0, "N·m·s/rad", "friction damping dTf/dv; null where undefined"),
    c!("ref", reference, "rad", "closed loop: load-angle reference θz_ref; null open loop"),
    c!("error", error, "rad", "closed loop: tracking error θz_ref − θz; null open loop"),
    c!("u_ff", u_ff, "V", "closed loop: friction-compensation feedforward voltage; null open loop"),
    c!(
        "tf_hat",
        tf_hat,
        "N·m",
        "closed loop: friction torque estimated by the controller's LuGre observer; null open loop"
    ),
    c!(
        "tb_hat",
        tb_hat,
        "N·m",
        "closed loop: transmitted torque estimated from current, motor speed and acceleration and the friction estimate; null open loop"
    ),
];

/// Signals sampled on the output grid. All columns have the same length.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Trace {
    /// Time [s].
    pub t: Vec<f64>,
    /// Armature voltage [V].
    pub u: Vec<f64>,
    /// Armature current [A].
    pub i: Vec<f64>,
    /// Motor angle [rad].
    pub theta_j: Vec<f64>,
    /// Motor speed [rad/s].
    pub omega_j: Vec<f64>,
    /// Load angle [rad].
    pub theta_z: Vec<f64>,
    /// Load speed [rad/s].
    pub omega_z: Vec<f64>,
    /// Gear deflection θj/N − θz [rad].
    pub theta: Vec<f64>,
    /// Hysteresis memory torque [N·m].
    pub z: Vec<f64>,
    /// LuGre mean bristle deflection [rad].
    pub s: Vec<f64>,
    /// Transmitted torque [N·m].
    pub tb: Vec<f64>,
    /// Friction torque [N·m].
    pub tf: Vec<f64>,
    /// Stiffness dTb/dθ [N·m/rad]; NaN where undefined.
    pub k: Vec<f64>,
    /// Friction damping dTf/dv [N·m·s/rad]; NaN where undefined.
    pub c0: Vec<f64>,
    /// Load-angle reference [rad]; NaN open loop.
    pub reference: Vec<f64>,
    /// Tracking error θz_ref − θz [rad]; NaN open loop.
    pub error: Vec<f64>,
    /// Friction feedforward voltage [V]; NaN open loop.
    pub u_ff: Vec<f64>,
    /// Estimated friction torque [N·m]; NaN open loop.
    pub tf_hat: Vec<f64>,
    /// Estimated transmitted torque [N·m]; NaN open loop.
    pub tb_hat: Vec<f64>,
}

impl Trace {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether the trace is empty.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The columns in [`TRACE_COLUMNS`] order.
    pub fn columns(&self) -> impl Iterator<Item = &[f64]> {
        TRACE_COLUMNS.iter().map(move |c| c.of(self))
    }

    /// The trace as plain columns for writing (`trace.parquet`).
    pub fn to_table(&self) -> crate::OutTable {
        let mut t = crate::OutTable::default();
        for c in TRACE_COLUMNS {
            t.push(c.name, crate::Cells::F64(c.of(self).to_vec()));
        }
        t
    }

    /// Keep every `k`-th sample (k ≥ 1), always keeping the last.
    pub fn decimate(&self, k: usize) -> Trace {
        let k = k.max(1);
        let n = self.len();
        let keep: Vec<usize> = (0..n).filter(|&j| j % k == 0 || j + 1 == n).collect();
        let mut out = Trace::default();
        for c in TRACE_COLUMNS {
            let src = c.of(self);
            *c.of_mut(&mut out) = keep.iter().map(|&j| src[j]).collect();
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every field of `Trace` has exactly one column, and each column reads its own field.
    #[test]
    fn columns_cover_every_field_once() {
        let mut t = Trace::default();
        for (k, c) in TRACE_COLUMNS.iter().enumerate() {
            c.of_mut(&mut t).push(k as f64);
        }
        for (k, c) in TRACE_COLUMNS.iter().enumerate() {
            assert_eq!(c.of(&t), &[k as f64], "{}", c.name);
        }
        assert_eq!(format!("{t:?}").matches(": [").count(), TRACE_COLUMNS.len());
    }
}
