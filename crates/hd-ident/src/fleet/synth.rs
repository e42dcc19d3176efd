//! The truth of a synthetic fleet: robots × joints, one friction test per unit and day.
//!
//! Each unit draws its own static levels, Stribeck speed and viscous coefficient around
//! the base values (log-normal, relative spread `unit_spread`). The ambient temperature
//! of each robot cycles `T = T₀ + A·sin(2π·day/P + φ_robot) + weather`, with the weather
//! Gaussian of `temp_noise` K; every parameter p then follows
//! `p = p_unit · exp(c_p·(T − T₀)) · wear(day) · (1 + day_scatter·ε)`, where c_p is its
//! stated effect per kelvin (−0.006 /K is −0.6 %/K to first order), ε a standard normal
//! draw per log, and `wear` 1 until the onset, then rising linearly by `wear_pct` over
//! `wear_days` and held there. Wear raises Tc, Ts and σ2 alike.

use hd_model::Params;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A wearing unit.
#[derive(Clone, Debug, PartialEq)]
pub struct Wear {
    /// Robot (0-based).
    pub robot: usize,
    /// Joint (0-based).
    pub joint: usize,
    /// First day of the wear [day].
    pub onset: f64,
}

/// The fleet to make.
#[derive(Clone, Debug, PartialEq)]
pub struct FleetSpec {
    /// Robots.
    pub robots: usize,
    /// Joints per robot.
    pub joints: usize,
    /// Days (one log per unit and day).
    pub days: usize,
    /// Mean ambient temperature T₀ [°C].
    pub temp_mean: f64,
    /// Amplitude of the temperature cycle [K].
    pub temp_amplitude: f64,
    /// Period of the temperature cycle [days].
    pub temp_period: f64,
    /// Day-to-day weather on top of the cycle, standard deviation [K].
    pub temp_noise: f64,
    /// Effect of temperature on Tc and Ts, log scale [1/K].
    pub coef_levels: f64,
    /// Effect of temperature on σ2, log scale [1/K].
    pub coef_viscous: f64,
    /// Relative spread of the units' own parameters [–].
    pub unit_spread: f64,
    /// Relative day-to-day scatter of every parameter, not explained by temperature [–].
    pub day_scatter: f64,
    /// Wear: relative rise of Tc, Ts, σ2 at the end of the ramp [–].
    pub wear_rise: f64,
    /// Wear: length of the ramp [days].
    pub wear_days: f64,
    /// Wearing units.
    pub wear: Vec<Wear>,
    /// Base parameters (σ0, σ1 kept as they are).
    pub base: Params,
    /// Seed of the random draws.
    pub seed: u64,
}

impl Default for FleetSpec {
    fn default() -> Self {
        let base = Params { sigma2: 0.05, ..Default::default() };
        Self {
            robots: 4,
            joints: 3,
            days: 60,
            temp_mean: 25.0,
            temp_amplitude: 10.0,
            temp_period: 15.0,
            temp_noise: 1.0,
            coef_levels: -0.006,
            coef_viscous: -0.02,
            unit_spread: 0.1,
            day_scatter: 0.003,
            wear_rise: 0.15,
            wear_days: 20.0,
            wear: vec![
                Wear { robot: 1, joint: 0, onset: 30.0 },
                Wear { robot: 3, joint: 2, onset: 38.0 },
            ],
            base,
            seed: 1,
        }
    }
}

/// One log's truth.
#[derive(Clone, Debug, PartialEq)]
pub struct LogTruth {
    /// Robot (0-based).
    pub robot: usize,
    /// Joint (0-based).
    pub joint: usize,
    /// Day [day].
    pub day: usize,
    /// Ambient temperature [°C].
    pub temperature: f64,
    /// Wear factor of Tc, Ts, σ2 [–].
    pub wear: f64,
    /// The true parameters of the log.
    pub params: Params,
    /// Seed for this log's measurement noise.
    pub noise_seed: u64,
}

fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    let u1 = 1.0 - rng.random::<f64>();
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

impl FleetSpec {
    /// The wear factor of a unit on a day.
    pub fn wear_at(&self, robot: usize, joint: usize, day: f64) -> f64 {
        self.wear.iter().find(|w| w.robot == robot && w.joint == joint).map_or(1.0, |w| {
            1.0 + self.wear_rise * ((day - w.onset) / self.wear_days).clamp(0.0, 1.0)
        })
    }

    /// Every log's truth, ordered by day, robot, joint.
    pub fn truth(&self) -> Vec<LogTruth> {
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        let units: Vec<[f64; 4]> = (0..self.robots * self.joints)
            .map(|_| std::array::from_fn(|_| (self.unit_spread * gauss(&mut rng)).exp()))
            .collect();
        let phases: Vec<f64> =
            (0..self.robots).map(|_| std::f64::consts::TAU * rng.random::<f64>()).collect();
        let mut out = Vec::with_capacity(self.days * units.len());
        for day in 0..self.days {
            for robot in 0..self.robots {
                let cycle =
                    (std::f64::consts::TAU * day as f64 / self.temp_period + phases[robot]).sin();
                let temp = self.temp_mean
                    + self.temp_amplitude * cycle
                    + self.temp_noise * gauss(&mut rng);
                let dt = temp - self.temp_mean;
                for joint in 0..self.joints {
                    let u = units[robot * self.joints + joint];
                    let wear = self.wear_at(robot, joint, day as f64);
                    let mut scatter = || 1.0 + self.day_scatter * gauss(&mut rng);
                    let mut p = self.base.clone();
                    let levels = (self.coef_levels * dt).exp() * wear;
                    p.tc = self.base.tc * u[0] * levels * scatter();
                    // Ts keeps its ratio to Tc of the unit, scattered on its own.
                    p.ts = self.base.ts * u[0] * u[1].sqrt() * levels * scatter();
                    p.ws = self.base.ws * u[2];
                    p.sigma2 =
                        self.base.sigma2 * u[3] * (self.coef_viscous * dt).exp() * wear * scatter();
                    out.push(LogTruth {
                        robot,
                        joint,
                        day,
                        temperature: temp,
                        wear,
                        params: p,
                        noise_seed: rng.random::<u64>(),
                    });
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_truth_carries_the_stated_temperature_effect_and_wear() {
        let spec = FleetSpec { day_scatter: 0.0, temp_noise: 0.0, ..Default::default() };
        let t = spec.truth();
        assert_eq!(t.len(), 720);
        // Same unit, two days: the ratio of Tc is exp(c·ΔT) (no wear on unit 0/0).
        let a = t.iter().find(|l| l.robot == 0 && l.joint == 0 && l.day == 3).unwrap();
        let b = t.iter().find(|l| l.robot == 0 && l.joint == 0 && l.day == 9).unwrap();
        let r = b.params.tc / a.params.tc;
        let want = (-0.006 * (b.temperature - a.temperature)).exp();
        assert!((r / want - 1.0).abs() < 1e-12, "{r} vs {want}");
        let rv = b.params.sigma2 / a.params.sigma2;
        assert!((rv / (-0.02 * (b.temperature - a.temperature)).exp() - 1.0).abs() < 1e-12);
        assert_eq!(spec.wear_at(1, 0, 29.0), 1.0);
        assert!((spec.wear_at(1, 0, 40.0) - 1.075).abs() < 1e-12);
        assert!((spec.wear_at(1, 0, 59.0) - 1.15).abs() < 1e-12);
        assert_eq!(spec.wear_at(0, 0, 59.0), 1.0);
    }
}
