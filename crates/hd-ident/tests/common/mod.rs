//! Helpers shared by the recovery tests (included with `mod common;`).
#![allow(dead_code)]

use hd_ident::synth::{HysteresisExcitation, Noise, SteadySweep, TransientExcitation};
use hd_ident::synth::{synth_hysteresis, synth_steady, synth_transient};
use hd_ident::{FitReport, HysteresisData, SteadyData, TransientData};
use hd_model::Params;

/// Parameters from `NAME=VALUE` assignments over the defaults.
pub fn params(sets: &[&str]) -> Params {
    let mut p = Params::default();
    for s in sets {
        p.apply_assignment(s).unwrap();
    }
    p
}

pub fn hysteresis_data(p: &Params, exc: &HysteresisExcitation, noise: Noise) -> HysteresisData {
    let c = synth_hysteresis(p, exc, &noise).unwrap().columns;
    HysteresisData::new(c[0].clone(), c[1].clone(), c[2].clone()).unwrap()
}

pub fn steady_data(p: &Params, noise: Noise) -> SteadyData {
    let c = synth_steady(p, &SteadySweep::default(), &noise).unwrap().columns;
    SteadyData::new(c[0].clone(), c[1].clone()).unwrap()
}

pub fn transient_data(p: &Params, noise: Noise) -> TransientData {
    let c = synth_transient(p, &TransientExcitation::default(), &noise).unwrap().columns;
    TransientData::new(c[0].clone(), c[1].clone(), c[2].clone()).unwrap()
}

/// Relative error of `name` against the truth in `p`; prints it for the record.
pub fn rel_error(r: &FitReport, p: &Params, name: &str) -> f64 {
    let e = r.parameters.get(name).unwrap();
    let truth = p.get(name).unwrap();
    let rel = (e.value / truth - 1.0).abs();
    println!(
        "{}: {name} = {:.6e} (truth {truth:e}), error {:.3} %, std error {:.3} %, ci95 {:?}",
        r.fit,
        e.value,
        100.0 * rel,
        100.0 * e.std_error.unwrap_or(f64::NAN) / e.value.abs(),
        e.ci95
    );
    rel
}

/// Whether the 95 % interval of `name` holds the truth.
pub fn covers(r: &FitReport, p: &Params, name: &str) -> bool {
    let truth = p.get(name).unwrap();
    r.parameters.get(name).unwrap().ci95.is_some_and(|[lo, hi]| lo <= truth && truth <= hi)
}

/// The default joint-test profile: 8 levels from 1e-3 to 1 rad/s, 0.25 s dwell, 0.05 s
/// transitions, sampled at 5 kHz (24 751 samples).
pub fn joint_profile() -> hd_ident::synth::PlateauProfile {
    hd_ident::synth::PlateauProfile {
        omega_min: 1e-3,
        omega_max: 1.0,
        levels: 8,
        dwell: 0.25,
        transition: 0.05,
    }
}

pub fn joint_data(p: &Params, noise: Noise) -> TransientData {
    let c = hd_ident::synth::synth_plateaus(p, &joint_profile(), 2e-4, &noise).unwrap().columns;
    TransientData::new(c[0].clone(), c[1].clone(), c[2].clone()).unwrap()
}
