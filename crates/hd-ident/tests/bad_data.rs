//! Every kind of bad data or bad request is an error that says what is wrong.

use hd_ident::{
    DataError, FitError, Fixed, HysteresisData, SteadyData, TransientData, fit_friction,
    fit_hysteresis,
};

fn ramp(n: usize) -> Vec<f64> {
    (0..n).map(|i| i as f64 * 1e-3).collect()
}

fn wave(n: usize) -> Vec<f64> {
    (0..n).map(|i| 1e-3 * (i as f64 * 0.1).sin()).collect()
}

#[test]
fn nan_and_infinite_values_name_column_and_row() {
    let mut theta = wave(100);
    theta[41] = f64::NAN;
    let e = HysteresisData::new(ramp(100), theta, wave(100)).unwrap_err();
    assert!(matches!(e, DataError::NonFinite { column: "theta", row: 42, .. }), "{e}");
    assert!(e.to_string().contains("row 42"));

    let mut torque = wave(100);
    torque[0] = f64::INFINITY;
    let e = TransientData::new(ramp(100), wave(100), torque).unwrap_err();
    assert!(matches!(e, DataError::NonFinite { column: "torque", row: 1, .. }), "{e}");

    let e = SteadyData::new(vec![1.0, f64::NEG_INFINITY], vec![0.1, 0.2]).unwrap_err();
    assert!(matches!(e, DataError::NonFinite { column: "omega", row: 2, .. }), "{e}");
}

#[test]
fn time_must_increase_strictly() {
    let mut t = ramp(50);
    t[20] = t[19]; // repeated
    let e = HysteresisData::new(t, wave(50), wave(50)).unwrap_err();
    assert!(matches!(e, DataError::NonIncreasingTime { row: 21, .. }), "{e}");
    assert!(e.to_string().contains("row 21"));

    let mut t = ramp(50);
    t[30] = 0.0; // going back
    let e = TransientData::new(t, wave(50), wave(50)).unwrap_err();
    assert!(matches!(e, DataError::NonIncreasingTime { row: 31, .. }), "{e}");
}

#[test]
fn columns_must_have_equal_lengths_and_content() {
    let e = HysteresisData::new(ramp(10), wave(9), wave(10)).unwrap_err();
    assert!(
        matches!(e, DataError::LengthMismatch { column: "theta", len: 9, expected: 10, .. }),
        "{e}"
    );
    assert_eq!(HysteresisData::new(vec![], vec![], vec![]).unwrap_err(), DataError::Empty);
    let e = HysteresisData::new(ramp(10), vec![0.5; 10], wave(10)).unwrap_err();
    assert!(matches!(e, DataError::Constant { column: "theta", .. }), "{e}");
    let e = SteadyData::new(vec![-1.0, 0.0, 1.0], vec![-0.2, 0.0, 0.2]).unwrap_err();
    assert_eq!(e, DataError::ZeroSpeed { row: 2 });
}

#[test]
fn too_few_samples_for_the_free_parameters() {
    // Five free parameters need 5 + 3 samples.
    let data = HysteresisData::new(ramp(7), wave(7), wave(7)).unwrap();
    let e = fit_hysteresis(&data, &Fixed::none()).unwrap_err();
    match &e {
        FitError::Data(DataError::TooFewSamples { have: 7, need: 8, free: 5, .. }) => {}
        other => panic!("{other}"),
    }
    assert!(e.to_string().contains("a, b, c, mem_A, mem_B"), "{e}");
    // Fixing three leaves two, which 7 samples suffice for.
    let fixed = Fixed::parse(&["a=0", "b=0", "B=300"]).unwrap();
    assert!(fit_hysteresis(&data, &fixed).is_ok());

    let steady = SteadyData::new(vec![-0.1, -0.01, 0.01, 0.1], vec![-0.2, -0.3, 0.3, 0.2]).unwrap();
    let e = fit_friction(Some(&steady), None, &Fixed::none()).unwrap_err();
    assert!(matches!(e, FitError::Data(DataError::TooFewSamples { have: 4, need: 7, .. })), "{e}");
}

#[test]
fn a_short_table_fits_with_a_warning() {
    // 38 points for the four static parameters: below ten per parameter, still a fit.
    let law = hd_model::laws::friction::LuGre::symmetric(1e5, 0.5, 0.02, 0.2, 0.35, 0.05);
    use hd_model::laws::friction::FrictionLaw;
    let omega: Vec<f64> = (0..38)
        .map(|k| {
            let w = 1e-3 * 10f64.powf(3.0 * (k % 19) as f64 / 18.0);
            if k < 19 { -w } else { w }
        })
        .collect();
    let torque: Vec<f64> = omega
        .iter()
        .enumerate()
        .map(|(k, &w)| law.steady_torque(w) * (1.0 + 0.002 * ((k * 7919 % 13) as f64 - 6.0) / 6.0))
        .collect();
    let steady = SteadyData::new(omega, torque).unwrap();
    let fit = fit_friction(Some(&steady), None, &Fixed::none()).unwrap();
    assert!(
        fit.report.remarks.iter().any(|r| r.contains("38 samples")),
        "{:?}",
        fit.report.remarks
    );
    let ts = fit.report.parameters.get("Ts").unwrap().value;
    assert!((ts / 0.35 - 1.0).abs() < 0.05, "Ts = {ts}");
}

#[test]
fn fixed_names_are_checked() {
    let e = Fixed::parse(&["sigma_0=1e5"]).unwrap_err();
    assert!(e.to_string().contains("did you mean 'sigma0'"), "{e}");
    let e = Fixed::parse(&["c=-5"]).unwrap_err();
    assert!(e.to_string().contains("expected"), "{e}");
    let e = Fixed::parse(&["B300"]).unwrap_err();
    assert!(e.to_string().contains("NAME=VALUE"), "{e}");

    let data = HysteresisData::new(ramp(100), wave(100), wave(100)).unwrap();
    let e = fit_hysteresis(&data, &Fixed::parse(&["sigma0=1e5"]).unwrap()).unwrap_err();
    assert!(matches!(e, FitError::NotInFit { fit: "hysteresis", .. }), "{e}");
    let all = Fixed::parse(&["a=0", "b=0", "c=5e4", "A=4e4", "B=300"]).unwrap();
    assert!(matches!(fit_hysteresis(&data, &all).unwrap_err(), FitError::NothingFree { .. }));
}

#[test]
fn friction_data_and_names_are_checked() {
    // A series alone fits whatever is not fixed; the fixed value is kept as given.
    let data = TransientData::new(ramp(100), wave(100), wave(100)).unwrap();
    let fit = fit_friction(None, Some(&data), &Fixed::parse(&["Tc=0.1"]).unwrap()).unwrap();
    let tc = fit.report.parameters.get("Tc").unwrap();
    assert!(tc.fixed && tc.value == 0.1);
    // Negative-side levels belong to the asymmetric fit only.
    let e = fit_friction(None, Some(&data), &Fixed::parse(&["Tc_neg=0.1"]).unwrap()).unwrap_err();
    assert!(matches!(e, FitError::NotInFit { .. }), "{e}");
    assert!(matches!(fit_friction(None, None, &Fixed::none()).unwrap_err(), FitError::NoData));
    // A dynamic parameter fixed for a static-only fit is refused, not ignored.
    let steady =
        SteadyData::new((1..=50).map(|i| i as f64 * 1e-3).collect(), vec![0.2; 50]).unwrap();
    let e = fit_friction(Some(&steady), None, &Fixed::parse(&["sigma0=1e5"]).unwrap()).unwrap_err();
    assert!(matches!(e, FitError::NotInFit { .. }), "{e}");
}
