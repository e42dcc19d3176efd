//! The estimators on the Ishigami function (a = 7, b = 0.1), through the same design and
//! analysis code a study uses, against the analytic indices.
//!
//! Documented sample count: N = `ISHIGAMI_BASE_SAMPLES` = 4096 base samples (20 480 runs);
//! Morris with 500 trajectories on 4 levels.

use hd_sweep::sensitivity::{
    ISHIGAMI_BASE_SAMPLES, ISHIGAMI_TOLERANCE, Ishigami, IshigamiCheckConfig, ishigami_check,
};

fn config() -> IshigamiCheckConfig {
    // Fewer bootstrap resamples than the CLI default keep the debug test quick; the point
    // estimates do not depend on them.
    IshigamiCheckConfig { bootstrap: 200, ..Default::default() }
}

#[test]
fn sobol_indices_match_analytic_at_documented_n() {
    let check = ishigami_check(&config()).unwrap();
    assert_eq!(check.config.base_samples, ISHIGAMI_BASE_SAMPLES);
    assert_eq!(check.sobol_runs, ISHIGAMI_BASE_SAMPLES * 5);
    let exact = Ishigami::default().analytic();
    for i in 0..3 {
        assert!(
            (check.s1[i] - exact.s1[i]).abs() <= ISHIGAMI_TOLERANCE,
            "S1[x{}] = {:.4}, analytic {:.4}",
            i + 1,
            check.s1[i],
            exact.s1[i]
        );
        assert!(
            (check.st[i] - exact.st[i]).abs() <= ISHIGAMI_TOLERANCE,
            "ST[x{}] = {:.4}, analytic {:.4}",
            i + 1,
            check.st[i],
            exact.st[i]
        );
    }
    assert!(check.passed);
}

#[test]
fn bootstrap_intervals_bracket_the_estimates() {
    let check = ishigami_check(&config()).unwrap();
    for r in check.rows.iter().filter(|r| r.method.as_str() == "sobol") {
        assert!(r.s1_lo <= r.s1 && r.s1 <= r.s1_hi, "{r:?}");
        assert!(r.st_lo <= r.st && r.st <= r.st_hi, "{r:?}");
        assert!(r.s1_hi - r.s1_lo < 0.15 && r.st_hi - r.st_lo < 0.15, "{r:?}");
        assert_eq!((r.n_used, r.n_dropped), (ISHIGAMI_BASE_SAMPLES, 0));
    }
}

#[test]
fn morris_ranks_x1_and_x2_above_x3() {
    for seed in 0..5 {
        let check = ishigami_check(&IshigamiCheckConfig { seed, ..config() }).unwrap();
        let m = check.mu_star;
        assert!(m[0] > m[2] && m[1] > m[2], "seed {seed}: mu* = {m:?}");
    }
}

#[test]
fn analytic_indices_follow_the_coefficients() {
    // With b = 0 the x3 interaction disappears and S1 = ST (additive function).
    let idx = Ishigami { a: 7.0, b: 0.0 }.analytic();
    for i in 0..3 {
        assert!((idx.s1[i] - idx.st[i]).abs() < 1e-15);
    }
    assert!((idx.s1.iter().sum::<f64>() - 1.0).abs() < 1e-12);
}
