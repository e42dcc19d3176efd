//! The joint fit's exact Jacobian against central differences of its own residuals.

use super::*;

/// A record with reversals and slow stretches, and a torque that the model at the test
/// point does not fit exactly (so the residual-dependent term of the Jacobian counts).
fn data(asymmetric: bool) -> TransientData {
    let n = 3000;
    let t: Vec<f64> = (0..n).map(|k| 2e-3 * k as f64 + 1e-4 * (0.7 * k as f64).sin()).collect();
    let omega: Vec<f64> = t
        .iter()
        .map(|&t| 0.03 * (std::f64::consts::TAU * 0.8 * t).sin() + 0.004 * (9.0 * t).cos())
        .collect();
    let sym = LuGre::symmetric(5e4, 0.5, 0.02, 0.2, 0.35, 0.01);
    let law = if asymmetric { LuGre { tc_neg: 0.16, ts_neg: 0.3, ..sym } } else { sym };
    let run = bristle_run(&t, &omega, &law, 0.0, false).unwrap();
    let torque: Vec<f64> = (0..n)
        .map(|k| {
            run.w[k] + 0.5 * run.slip[k] + 0.02 * omega[k] + 0.03 + 0.01 * (1.3 * k as f64).sin()
        })
        .collect();
    TransientData::new(t, omega, torque).unwrap()
}

#[test]
fn exact_jacobian_matches_central_differences() {
    for opts in [
        FrictionOptions { asymmetric: false, offset: true },
        FrictionOptions { asymmetric: true, offset: true },
    ] {
        let start = [
            ("Tc", 0.19),
            ("Ts", 0.37),
            ("ws", 0.011),
            ("sigma0", 4.5e4),
            ("Tc_neg", if opts.asymmetric { 0.165 } else { 0.19 }),
            ("Ts_neg", if opts.asymmetric { 0.29 } else { 0.37 }),
        ];
        let d = data(opts.asymmetric);
        let problem = JointProblem::new(&d, &Fixed::none(), opts, &start);
        let x = problem.x_of(&problem.base);
        let proj = problem.project(&problem.values(&x)).unwrap();
        assert!(proj.at_bound.iter().all(|b| !b), "at a bound: {:?}", proj.beta);
        let (r, jac) = problem.residuals_and_jacobian(&x).unwrap();
        assert_eq!(jac.len(), problem.nonlinear.len());
        // The fit's own evaluation (workspace, Gram solve) gives the same normal equations.
        let reference = crate::lm::Normal::from_model_columns(&jac, &r);
        let normal = problem.pool.with(|ws| problem.normal_at(&x, ws)).unwrap();
        let cost = normal.cost;
        let rss: f64 = r.iter().map(|v| v * v).sum();
        assert!((cost - rss).abs() <= 1e-12 * rss, "{cost} vs {rss}");
        let close = |a: f64, b: f64, scale: f64| (a - b).abs() <= 1e-9 * scale;
        let big = reference.jtj.amax();
        for (a, b) in normal.jtj.iter().zip(reference.jtj.iter()) {
            assert!(close(*a, *b, big), "JᵀJ {a} vs {b}");
        }
        let big = reference.jtr.amax().max(1e-9 * big.sqrt() * rss.sqrt());
        for (a, b) in normal.jtr.iter().zip(reference.jtr.iter()) {
            assert!(close(*a, *b, big), "Jᵀr {a} vs {b}");
        }
        let h = 1e-5;
        for (j, name) in problem.nonlinear.iter().enumerate() {
            let at = |dx: f64| {
                let mut xj = x.clone();
                xj[j] += dx;
                problem.project(&problem.values(&xj)).unwrap().residuals
            };
            let (up, down) = (at(h), at(-h));
            // ∂model/∂x = −∂r/∂x.
            let fd: Vec<f64> = up.iter().zip(&down).map(|(a, b)| -(a - b) / (2.0 * h)).collect();
            let scale = jac[j].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let worst = fd.iter().zip(&jac[j]).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            println!("{opts:?} ∂/∂ln {name}: {worst:.1e} of {scale:.3e}");
            assert!(scale > 0.0, "{name}: zero column");
            assert!(worst <= 1e-6 * scale, "{name}: {worst:e} of {scale:e}");
        }
    }
}

#[test]
fn sigma0_pass_matches_the_general_evaluation() {
    // Symmetric and asymmetric, every linear parameter free or σ2 held, over the σ0 range
    // from soft (bristles never saturate) to stiff; the record reverses, so the split
    // intervals are exercised.
    for (opts, fix) in [
        (FrictionOptions { asymmetric: false, offset: false }, None),
        (FrictionOptions { asymmetric: true, offset: true }, None),
        (FrictionOptions { asymmetric: true, offset: true }, Some("sigma2=0.015")),
    ] {
        let d = data(opts.asymmetric);
        let fixed = Fixed::parse(&fix.map(String::from).into_iter().collect::<Vec<_>>()).unwrap();
        let start = [("Tc", 0.19), ("Ts", 0.37), ("ws", 0.011), ("Tc_neg", 0.17), ("Ts_neg", 0.3)];
        let mut problem = JointProblem::new(&d, &fixed, opts, &start);
        problem.first_bias = 0.01;
        let pass = sigma0_pass::Sigma0Pass::new(&problem, problem.law(&problem.base));
        let mut worst = 0.0f64;
        for sigma0 in [1.0, 30.0, 1e3, 5e4, 3e6, 1e9] {
            let mut v = problem.base;
            v[3] = sigma0;
            let general = problem.rss_at(&v).unwrap();
            let fast = pass.rss(&problem, sigma0).expect("a usable Gram matrix");
            worst = worst.max((fast - general).abs() / general);
        }
        println!("{opts:?}, {fix:?}: worst relative difference {worst:.1e}");
        assert!(worst <= 3e-13, "{worst:e}"); // 2.3e-14 measured
    }
}

#[test]
fn chunked_kernel_matches_the_laws_own_steps() {
    // The vectorised chunks against LuGre::step_interval and slip_rate_grad sample by
    // sample (the reference run), over a record with reversals, both laws.
    for asym in [false, true] {
        let d = data(asym);
        let law = LuGre {
            tc_neg: 0.17,
            ts_neg: 0.31,
            ..LuGre::symmetric(4e4, 0.0, 0.0, 0.19, 0.36, 0.011)
        };
        let law = if asym { law } else { LuGre { tc_neg: law.tc, ts_neg: law.ts, ..law } };
        let (t, omega) = (d.t(), d.omega());
        let reference = bristle_run(t, omega, &law, 0.05, true).unwrap();
        let fold = |g: &[f64; 6]| {
            if asym { *g } else { [g[0] + g[4], g[1] + g[5], g[2], g[3], 0.0, 0.0] }
        };
        let n = t.len();
        let (mut w, mut slip) = (vec![0.0; n], vec![0.0; n]);
        let (mut dw, mut ds) = (vec![[0.0; 6]; n], vec![[0.0; 6]; n]);
        kernel::grad_run(&law, asym, t, omega, 0.05, |k0, len, out| {
            for j in 0..len {
                w[k0 + j] = out.w[j];
                slip[k0 + j] = out.slip[j];
                dw[k0 + j] = std::array::from_fn(|i| out.dw[i][j]);
                ds[k0 + j] = std::array::from_fn(|i| out.ds[i][j]);
            }
        });
        let worst = |a: &[f64], b: &[f64]| {
            let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
            a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale
        };
        let mut err = worst(&w, &reference.w).max(worst(&slip, &reference.slip));
        for i in 0..6 {
            let col = |rows: &[[f64; 6]]| rows.iter().map(|r| r[i]).collect::<Vec<f64>>();
            let want_w: Vec<[f64; 6]> = reference.d_w.iter().map(fold).collect();
            let want_s: Vec<[f64; 6]> = reference.d_slip.iter().map(fold).collect();
            if col(&want_w).iter().any(|v| *v != 0.0) {
                err = err.max(worst(&col(&dw), &col(&want_w)));
                err = err.max(worst(&col(&ds), &col(&want_s)));
            }
        }
        println!("asymmetric {asym}: worst difference {err:.1e} of each column's largest value");
        assert!(err <= 1.5e-12, "{err:e}"); // 1.2e-13 measured
    }
}
