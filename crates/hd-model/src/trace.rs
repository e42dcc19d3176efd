//! The sampled time series of a run (the columns of `trace.parquet`).

use serde::{Deserialize, Serialize};

/// Names of the trace columns, in output order, with their units.
pub const TRACE_COLUMNS: [(&str, &str); 14] = [
    ("t", "s"),
    ("u", "V"),
    ("i", "A"),
    ("theta_j", "rad"),
    ("omega_j", "rad/s"),
    ("theta_z", "rad"),
    ("omega_z", "rad/s"),
    ("theta", "rad"),
    ("z", "N·m"),
    ("s", "rad"),
    ("Tb", "N·m"),
    ("Tf", "N·m"),
    ("K", "N·m/rad"),
    ("C0", "N·m·s/rad"),
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
    pub fn columns(&self) -> [&[f64]; 14] {
        [
            &self.t,
            &self.u,
            &self.i,
            &self.theta_j,
            &self.omega_j,
            &self.theta_z,
            &self.omega_z,
            &self.theta,
            &self.z,
            &self.s,
            &self.tb,
            &self.tf,
            &self.k,
            &self.c0,
        ]
    }

    /// Keep every `k`-th sample (k ≥ 1), always keeping the last.
    pub fn decimate(&self, k: usize) -> Trace {
        let k = k.max(1);
        let n = self.len();
        let keep: Vec<usize> = (0..n).filter(|&j| j % k == 0 || j + 1 == n).collect();
        let pick = |c: &Vec<f64>| keep.iter().map(|&j| c[j]).collect::<Vec<f64>>();
        Trace {
            t: pick(&self.t),
            u: pick(&self.u),
            i: pick(&self.i),
            theta_j: pick(&self.theta_j),
            omega_j: pick(&self.omega_j),
            theta_z: pick(&self.theta_z),
            omega_z: pick(&self.omega_z),
            theta: pick(&self.theta),
            z: pick(&self.z),
            s: pick(&self.s),
            tb: pick(&self.tb),
            tf: pick(&self.tf),
            k: pick(&self.k),
            c0: pick(&self.c0),
        }
    }
}
