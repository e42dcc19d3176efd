//! `--law all` on data made by each law: a quasi-static loop from a Maxwell-slip law and
//! one from a Bouc–Wen law are ranked to a rate-independent law with a residual near the
//! noise and the true loop energies; the seed's memory-law data rank the memory law first.

use hd_ident::HysteresisData;
use hd_ident::stiffness::cycles::loop_energies;
use hd_ident::stiffness::{LawOptions, compare_laws};
use hd_ident::synth::{
    HysteresisExcitation, Noise, QuasiStatic, Schedule, StiffnessTruth, bouc_wen_truth,
    maxwell_slip_truth, synth_stiffness,
};
use hd_model::Params;

fn data(truth: &StiffnessTruth, schedule: &Schedule, noise: f64) -> (HysteresisData, f64) {
    let s = synth_stiffness(truth, schedule, &Noise { relative: noise, seed: 5 }).unwrap();
    let [t, th, tb] = [&s.columns[0], &s.columns[1], &s.columns[2]].map(|c| c.to_vec());
    (HysteresisData::new(t, th, tb).unwrap(), s.noise_std)
}

/// Fit all laws to noisy data from `truth`; check the ranking, the residual against the
/// noise and the fitted loop energies against the clean record's.
fn check_rate_independent(truth: StiffnessTruth, label: &str) {
    let schedule = Schedule::QuasiStatic { test: QuasiStatic::default(), sample_rate: 200.0 };
    let (noisy, sd) = data(&truth, &schedule, 0.01);
    let (clean, _) = data(&truth, &schedule, 0.0);
    let cmp = compare_laws(&noisy, &LawOptions::default());
    let best = &cmp.entries[0];
    for e in &cmp.entries {
        println!(
            "{label}: {} rms/noise {:.3}, ΔBIC {:.1}, p {}",
            e.law,
            e.rms.unwrap() / sd,
            e.delta_bic.unwrap(),
            e.parameters
        );
    }
    assert_ne!(best.law, "memory", "{label}");
    assert!(best.rms.unwrap() < 1.3 * sd, "{label}: rms {} vs noise {sd}", best.rms.unwrap());
    let fit = &cmp.fits[0];
    println!(
        "{label}: {} {} iterations: {}",
        fit.law.name(),
        fit.report.iterations,
        fit.report.termination
    );
    let truth_blocks = loop_energies(clean.theta(), clean.torque(), clean.torque());
    assert_eq!(fit.report.loop_energy.len(), truth_blocks.len(), "{label}");
    for (f, t) in fit.report.loop_energy.iter().zip(&truth_blocks) {
        let err = f.model_energy_per_cycle / t.measured_energy_per_cycle - 1.0;
        println!("{label}: block at {:.3e} rad: energy error {:+.3} %", t.amplitude, 100.0 * err);
        assert!(err.abs() < 0.05, "{label}: {f:?} vs {t:?}");
    }
    println!(
        "{label}: {} samples, --law all in {:.2} s",
        noisy.len(),
        cmp.fits.iter().map(|f| f.report.wall_time_s).sum::<f64>()
    );
}

#[test]
fn maxwell_slip_loop_ranks_a_rate_independent_law_first() {
    let p = Params::default();
    let truth = StiffnessTruth::MaxwellSlip(maxwell_slip_truth(&p, 1e-3, 8, &[]).unwrap());
    check_rate_independent(truth, "maxwell-slip data");
}

#[test]
fn bouc_wen_loop_ranks_a_rate_independent_law_first() {
    let p = Params::default();
    let truth = StiffnessTruth::BoucWen(bouc_wen_truth(&p, 1e-3, &[]).unwrap());
    check_rate_independent(truth, "bouc-wen data");
}

#[test]
fn memory_law_data_rank_the_memory_law_first() {
    // The shipped data/hysteresis-paper-range.csv is this record (same settings and seed).
    let p = Params::default();
    let schedule = Schedule::Sines(HysteresisExcitation::default());
    let s = synth_stiffness(
        &StiffnessTruth::Memory(Box::new(p)),
        &schedule,
        &Noise { relative: 0.01, seed: 1 },
    )
    .unwrap();
    let [t, th, tb] = [&s.columns[0], &s.columns[1], &s.columns[2]].map(|c| c.to_vec());
    let d = HysteresisData::new(t, th, tb).unwrap();
    let cmp = compare_laws(&d, &LawOptions::default());
    for e in &cmp.entries {
        println!(
            "memory data: {} rms/noise {:.3}, ΔBIC {:.1}",
            e.law,
            e.rms.unwrap() / s.noise_std,
            e.delta_bic.unwrap()
        );
    }
    assert_eq!(cmp.entries[0].law, "memory");
    assert!(cmp.entries[1].delta_bic.unwrap() > 10.0);
}

/// RSS [N²·m²] of the cubic spring alone (θ³, θ², θ and, with `offset`, a constant) by
/// linear least squares: the law every `--law all` law contains (each adds a hysteretic
/// term whose coefficient is solved linearly, or a non-negative stiffness, so it can be 0).
fn spring_only_rss(d: &HysteresisData, offset: bool) -> f64 {
    let th = d.theta();
    let n = th.len();
    let cols = if offset { 4 } else { 3 };
    let a = nalgebra::DMatrix::from_fn(
        n,
        cols,
        |i, j| if j < 3 { th[i].powi(3 - j as i32) } else { 1.0 },
    );
    let y = nalgebra::DVector::from_column_slice(d.torque());
    let beta = a.clone().svd(true, true).solve(&y, 1e-14).unwrap();
    (&y - &a * beta).norm_squared()
}

/// Nested laws stay nested under `--law all`: on records from each law (and from a spring
/// with no hysteresis at all), with and without an offset, no law ends above the cubic
/// spring it contains.
#[test]
fn no_law_fits_worse_than_the_spring_it_contains() {
    let p = Params::default();
    let quasi = Schedule::QuasiStatic { test: QuasiStatic::default(), sample_rate: 200.0 };
    let sines = Schedule::Sines(HysteresisExcitation::default());
    let records = [
        ("memory", StiffnessTruth::Memory(Box::new(p.clone())), &sines),
        (
            "spring only",
            StiffnessTruth::Memory(Box::new(Params { mem_a: 0.0, ..p.clone() })),
            &sines,
        ),
        (
            "maxwell-slip",
            StiffnessTruth::MaxwellSlip(maxwell_slip_truth(&p, 1e-3, 8, &[]).unwrap()),
            &quasi,
        ),
        ("bouc-wen", StiffnessTruth::BoucWen(bouc_wen_truth(&p, 1e-3, &[]).unwrap()), &quasi),
    ];
    for (label, truth, schedule) in &records {
        let (d, _) = data(truth, schedule, 0.01);
        for offset in [false, true] {
            let spring = spring_only_rss(&d, offset);
            let cmp = compare_laws(&d, &LawOptions { offset, ..LawOptions::default() });
            for (e, fit) in cmp.entries.iter().zip(&cmp.fits) {
                println!(
                    "{label}, offset {offset}: {} RSS {:.6e}, spring alone {spring:.6e}",
                    e.law,
                    fit.rss()
                );
                assert!(fit.rss() <= spring * (1.0 + 1e-9), "{label}, offset {offset}: {}", e.law);
            }
            assert_eq!(cmp.fits.len(), 3, "{label}: every law fitted");
        }
    }
}
