//! The hysteresis fit recovers known parameters from synthetic data with 1 % noise, its
//! intervals cover the truth, and it says when the data cannot determine a and b.

mod common;

use common::*;
use hd_ident::synth::{HysteresisExcitation, Noise};
use hd_ident::{Fixed, fit_hysteresis};

/// Parameter sets that differ from the defaults, with the memory corner frequency B/2π
/// from 13 Hz to 127 Hz.
const SETS: [&[&str]; 3] = [
    &["a=0.5", "b=-1.0", "c=6.5e4", "A=2.5e4", "B=150"],
    &["a=0.05", "b=2.0", "c=4.0e4", "A=6.0e4", "B=800"],
    &["c=8.0e4", "A=1.5e4", "B=80"],
];

#[test]
fn recovers_c_a_b_within_two_percent() {
    for (i, set) in SETS.iter().enumerate() {
        let p = params(set);
        let data = hysteresis_data(
            &p,
            &HysteresisExcitation::default(),
            Noise { relative: 0.01, seed: 1 },
        );
        let fit = fit_hysteresis(&data, &Fixed::none()).unwrap();
        let r = &fit.report;
        for name in ["c", "mem_A", "mem_B"] {
            assert!(rel_error(r, &p, name) < 0.02, "set {i}: {name}");
            assert!(r.parameters.get(name).unwrap().determined, "set {i}: {name}");
        }
        assert!(r.r2 > 0.999 && r.iterations > 0, "{}", r.table());
        // The noise estimate matches the noise put in (1 % of the RMS torque).
        let rms_torque =
            (data.torque().iter().map(|v| v * v).sum::<f64>() / data.len() as f64).sqrt();
        assert!((r.noise_std / (0.01 * rms_torque) - 1.0).abs() < 0.05);
    }
}

#[test]
fn paper_deflection_range_leaves_a_and_b_undetermined() {
    let p = params(&[]);
    let data =
        hysteresis_data(&p, &HysteresisExcitation::default(), Noise { relative: 0.01, seed: 11 });
    let r = fit_hysteresis(&data, &Fixed::none()).unwrap().report;
    println!("{}", r.table());
    assert_eq!(r.undetermined(), vec!["a", "b"]);
    for name in ["a", "b"] {
        let note = r.parameters.get(name).unwrap().note.as_deref().unwrap();
        assert!(note.contains("below the noise") && note.contains("deflection range"), "{note}");
    }
    let json = r.to_json();
    assert!(json.contains("\"determined\": false"));
}

#[test]
fn large_deflection_range_recovers_a_and_b() {
    // |θ| up to 0.02 rad: a·θ³ and b·θ² reach hundreds of N·m beside c·θ ≈ 1000 N·m.
    let p = params(&["a=1e8", "b=2e6", "c=5.2e4", "A=4e4", "B=300"]);
    let exc = HysteresisExcitation { amplitude: 0.02, ..Default::default() };
    let r = fit_hysteresis(
        &hysteresis_data(&p, &exc, Noise { relative: 0.01, seed: 5 }),
        &Fixed::none(),
    )
    .unwrap()
    .report;
    for name in ["a", "b", "c", "mem_A", "mem_B"] {
        assert!(rel_error(&r, &p, name) < 0.02, "{name}");
        assert!(covers(&r, &p, name), "{name}");
        assert!(r.parameters.get(name).unwrap().determined, "{name}");
    }
}

#[test]
fn noise_free_data_are_reproduced_by_the_same_laws() {
    let p = params(SETS[0]);
    let data =
        hysteresis_data(&p, &HysteresisExcitation::default(), Noise { relative: 0.0, seed: 1 });
    let fit = fit_hysteresis(&data, &Fixed::none()).unwrap();
    // Only the piecewise-linear reading of θ between samples separates fit and data.
    for name in ["c", "mem_A", "mem_B"] {
        assert!(rel_error(&fit.report, &p, name) < 2e-4, "{name}");
    }
}

#[test]
fn fixing_b_gives_the_closed_form_and_reports_it_held() {
    let p = params(SETS[0]);
    let data =
        hysteresis_data(&p, &HysteresisExcitation::default(), Noise { relative: 0.01, seed: 2 });
    let fixed = Fixed::parse(&["B=150", "a=0.5"]).unwrap();
    let r = fit_hysteresis(&data, &fixed).unwrap().report;
    let b = r.parameters.get("mem_B").unwrap();
    assert!(b.fixed && b.std_error.is_none() && b.value == 150.0);
    assert_eq!(r.iterations, 0);
    assert!(r.search.is_none() && r.termination.contains("closed form"));
    assert!(rel_error(&r, &p, "mem_A") < 0.02);
}

#[test]
fn intervals_cover_the_truth_at_about_the_stated_rate() {
    // Ten noise realisations for each set: 30 intervals per parameter, of which a 95 %
    // interval should miss about 1.5; allow up to 5.
    let exc = HysteresisExcitation::default();
    let names = ["a", "b", "c", "mem_A", "mem_B"];
    let mut misses = [0; 5];
    for set in SETS {
        let p = params(set);
        for seed in 100..110 {
            let data = hysteresis_data(&p, &exc, Noise { relative: 0.01, seed });
            let r = fit_hysteresis(&data, &Fixed::none()).unwrap().report;
            for (k, name) in names.iter().enumerate() {
                misses[k] += usize::from(!covers(&r, &p, name));
            }
        }
    }
    println!("95 % intervals missing the truth, of 30, for {names:?}: {misses:?}");
    assert!(misses.iter().all(|&m| m <= 5), "{misses:?}");
}

#[test]
fn coarse_sampling_is_flagged() {
    // 2000 samples over 0.5 s read the 200 Hz component with 10 points per period.
    let p = params(SETS[1]);
    let coarse = HysteresisExcitation { samples: 2000, ..Default::default() };
    let r = fit_hysteresis(
        &hysteresis_data(&p, &coarse, Noise { relative: 0.01, seed: 1 }),
        &Fixed::none(),
    )
    .unwrap()
    .report;
    println!("{:?}", r.remarks);
    assert!(
        r.remarks.iter().any(|m| m.starts_with("warning: reading θ as linear")),
        "{:?}",
        r.remarks
    );
    let fine = fit_hysteresis(
        &hysteresis_data(&p, &HysteresisExcitation::default(), Noise { relative: 0.01, seed: 1 }),
        &Fixed::none(),
    )
    .unwrap()
    .report;
    assert!(fine.remarks.iter().any(|m| m.starts_with("sampling check")), "{:?}", fine.remarks);
}

#[test]
fn a_torque_offset_is_fitted_with_the_law() {
    let p = params(SETS[0]);
    let clean =
        hysteresis_data(&p, &HysteresisExcitation::default(), Noise { relative: 0.01, seed: 3 });
    // The rig's torque zero is 1.5 N·m off.
    let shifted: Vec<f64> = clean.torque().iter().map(|v| v + 1.5).collect();
    let data =
        hd_ident::HysteresisData::new(clean.t().to_vec(), clean.theta().to_vec(), shifted).unwrap();
    let plain = fit_hysteresis(&data, &Fixed::none()).unwrap().report;
    let fit = hd_ident::fit_hysteresis_with(&data, &Fixed::none(), true).unwrap();
    let r = &fit.report;
    let off = r.parameters.get("offset").unwrap();
    println!(
        "offset {:.4} ± {:.4} N·m (truth 1.5); rms {:.4e} with offset, {:.4e} without",
        off.value,
        off.std_error.unwrap(),
        r.rms,
        plain.rms
    );
    assert!((off.value - 1.5).abs() < 3.0 * off.std_error.unwrap(), "{}", r.table());
    for name in ["c", "mem_A", "mem_B"] {
        assert!(rel_error(r, &p, name) < 0.02, "{name}");
    }
    assert!(r.rms < plain.rms);
}
