//! The armature-controlled DC motor (docs/model.md §2.6).

use crate::fma::fmadd;
use serde::{Deserialize, Serialize};

/// DC motor: `u = R·i + L·di/dt + Ke·ωj`, `Tj = Km·i`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DcMotor {
    /// Armature resistance R [Ω].
    pub r: f64,
    /// Torque constant Km [N·m/A].
    pub km: f64,
    /// Back-EMF constant Ke [V·s/rad].
    pub ke: f64,
    /// Armature inductance L [H]; 0 makes the current algebraic.
    pub l: f64,
}

impl DcMotor {
    /// Whether the current is a state (L > 0).
    pub fn has_inductance(&self) -> bool {
        self.l > 0.0
    }
    /// Algebraic current without inductance, `(u − Ke·ωj)/R` [A].
    pub fn static_current(&self, u: f64, omega_j: f64) -> f64 {
        // 1/R does not depend on the state: its division is off the critical path.
        fmadd(-self.ke, omega_j, u) * (1.0 / self.r)
    }
    /// Current rate with inductance, `(u − R·i − Ke·ωj)/L` [A/s].
    pub fn current_rate(&self, u: f64, i: f64, omega_j: f64) -> f64 {
        (u - self.r * i - self.ke * omega_j) / self.l
    }
    /// Motor torque `Km·i` [N·m].
    pub fn torque(&self, i: f64) -> f64 {
        self.km * i
    }
}
