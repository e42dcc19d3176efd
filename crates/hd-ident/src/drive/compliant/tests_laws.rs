//! The compliant drive with the other gear laws (Bouc–Wen, Maxwell-slip): against hd-model's
//! own solver of the same drive (`stiffness = "bouc-wen"`, `"maxwell-slip"`), its exact
//! derivatives against central differences, and fits that recover the gear from records
//! of it; and the friction levels that differ by direction.

use super::fit::{CompliantFit, CompliantSpec, substeps_for};
use super::model::{Compliant, P, ix::*};
use super::record::Between;
use super::tests::{
    assert_jacobian_matches, assert_matches_reference, chirp_reference_of, drive_with,
    fit_and_judge, jacobian_spec, off_start, record, rig_record, test_spec,
};
use hd_model::{HystLaw, Params};

/// The seed drive with gear law `law` at hd-model's defaults (Bouc–Wen: α = 4e4 N·m/rad,
/// A = 1, β = γ = 5e4 1/rad, n = 1, saturating at 1e-5 rad and 0.4 N·m; Maxwell-slip: 8
/// elements of 4e4 N·m/rad in all, yielding up to 2e-5 rad), as a params set and in
/// [`NAMES`] order.
fn drive_of(law: HystLaw) -> (Params, [f64; P]) {
    drive_with(Params::default(), law)
}

/// The fit's integration of the drive with gear law `law` against hd-model's adaptive solve
/// (rtol 1e-11) of the same drive under a 0.4 s, 2–60 Hz chirp at 1 kHz: each output within
/// `largest` of its RMS at the substeps the fit picks, and twice the substeps cutting every
/// difference by more than `factor`.
fn matches_the_simulator_with(law: HystLaw, largest: f64, factor: f64) {
    matches_the_simulator_at(drive_of(law), law, largest, factor);
}

/// [`matches_the_simulator_with`] for the drive `(params, v)` ([`drive_with`]).
fn matches_the_simulator_at(
    (params, v): (Params, [f64; P]),
    law: HystLaw,
    largest: f64,
    factor: f64,
) {
    let h = 1e-3;
    let cols = chirp_reference_of(&params, law, 0.4, h, 12.0, 60.0);
    let rec = record(&cols, "ref");
    assert_matches_reference(&Compliant::new(v, params.n), &rec, largest, factor);
}

/// Measured: 1.9e-8, 1.9e-8 and 3.5e-8 at 20 substeps, 8.4e-9, 8.4e-9 and 7.2e-9 at 40
/// (the integration's error and the comparison's floor, not a model difference).
#[test]
fn bouc_wen_matches_the_simulator() {
    matches_the_simulator_with(HystLaw::BoucWen, 3e-7, 4.0);
}

/// The slip elements are held over a substep and moved along it as if the deflection were
/// monotone there (hd-model splits the step at its turning points). Measured: 1.9e-8,
/// 2.0e-8 and 3.5e-8 at 20 substeps, 8.5e-9, 8.5e-9 and 7.2e-9 at 40.
#[test]
fn maxwell_slip_matches_the_simulator() {
    matches_the_simulator_with(HystLaw::MaxwellSlip, 3e-7, 4.0);
}

/// The Jacobian from dual numbers against central differences of the plain simulation of
/// the drive with gear law `law` on the columns `free_idx` (0.15 s of a 2–60 Hz chirp):
/// each column non-zero and within `tolerance` of the differences (relative RMS).
fn exact_derivatives_with(law: HystLaw, free_idx: &[usize], tolerance: f64) {
    exact_derivatives_at(drive_of(law), law, free_idx, tolerance, true);
}

/// [`exact_derivatives_with`] for the drive `(params, start)` ([`drive_with`]), its friction
/// levels tied across directions or not (`symmetric`).
fn exact_derivatives_at(
    (params, start): (Params, [f64; P]),
    law: HystLaw,
    free_idx: &[usize],
    tolerance: f64,
    symmetric: bool,
) {
    let h = 1e-3;
    let cols = chirp_reference_of(&params, law, 0.15, h, 12.0, 60.0);
    let rec = record(&cols, "ref");
    let fv = hd_model::FrictionVelocity::Motor;
    let spec = jacobian_spec(params.n, start, fv, symmetric, 8);
    assert_jacobian_matches(&spec, &start, free_idx, &rec, tolerance);
}

/// Measured: at most 2e-6 on the gear's columns and Cz; 7.0e-5 on Jz, whose differences
/// cross the element's switches (sgn(θ̇·h)), where a central difference is not exact.
#[test]
fn bouc_wen_exact_derivatives() {
    let free = [JZ, CZ, C, BW_ALPHA, BW_A, BW_BETA, BW_GAMMA, BW_N];
    exact_derivatives_with(HystLaw::BoucWen, &free, 7e-4);
}

/// The elements' torque is piecewise linear in θ and the offsets move by the play
/// operator: the recursion's derivative is exact between its switches. Measured: at most
/// 1.2e-5 (Cz), 1.3e-6 on ms_delta, 1.1e-7 on ms_k.
#[test]
fn maxwell_slip_exact_derivatives() {
    exact_derivatives_with(HystLaw::MaxwellSlip, &[JZ, CZ, C, MS_K, MS_DELTA], 2e-4);
}

/// The drive with gear law `law` fitted to a chirp through the gear's resonance (2–450 Hz,
/// 12 V, 1 s at 1 kHz) logged as a rig logs it (4096-count motor encoder, 2^20-count load
/// encoder, current with 1 % noise), from a start 25–30 % off on the motor, the load, the
/// friction and the gear (c and `gear`): the residuals sit at the noise (≤ 1.2×) and every
/// parameter reported as determined lies within 3 standard errors of the truth.
fn fit_with(law: HystLaw, gear: &[usize]) -> CompliantFit {
    let h = 1e-3;
    let (params, truth) = drive_of(law);
    let (rec, outputs) = rig_record(chirp_reference_of(&params, law, 1.0, h, 12.0, 450.0), 11);
    let free_idx: Vec<usize> = [R, KE, JJ, JZ, CJ, CZ, C]
        .into_iter()
        .chain(gear.iter().copied())
        .chain([SIGMA0, TC])
        .collect();
    let (start, free, lower, upper) = off_start(&truth, &free_idx);
    let m = substeps_for(&start, params.n, h);
    let spec = CompliantSpec {
        free,
        lower,
        upper,
        between: Between::Linear,
        ..test_spec(params.n, start, outputs, m)
    };
    fit_and_judge(&spec, rec, &truth, &free_idx)
}

/// The Bouc–Wen element's shape (β, γ) is among the determined parameters (measured: 0.80
/// and 1.22 standard errors off).
#[test]
fn fits_a_bouc_wen_gear() {
    let fit = fit_with(HystLaw::BoucWen, &[BW_ALPHA, BW_BETA, BW_GAMMA]);
    assert!(fit.determined[BW_BETA] && fit.determined[BW_GAMMA], "the loop's shape is seen");
}

/// The slip elements' yield deflection is among the determined parameters (measured:
/// 2.022e-5 ± 5.8e-7 rad, 0.37 standard errors off).
#[test]
fn fits_a_maxwell_slip_gear() {
    let fit = fit_with(HystLaw::MaxwellSlip, &[MS_K, MS_DELTA]);
    assert!(fit.determined[MS_DELTA], "the elements' yield is seen");
}

/// Friction levels that differ by direction (Tc_neg = 0.1, Ts_neg = 0.18 N·m against Tc =
/// 0.15, Ts = 0.25): the fit's drive matches hd-model's solve of the same drive as closely
/// as the symmetric one does, and its exact Jacobian matches central differences on the
/// four levels and ωs (measured: 1.0e-4 at 20 substeps against hd-model; at most 4.4e-7
/// against the differences).
#[test]
fn direction_dependent_friction() {
    let p = Params { tc_neg: Some(0.1), ts_neg: Some(0.18), ..Params::default() };
    let drive = drive_with(p, HystLaw::Memory);
    assert_eq!((drive.1[TC_NEG], drive.1[TS_NEG]), (0.1, 0.18));
    matches_the_simulator_at(drive.clone(), HystLaw::Memory, 1e-3, 4.0);
    exact_derivatives_at(drive, HystLaw::Memory, &[TC, TS, WS, TC_NEG, TS_NEG], 5e-6, false);
}

/// The seed drive with a catalogue gear whose corners the 12 V chirps reach (K1 = 4e4,
/// K2 = 8e4, K3 = 1.2e5 N·m/rad, T1 = 0.15, T2 = 0.35 N·m: a data sheet's curve scaled to the
/// seed's torques), no hysteresis loss.
fn catalogue_drive() -> (Params, [f64; P]) {
    let p = Params {
        cat_k1: 4e4,
        cat_k2: 8e4,
        cat_k3: 1.2e5,
        cat_t1: 0.15,
        cat_t2: 0.35,
        ..Params::default()
    };
    drive_with(p, HystLaw::Catalogue)
}

/// The rounded three-segment curve in the fit's drive against hd-model's solve of the same
/// drive (`stiffness = "catalogue"`). Measured: 2.8e-8, 2.9e-8 and 3.2e-8 at 23 substeps,
/// 1.0e-8, 1.0e-8 and 7.5e-9 at 46.
#[test]
fn catalogue_matches_the_simulator() {
    matches_the_simulator_at(catalogue_drive(), HystLaw::Catalogue, 3e-7, 4.0);
}

/// The curve's derivatives (hd-model's `torque_grad`, lifted) against central differences
/// of the plain simulation, the chirp crossing both corners. Measured: at most 8.9e-7 on
/// the curve's five columns, 7.5e-6 on Cz.
#[test]
fn catalogue_exact_derivatives() {
    let free = [JZ, CZ, CAT_K1, CAT_K2, CAT_K3, CAT_T1, CAT_T2];
    exact_derivatives_at(catalogue_drive(), HystLaw::Catalogue, &free, 1e-4, true);
}
