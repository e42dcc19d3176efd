//! The one table of metric columns: name, unit, description and the field it reads. The
//! JSON of [`Metrics`] (metrics.json, study rows), the Parquet columns, their units and the
//! column docs all come from [`METRICS`].

use super::Metrics;
use serde::de::{Deserializer, MapAccess, Visitor};
use serde::ser::{SerializeMap, Serializer};
use serde::{Deserialize, Serialize};

/// One metric column.
#[derive(Clone, Copy, Debug)]
pub struct MetricColumn {
    /// Column name.
    pub name: &'static str,
    /// SI unit (`-` for a ratio or a count).
    pub unit: &'static str,
    /// One-line description.
    pub doc: &'static str,
    get: fn(&Metrics) -> f64,
    set: fn(&mut Metrics, f64),
}

impl MetricColumn {
    /// The value of this metric in `m`.
    pub fn get(&self, m: &Metrics) -> f64 {
        (self.get)(m)
    }

    /// Set this metric in `m`.
    pub fn set(&self, m: &mut Metrics, v: f64) {
        (self.set)(m, v)
    }
}

macro_rules! m {
    ($name:literal, $field:ident, $unit:literal, $doc:literal) => {
        MetricColumn {
            name: $name,
            unit: $unit,
            doc: $doc,
            get: |m| m.$field,
            set: |m, v| m.$field = v,
        }
    };
}

/// Every metric, in output order.
pub static METRICS: &[MetricColumn] = &[
    m!("thz_amp", thz_amp, "rad", "half peak-to-peak of θz over the window (periodic runs)"),
    m!("thz_mean", thz_mean, "rad", "mean of θz over the window (periodic runs)"),
    m!(
        "thz_ripple",
        thz_ripple,
        "rad",
        "RMS of θz after removing the mean and the fundamental at the drive frequency"
    ),
    m!(
        "hyst_loss_per_cycle",
        hyst_loss_per_cycle,
        "J",
        "energy dissipated per cycle by the hysteretic part of the stiffness, ∮ z dθ"
    ),
    m!(
        "friction_loss_per_cycle",
        friction_loss_per_cycle,
        "J",
        "energy dissipated per cycle by friction, ∮ Tf·v dt"
    ),
    m!(
        "efficiency",
        efficiency,
        "-",
        "positive output work over positive input work at the wave generator"
    ),
    m!(
        "gain_db",
        gain_db,
        "dB",
        "gain of θz's fundamental over the drive's: over u open loop (re 1 rad/V), over θz_ref closed loop"
    ),
    m!(
        "phase_deg",
        phase_deg,
        "deg",
        "phase of θz's fundamental minus the drive's (u open loop, θz_ref closed loop), in (−180, 180]"
    ),
    m!("cycles_used", cycles_used, "-", "number of whole cycles the periodic metrics used"),
    m!("rise_time", rise_time, "s", "10 %–90 % rise time of the load speed after a step"),
    m!(
        "overshoot",
        overshoot,
        "-",
        "peak load speed above its final value, as a fraction of it (0.05 = 5 %)"
    ),
    m!(
        "settling_time",
        settling_time,
        "s",
        "time after the step until the load speed stays within the settling band"
    ),
    m!(
        "damping_ratio",
        damping_ratio,
        "-",
        "damping ratio from the logarithmic decrement of the deflection oscillation"
    ),
    m!(
        "final_speed",
        final_speed,
        "rad/s",
        "mean load speed over the final window (step and constant inputs)"
    ),
    m!(
        "limit_cycle",
        limit_cycle,
        "-",
        "1 if a persistent oscillation of the load speed remains in the final window, else 0 (constant and step inputs)"
    ),
    m!("lc_amplitude", lc_amplitude, "rad/s", "half peak-to-peak of the limit-cycle oscillation"),
    m!("lc_period", lc_period, "s", "period of the limit-cycle oscillation"),
    m!("thz_peak", thz_peak, "rad", "largest |θz| over the run"),
    m!("tb_peak", tb_peak, "N·m", "largest |Tb| over the run"),
    m!(
        "tf_peak",
        tf_peak,
        "N·m",
        "largest |Tf| over the run (the break-away peak after a start from rest)"
    ),
    m!(
        "s_peak",
        s_peak,
        "rad",
        "largest |s|, the LuGre bristle (pre-sliding) deflection, over the run"
    ),
    m!(
        "energy_residual",
        energy_residual,
        "-",
        "energy-balance residual over the run, relative to the energy turned over"
    ),
    m!(
        "track_rms",
        track_rms,
        "rad",
        "closed loop: RMS of the tracking error θz_ref − θz after the first reference period (after the move for point-to-point references)"
    ),
    m!("track_max", track_max, "rad", "closed loop: largest |θz_ref − θz| in the same window"),
    m!(
        "reversal_peak",
        reversal_peak,
        "rad",
        "closed loop: largest |tracking error| within the reversal window after each reversal of the reference speed"
    ),
    m!("u_rms", u_rms, "V", "closed loop: RMS of the voltage command in the tracking window"),
    m!(
        "saturation_fraction",
        saturation_fraction,
        "-",
        "closed loop: fraction of the tracking window with the command clipped at ±u_max"
    ),
    m!(
        "torque_est_rms",
        torque_est_rms,
        "N·m",
        "closed loop: RMS error of the transmitted-torque estimate (motor equation and friction observer) against Tb"
    ),
    m!(
        "torque_est_rms_nofric",
        torque_est_rms_nofric,
        "N·m",
        "closed loop: RMS error of the transmitted-torque estimate without the friction model against Tb"
    ),
    m!(
        "steady_error",
        steady_error,
        "rad",
        "closed-loop regulation: mean tracking error over the final window"
    ),
    m!(
        "hunting",
        hunting,
        "-",
        "closed-loop regulation: 1 if the tracking error keeps oscillating in the final window (limit cycle), else 0"
    ),
    m!(
        "hunt_amplitude",
        hunt_amplitude,
        "rad",
        "closed-loop regulation: half peak-to-peak of the tracking error over the final window"
    ),
    m!(
        "hunt_period",
        hunt_period,
        "s",
        "closed-loop regulation: period of the hunting oscillation"
    ),
];

/// Looks a metric up by name.
pub fn metric(name: &str) -> Option<&'static MetricColumn> {
    METRICS.iter().find(|m| m.name == name)
}

impl Serialize for Metrics {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(METRICS.len()))?;
        for m in METRICS {
            let v = m.get(self);
            // Undefined metrics are null, never a made-up number.
            map.serialize_entry(m.name, &v.is_finite().then_some(v))?;
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for Metrics {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Fields;
        impl<'de> Visitor<'de> for Fields {
            type Value = Metrics;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a map of metric names to numbers or null")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Metrics, A::Error> {
                let mut out = Metrics::undefined();
                while let Some(name) = map.next_key::<String>()? {
                    let col = metric(&name).ok_or_else(|| {
                        serde::de::Error::custom(format!("unknown metric '{name}'"))
                    })?;
                    let v: Option<f64> = map.next_value()?;
                    col.set(&mut out, v.unwrap_or(f64::NAN));
                }
                Ok(out)
            }
        }
        deserializer.deserialize_map(Fields)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Names, getters and setters line up: a distinct value per metric goes in through
    /// each setter and comes back out under the same name, in JSON and through `get`.
    #[test]
    fn names_units_and_values_line_up() {
        let mut m = Metrics::undefined();
        for (k, col) in METRICS.iter().enumerate() {
            col.set(&mut m, k as f64 + 0.5);
        }
        let json = serde_json::to_value(m).unwrap();
        let obj = json.as_object().unwrap();
        assert_eq!(obj.len(), METRICS.len());
        for (k, col) in METRICS.iter().enumerate() {
            assert_eq!(col.get(&m), k as f64 + 0.5, "{}", col.name);
            assert_eq!(obj[col.name].as_f64(), Some(k as f64 + 0.5), "{}", col.name);
            assert!(!col.unit.is_empty() && !col.doc.is_empty(), "{}", col.name);
        }
        let back: Metrics = serde_json::from_value(json).unwrap();
        assert_eq!(back, m);
        // Every field of the struct has a column (the Debug text lists each field once).
        assert_eq!(format!("{m:?}").matches(": ").count(), METRICS.len());
    }

    #[test]
    fn undefined_metrics_are_null_and_unknown_names_are_errors() {
        let json = serde_json::to_value(Metrics::undefined()).unwrap();
        assert!(json["thz_amp"].is_null());
        let e = serde_json::from_str::<Metrics>(r#"{"thz_amps": 1.0}"#).unwrap_err();
        assert!(e.to_string().contains("unknown metric 'thz_amps'"), "{e}");
    }
}
