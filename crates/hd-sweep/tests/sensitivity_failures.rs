//! Failed runs in a design: dropped whole (base rows, trajectories), counted, never filled,
//! and the indices of what remains still match the analytic ones.

use hd_sweep::sensitivity::{
    DesignPoint, ISHIGAMI_BASE_SAMPLES, ISHIGAMI_NAMES, ISHIGAMI_TOLERANCE, Ishigami, MetricColumn,
    SensitivityRow, SobolOptions, analyse, morris_design, saltelli_design,
};
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

const OPTIONS: SobolOptions =
    SobolOptions { bootstrap: 100, confidence: 0.95, seed: 1, min_base_rows: 16 };

/// Ishigami outputs with a seeded fraction of runs replaced by NaN.
fn outputs_with_failures(points: &[DesignPoint], rate: f64, seed: u64) -> Vec<f64> {
    let f = Ishigami::default();
    let ranges = Ishigami::ranges();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    points
        .iter()
        .map(|p| {
            let x = hd_sweep::sensitivity::map_point(&ranges, &p.unit);
            if rng.random_bool(rate) { f64::NAN } else { f.eval(&x) }
        })
        .collect()
}

fn by_param(rows: &[SensitivityRow], get: fn(&SensitivityRow) -> f64) -> Vec<f64> {
    ISHIGAMI_NAMES.iter().map(|n| get(rows.iter().find(|r| r.parameter == *n).unwrap())).collect()
}

#[test]
fn sobol_drops_base_rows_with_failures_and_stays_accurate() {
    let design = saltelli_design(3, ISHIGAMI_BASE_SAMPLES, Some(3)).unwrap();
    let y = outputs_with_failures(&design.points, 0.03, 9);
    // A base row is lost if any of its 5 runs failed.
    let failed_rows = (0..ISHIGAMI_BASE_SAMPLES)
        .filter(|j| y[j * 5..j * 5 + 5].iter().any(|v| v.is_nan()))
        .count();
    assert!(failed_rows > 300, "the test should drop a good share of rows");
    let rows = analyse(
        &ISHIGAMI_NAMES,
        &design.points,
        &[MetricColumn { name: "y", values: &y }],
        &OPTIONS,
    )
    .unwrap();
    for r in &rows {
        assert_eq!(r.n_dropped, failed_rows);
        assert_eq!(r.n_used, ISHIGAMI_BASE_SAMPLES - failed_rows);
        assert!(r.note.as_deref().unwrap().contains("dropped"));
    }
    let exact = Ishigami::default().analytic();
    let (s1, st) = (by_param(&rows, |r| r.s1), by_param(&rows, |r| r.st));
    for i in 0..3 {
        assert!((s1[i] - exact.s1[i]).abs() <= ISHIGAMI_TOLERANCE, "S1 {s1:?}");
        assert!((st[i] - exact.st[i]).abs() <= ISHIGAMI_TOLERANCE, "ST {st:?}");
    }
}

#[test]
fn order_does_not_matter_and_missing_runs_count_as_failures() {
    let design = saltelli_design(3, 256, Some(0)).unwrap();
    let y = Ishigami::default().run_design(&design);
    let metric = |v| [MetricColumn { name: "y", values: v }];
    let full = analyse(&ISHIGAMI_NAMES, &design.points, &metric(&y), &OPTIONS).unwrap();

    // Shuffled: identical results.
    let mut order: Vec<usize> = (0..design.len()).collect();
    order.shuffle(&mut ChaCha8Rng::seed_from_u64(5));
    let pts: Vec<DesignPoint> = order.iter().map(|&i| design.points[i].clone()).collect();
    let ys: Vec<f64> = order.iter().map(|&i| y[i]).collect();
    let shuffled = analyse(&ISHIGAMI_NAMES, &pts, &metric(&ys), &OPTIONS).unwrap();
    // Debug text, because the unused Morris columns are NaN (never equal to themselves).
    assert_eq!(format!("{shuffled:?}"), format!("{full:?}"));

    // Two runs of different base rows missing from the table: those rows are dropped.
    let keep: Vec<usize> = (0..design.len()).filter(|&i| i != 7 && i != 5 * 100).collect();
    let pts: Vec<DesignPoint> = keep.iter().map(|&i| design.points[i].clone()).collect();
    let ys: Vec<f64> = keep.iter().map(|&i| y[i]).collect();
    let rows = analyse(&ISHIGAMI_NAMES, &pts, &metric(&ys), &OPTIONS).unwrap();
    assert!(rows.iter().all(|r| r.n_dropped == 2 && r.n_used == 254));
}

#[test]
fn too_many_failures_give_nan_with_a_reason() {
    let design = saltelli_design(3, 64, Some(0)).unwrap();
    let y = outputs_with_failures(&design.points, 0.5, 2);
    let rows = analyse(
        &ISHIGAMI_NAMES,
        &design.points,
        &[MetricColumn { name: "y", values: &y }],
        &OPTIONS,
    )
    .unwrap();
    for r in &rows {
        assert!(r.s1.is_nan() && r.st.is_nan() && r.s1_lo.is_nan());
        assert!(r.note.as_deref().unwrap().contains("need at least 16"), "{:?}", r.note);
        assert_eq!(r.n_used + r.n_dropped, 64);
    }
}

#[test]
fn morris_drops_trajectories_with_failures() {
    let design = morris_design(3, 500, 4, 8).unwrap();
    let y = outputs_with_failures(&design.points, 0.05, 4);
    let failed = (0..500).filter(|t| y[t * 4..t * 4 + 4].iter().any(|v| v.is_nan())).count();
    assert!(failed > 0);
    let rows = analyse(
        &ISHIGAMI_NAMES,
        &design.points,
        &[MetricColumn { name: "y", values: &y }],
        &OPTIONS,
    )
    .unwrap();
    assert!(rows.iter().all(|r| r.n_dropped == failed && r.n_used == 500 - failed));
    let m = by_param(&rows, |r| r.mu_star);
    assert!(m[0] > m[2] && m[1] > m[2], "mu* = {m:?}");
    assert!(rows.iter().all(|r| r.s1.is_nan() && r.mu.is_finite() && r.sigma.is_finite()));
}
