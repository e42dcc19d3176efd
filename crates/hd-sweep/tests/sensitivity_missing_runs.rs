//! Runs missing from a results table stand in as points with NaN coordinates and NaN
//! outputs: their base row or trajectory is dropped and counted, including the last one.

use hd_sweep::sensitivity::{
    DesignPoint, MetricColumn, SobolOptions, analyse, morris_design, saltelli_design,
};

/// y = 2·x0 + x1 on the unit cube.
fn outputs(points: &[DesignPoint]) -> Vec<f64> {
    points.iter().map(|p| 2.0 * p.unit[0] + p.unit[1]).collect()
}

/// Replace point `k` by a stand-in for a missing run.
fn blank(points: &mut [DesignPoint], y: &mut [f64], k: usize) {
    points[k].unit.iter_mut().for_each(|u| *u = f64::NAN);
    y[k] = f64::NAN;
}

#[test]
fn a_missing_morris_run_drops_its_trajectory_even_the_last() {
    let design = morris_design(2, 10, 4, 1).unwrap();
    let mut points = design.points.clone();
    let mut y = outputs(&points);
    blank(&mut points, &mut y, 4); // trajectory 1, step 1
    blank(&mut points, &mut y, 29); // trajectory 9 (the last), step 2
    let rows = analyse(
        &["x0", "x1"],
        &points,
        &[MetricColumn { name: "y", values: &y }],
        &SobolOptions::default(),
    )
    .unwrap();
    for r in &rows {
        assert_eq!((r.n_used, r.n_dropped), (8, 2), "{r:?}");
    }
    // A linear function: every elementary effect is its coefficient.
    assert!((rows[0].mu_star - 2.0).abs() < 1e-12 && (rows[1].mu_star - 1.0).abs() < 1e-12);
}

#[test]
fn a_missing_sobol_run_drops_its_base_row_even_the_last() {
    let design = saltelli_design(2, 32, Some(1)).unwrap();
    let mut points = design.points.clone();
    let mut y = outputs(&points);
    let last = points.len() - 1;
    blank(&mut points, &mut y, last);
    let opts = SobolOptions { bootstrap: 0, ..SobolOptions::default() };
    let rows =
        analyse(&["x0", "x1"], &points, &[MetricColumn { name: "y", values: &y }], &opts).unwrap();
    for r in &rows {
        assert_eq!((r.n_used, r.n_dropped), (31, 1), "{r:?}");
    }
    // Additive: S1 = ST = 4/5 and 1/5.
    assert!((rows[0].st - 0.8).abs() < 0.05 && (rows[1].st - 0.2).abs() < 0.05, "{rows:?}");
}
