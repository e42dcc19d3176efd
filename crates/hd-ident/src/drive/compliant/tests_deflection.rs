//! Friction across the gear (`friction_velocity = "deflection"`: v = θ̇ = ωj/N − ωz, Tf/N
//! on the motor and +Tf on the load): the fit's drive against hd-model's solve of the same
//! drive, and its exact derivatives against central differences.

use super::model::{Compliant, P, ix::*};
use super::tests::{
    assert_jacobian_matches, assert_matches_reference, chirp_reference_with, drive_with,
    jacobian_spec, record,
};
use hd_model::{FrictionVelocity, HystLaw, Params};

/// The seed drive with its friction across the gear: levels 0.5 and 0.8 N·m on a bristle
/// softer than the gear (σ0 = 5e4 N·m/rad), so that it slides within the gear's small
/// deflections (a stiffer, stronger one locks the gear, and then no level shows).
fn across() -> (Params, [f64; P]) {
    let p = Params { tc: 0.5, ts: 0.8, ws: 1e-3, sigma0: 5e4, sigma1: 2.0, ..Params::default() };
    drive_with(p, HystLaw::Memory)
}

/// hd-model's solve (rtol 1e-11) under a 2 Hz → 60 Hz, 12 V chirp over `t_end` seconds.
fn reference(t_end: f64) -> [Vec<f64>; 5] {
    let (params, _) = across();
    let fv = FrictionVelocity::Deflection;
    chirp_reference_with(&params, HystLaw::Memory, fv, t_end, 1e-3, 12.0, 60.0)
}

/// The fit's integration against hd-model's over 0.4 s: each output within 1e-8 of its RMS
/// at the substeps the fit picks, and twice as many cutting every difference by more than 4.
/// Measured: 8.3e-13 (motor), 7.7e-10 (load), 4.3e-11 (current) at 20 substeps, 8 to 20
/// times less at 40.
#[test]
fn friction_across_the_gear_matches_the_simulator() {
    let (params, v) = across();
    let rec = record(&reference(0.4), "ref");
    let d = Compliant::new(v, params.n).with_friction_velocity(FrictionVelocity::Deflection);
    assert_matches_reference(&d, &rec, 1e-8, 4.0);
}

/// The exact Jacobian against central differences on the friction and the gear, over
/// 0.15 s. Measured: at most 3.5e-5 (ωs, a column the differences' rounding reaches), the
/// gear's and the bristle's columns at 2.3e-7 and less.
#[test]
fn friction_across_the_gear_exact_derivatives() {
    let (_, v) = across();
    let rec = record(&reference(0.15), "ref");
    let fv = FrictionVelocity::Deflection;
    let spec = jacobian_spec(Params::default().n, v, fv, true, 16);
    let free = [TC, TS, WS, SIGMA0, SIGMA1, C, MEM_A, JZ];
    assert_jacobian_matches(&spec, &v, &free, &rec, 1e-4);
}
