//! Checks of the design core against closed forms: the criteria of known matrices, the
//! information against central differences of the simulated outputs, its growth with the
//! square of a linear drive's amplitude, and the scaled input against its limits.

use super::*;
use crate::drive::compliant::fit::CompliantSpec;
use crate::drive::compliant::model::{NAMES, P, ix};
use crate::drive::compliant::{Between, Signal};
use crate::lm::LmOptions;

fn seed() -> ([f64; P], f64) {
    let p = hd_model::Params::default();
    let mut v = [0.0; P];
    for (k, n) in NAMES.iter().enumerate() {
        v[k] = p.get(n).unwrap();
    }
    // The other gear laws' constants to zero, as the fit's params reader does.
    crate::drive::compliant::model::on_law(&mut v, hd_model::HystLaw::Memory);
    (v, p.n)
}

pub(super) fn problem(free: &[usize], limits: Limits) -> Problem {
    let (values, n) = seed();
    let mut f = [false; P];
    for &k in free {
        f[k] = true;
    }
    let spec = CompliantSpec {
        n,
        between: Between::Hold,
        start: values,
        free: f,
        lower: values.map(|v| v / 1e3),
        upper: values.map(|v| v * 1e3),
        outputs: vec![(Signal::Motor, vec![1.0])],
        noise_estimated: vec![false],
        km_is_ke: true,
        symmetric_friction: true,
        symmetric_load_friction: true,
        current_offset: false,
        friction_velocity: hd_model::FrictionVelocity::Motor,
        substeps: 20,
        settings: LmOptions::drive(),
    };
    let k = free.len();
    Problem {
        spec,
        values,
        free: free.to_vec(),
        noise: Noise { motor: 4.43e-4, load: 1.73e-6, current: Some(0.01) },
        prior: DMatrix::zeros(k, k),
        limits,
        closed: None,
    }
}

pub(super) fn limits(duration: f64) -> Limits {
    Limits {
        reference: None,
        voltage: 12.0,
        current: None,
        speed: None,
        deflection: None,
        load_speed: None,
        torque: None,
        load_angle: None,
        duration,
        rate: 1000.0,
    }
}

#[test]
fn criteria_of_a_known_matrix() {
    let m = DMatrix::from_diagonal(&DVector::from_vec(vec![4.0, 100.0, 0.0]));
    let r = criterion::RIDGE;
    let d = Criterion::D.cost(&m);
    let want = -((4.0 + r).ln() + (100.0 + r).ln() + r.ln());
    assert!((d - want).abs() < 1e-12, "{d} {want}");
    let a = Criterion::A(vec![0, 1]).cost(&m);
    assert!((a - (1.0 / (4.0 + r) + 1.0 / (100.0 + r))).abs() < 1e-12, "{a}");
    // The weakest direction is the unseen third parameter, and targeting it costs ln(1/ε).
    let (dirs, eig) = weakest(&m);
    assert!((dirs[(2, 0)].abs() - 1.0).abs() < 1e-12 && (eig[0] - r).abs() < 1e-12);
    let t = Criterion::Targeted(dirs.columns(0, 1).into_owned()).cost(&m);
    assert!((t - (1.0 / r).ln()).abs() < 1e-9, "{t}");
    // A rotated matrix: the prediction's relative SEs are the inverse's diagonal.
    let q = DMatrix::from_row_slice(2, 2, &[0.6, -0.8, 0.8, 0.6]);
    let m2 = &q * DMatrix::from_diagonal(&DVector::from_vec(vec![9.0, 0.25])) * q.transpose();
    let p = predict(&m2, &[ix::R, ix::KE]);
    let inv = m2.clone().try_inverse().unwrap();
    for i in 0..2 {
        assert!((p.relative[i].unwrap() - inv[(i, i)].sqrt()).abs() < 1e-12);
    }
    let rho = inv[(0, 1)] / (inv[(0, 0)] * inv[(1, 1)]).sqrt();
    assert!((p.correlation[(0, 1)] - rho).abs() < 1e-12);
}

/// The information of `pr`'s free parameters `free` (log coordinates) from central
/// differences (step 1e-5 in ln p) of `outputs`, the noise-weighted outputs at a parameter
/// set: the Gram matrix of the difference columns.
fn difference_information(
    pr: &Problem,
    free: &[usize],
    outputs: &dyn Fn([f64; P]) -> Vec<f64>,
) -> DMatrix<f64> {
    let h = 1e-5;
    let cols: Vec<Vec<f64>> = free
        .iter()
        .map(|&k| {
            let at = |s: f64| {
                let mut v = pr.values;
                v[k] *= (s * h).exp();
                outputs(pr.spec.tied(v))
            };
            let (a, b) = (at(1.0), at(-1.0));
            a.iter().zip(&b).map(|(x, y)| (x - y) / (2.0 * h)).collect()
        })
        .collect();
    DMatrix::from_fn(free.len(), free.len(), |i, j| {
        cols[i].iter().zip(&cols[j]).map(|(a, b)| a * b).sum()
    })
}

/// JᵀJ from the fit's exact Jacobian equals the one from central differences of the
/// simulated outputs (each less its mean, as the encoder zeros are fitted; each divided by
/// its noise), in log coordinates.
#[test]
fn information_matches_central_differences() {
    let free = [ix::R, ix::KE, ix::JJ, ix::CJ, ix::TC];
    let pr = problem(&free, limits(0.3));
    let u: Vec<f64> = Design::single(Segment::Chirp { f0: 2.0, f1: 40.0 })
        .shape(pr.limits.samples(), 1000.0)
        .iter()
        .map(|v| 12.0 * v)
        .collect();
    let info = pr.information_all(&u).unwrap();
    let outputs = |values: [f64; P]| -> Vec<f64> {
        let q = Problem { values, ..pr.clone() };
        let rec = q.record(&u);
        let centred = |x: &[f64]| {
            let m = x.iter().sum::<f64>() / x.len() as f64;
            x.iter().map(|v| v - m).collect::<Vec<f64>>()
        };
        let mut out: Vec<f64> = centred(&rec.theta_m).iter().map(|v| v / pr.noise.motor).collect();
        out.extend(centred(&rec.theta_l).iter().map(|v| v / pr.noise.load));
        out.extend(rec.current.unwrap().iter().map(|v| v / pr.noise.current.unwrap()));
        out
    };
    let fd = difference_information(&pr, &free, &outputs);
    for i in 0..free.len() {
        for j in 0..free.len() {
            let (fd, scale) = (fd[(i, j)], (info[(i, i)] * info[(j, j)]).sqrt());
            assert!(
                (fd - info[(i, j)]).abs() < 1e-5 * scale,
                "{} {}: exact {} differences {fd}",
                NAMES[free[i]],
                NAMES[free[j]],
                info[(i, j)]
            );
        }
    }
}

/// A drive without friction or memory is linear in its voltage: its information grows with
/// the square of the amplitude (to 1e-6 of the diagonal).
#[test]
fn information_of_a_linear_drive_grows_with_the_square_of_the_amplitude() {
    let free = [ix::R, ix::KE, ix::JZ, ix::C];
    let mut pr = problem(&free, limits(0.2));
    for k in [ix::SIGMA0, ix::SIGMA1, ix::MEM_A] {
        pr.values[k] = 0.0;
    }
    pr.values[ix::A] = 0.0;
    pr.values[ix::B] = 0.0;
    let shape = Design::single(Segment::Multisine { f0: 5.0, f1: 300.0, lines: 8, tilt: 0.0 })
        .shape(pr.limits.samples(), 1000.0);
    let at = |a: f64| pr.information_all(&shape.iter().map(|v| a * v).collect::<Vec<_>>()).unwrap();
    let (one, three) = (at(1.0), at(3.0));
    let k = one.nrows();
    for i in 0..k {
        for j in 0..k {
            let scale = (one[(i, i)] * one[(j, j)]).sqrt();
            let (x, y) = (one[(i, j)], three[(i, j)]);
            assert!((y - 9.0 * x).abs() <= 1e-6 * 9.0 * scale, "{i} {j}: {x} {y}");
        }
    }
}

/// The scaled input meets the limit that binds, and no other is exceeded.
#[test]
fn scaled_input_meets_its_limits() {
    let free = [ix::R, ix::KE];
    let mut l = limits(0.3);
    let pr0 = problem(&free, l.clone());
    let shape = Design::single(Segment::Ramp { f: 5.0, dwell: 0.2 }).shape(l.samples(), 1000.0);
    let free_run = pr0.scaled(&shape);
    assert_eq!(free_run.binds, "voltage");
    assert!((free_run.peaks.voltage - 12.0).abs() < 1e-9);
    // Limit the speed to half of what 12 V reaches: the speed binds, within 1 %.
    l.speed = Some(0.5 * free_run.peaks.speed);
    let pr = Problem { limits: l.clone(), ..pr0 };
    let s = pr.scaled(&shape);
    assert_eq!(s.binds, "speed");
    assert!(s.within);
    let lim = l.speed.unwrap();
    assert!(s.peaks.speed <= lim * (1.0 + 1e-9) && s.peaks.speed > 0.97 * lim, "{:?}", s.peaks);
    assert!(s.peaks.voltage < 12.0);
}

/// On the seed drive with no prior, the targeted search improves on its start and the
/// outcome's best input respects the limits.
#[test]
fn search_improves_on_its_start() {
    let free = [ix::R, ix::KE, ix::JJ, ix::CJ, ix::JZ, ix::C];
    let pr = problem(&free, limits(0.2));
    let crit = Criterion::D;
    let start: Vec<f64> = Family::Chirp.params(1000.0, 0.2).iter().map(|p| p.3).collect();
    let first = evaluate(&pr, &Family::Chirp.design(&start), &crit);
    let o = optimise(&pr, Family::Chirp, &crit, 14, &|_, _| {});
    assert!(o.best.cost <= first.cost, "{} {}", o.best.cost, first.cost);
    assert!(o.best.scaled.within && o.evaluations <= 16);
}

/// The transmitted torque is the spring's c·θ + b·θ² + a·θ³ where the gear has no memory
/// (to rounding), and a torque or load-travel limit binds where set below what 12 V
/// reaches, the load's excursion measured from where it started; the load speed is the
/// angle's rate, and its limit binds too.
#[test]
fn torque_load_travel_and_load_speed_limits_bind() {
    let free = [ix::R, ix::KE, ix::JZ];
    let mut l = limits(0.3);
    let mut pr0 = problem(&free, l.clone());
    pr0.values[ix::MEM_A] = 0.0;
    let shape = Design::single(Segment::Ramp { f: 5.0, dwell: 0.2 }).shape(l.samples(), 1000.0);
    let free_run = pr0.scaled(&shape);
    assert_eq!(free_run.binds, "voltage");
    let v = &pr0.values;
    let r = &free_run.response;
    let tmax = free_run.peaks.torque;
    assert!(tmax > 0.0);
    for (tau, th) in r.torque.iter().zip(&r.deflection) {
        let spring = v[ix::C] * th + v[ix::B] * th * th + v[ix::A] * th * th * th;
        assert!((tau - spring).abs() <= 1e-12 * tmax, "{tau} {spring}");
    }
    let travel = r.load.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(travel > 0.0 && travel <= free_run.peaks.load_angle);
    l.torque = Some(0.4 * tmax);
    let pr = Problem { limits: l.clone(), ..pr0.clone() };
    let s = pr.scaled(&shape);
    assert_eq!(s.binds, "torque");
    assert!(s.within && s.peaks.torque > 0.97 * 0.4 * tmax, "{:?}", s.peaks);
    l.torque = None;
    l.load_angle = Some(0.3 * free_run.peaks.load_angle);
    let pr = Problem { limits: l.clone(), ..pr0 };
    let s = pr.scaled(&shape);
    assert_eq!(s.binds, "load angle");
    let lim = l.load_angle.unwrap();
    assert!(s.within && s.peaks.load_angle > 0.97 * lim, "{:?}", s.peaks);
    assert!(s.peaks.voltage < 12.0);
    // The load speed is the rate of the load angle: its trapezoidal integral over the
    // samples follows the angle to the rule's error.
    let h = 1.0 / l.rate;
    let mut integral = 0.0;
    let mut worst = 0.0f64;
    for k in 1..r.load.len() {
        integral += 0.5 * h * (r.load_speed[k - 1] + r.load_speed[k]);
        worst = worst.max((integral - r.load[k]).abs());
    }
    assert!(worst <= 1e-3 * travel, "{worst} {travel}");
    l.load_angle = None;
    l.load_speed = Some(0.5 * free_run.peaks.load_speed);
    let pr = Problem { limits: l.clone(), ..pr.clone() };
    let s = pr.scaled(&shape);
    assert_eq!(s.binds, "load speed");
    assert!(s.within && s.peaks.load_speed > 0.97 * 0.5 * free_run.peaks.load_speed);
}

/// The seed drive in a motor-encoder loop with a voltage amplifier (kp 30 1/s, kv 0.5
/// V·s/rad, one sample's delay), its reference limited to `reference` [rad].
fn in_loop(free: &[usize], duration: f64, reference: f64) -> Problem {
    let controller = crate::drive::controller::Controller {
        kp: 30.0,
        kv: 0.5,
        saturation: f64::INFINITY,
        delay: 1,
        speed_filter: vec![1.0],
        h: 1e-3,
        open_loop: None,
    };
    let l = Limits { reference: Some(reference), ..limits(duration) };
    let mut pr = problem(free, l);
    let command_noise = command_noise(&controller, pr.noise.motor);
    pr.closed = Some(Loop {
        controller,
        feedback: crate::drive::compliant::Feedback::Motor,
        amplifier: crate::drive::compliant::Amplifier::Voltage,
        command_noise,
    });
    pr
}

/// The command noise of the cascade law on white encoder noise σ is its closed form: with
/// the one-tap speed filter, u_k = −kv·(kp + 1/h)·q_k + kv/h·q_(k−1), so
/// σ_u = σ·kv·√((kp + 1/h)² + 1/h²).
#[test]
fn command_noise_is_the_laws_closed_form() {
    let pr = in_loop(&[ix::R], 0.2, 0.5);
    let l = pr.closed.as_ref().unwrap();
    let c = &l.controller;
    let sigma = pr.noise.motor;
    let exact = sigma * c.kv * ((c.kp + 1.0 / c.h).powi(2) + 1.0 / (c.h * c.h)).sqrt();
    let rel = (l.command_noise / exact - 1.0).abs();
    assert!(rel < 2e-2, "{} {exact} ({rel:e})", l.command_noise);
}

/// In closed loop the input is the reference: a ramp reference scaled to its own limit
/// binds there, the voltage reported is the command the loop computed (its record's
/// command column, sample by sample), and a voltage limit below that peak binds instead.
#[test]
fn a_loop_design_scales_its_reference() {
    let pr = in_loop(&[ix::R, ix::KE, ix::JJ], 0.3, 0.5);
    let shape =
        Design::single(Segment::Ramp { f: 3.0, dwell: 0.2 }).shape(pr.limits.samples(), 1000.0);
    let s = pr.scaled(&shape);
    assert_eq!(s.binds, "reference", "{:?}", s.peaks);
    assert!((s.peaks.reference - 0.5).abs() < 1e-12 && s.within);
    let rec = pr.record(&s.u);
    assert_eq!(rec.u.len(), s.response.voltage.len());
    for (a, b) in rec.u.iter().zip(&s.response.voltage) {
        assert!((a - b).abs() <= 1e-12 * s.peaks.voltage.max(1.0), "{a} {b}");
    }
    assert!(s.peaks.voltage > 0.0);
    let l = Limits { voltage: 0.5 * s.peaks.voltage, ..pr.limits.clone() };
    let q = Problem { limits: l, ..pr.clone() };
    let t = q.scaled(&shape);
    assert_eq!(t.binds, "voltage");
    assert!(t.within && t.peaks.voltage > 0.97 * 0.5 * s.peaks.voltage && t.amplitude < 0.5);
}

/// The information of a loop record (motor and load encoders, current and the command, the
/// fed-back encoder's zero not fitted) equals central differences of its simulated outputs.
#[test]
fn loop_information_matches_central_differences() {
    let free = [ix::R, ix::KE, ix::JJ, ix::CJ, ix::JZ];
    let pr = in_loop(&free, 0.3, 0.5);
    let r: Vec<f64> = Design::single(Segment::Chirp { f0: 1.0, f1: 20.0 })
        .shape(pr.limits.samples(), 1000.0)
        .iter()
        .map(|v| 0.5 * v)
        .collect();
    let info = pr.information_all(&r).unwrap();
    let cn = pr.closed.as_ref().unwrap().command_noise;
    let outputs = |values: [f64; P]| -> Vec<f64> {
        let q = Problem { values, ..pr.clone() };
        let rec = q.record(&r);
        let m = rec.theta_l.iter().sum::<f64>() / rec.theta_l.len() as f64;
        let mut out: Vec<f64> = rec.theta_m.iter().map(|v| v / pr.noise.motor).collect();
        out.extend(rec.theta_l.iter().map(|v| (v - m) / pr.noise.load));
        out.extend(rec.current.unwrap().iter().map(|v| v / pr.noise.current.unwrap()));
        out.extend(rec.u.iter().map(|v| v / cn));
        out
    };
    let fd = difference_information(&pr, &free, &outputs);
    let mut worst = 0.0f64;
    for i in 0..free.len() {
        for j in 0..free.len() {
            let scale = (info[(i, i)] * info[(j, j)]).sqrt();
            worst = worst.max((info[(i, j)] - fd[(i, j)]).abs() / scale);
        }
    }
    assert!(worst < 1e-7, "{worst:e}");
}

/// The fade is a raised cosine: 0 at both ends, ½ at a quarter of its span, the input
/// itself beyond it.
#[test]
fn the_fade_is_a_raised_cosine() {
    let mut u = vec![2.0; 101];
    super::input::fade(&mut u, 0.1);
    // 10 samples each end: w(k) = (1 − cos(πk/10))/2.
    assert_eq!((u[0], u[100]), (0.0, 0.0));
    assert!((u[5] - 1.0).abs() < 1e-12 && (u[95] - 1.0).abs() < 1e-12, "{} {}", u[5], u[95]);
    assert!(u[10..=90].iter().all(|&v| v == 2.0));
    assert!(u[..10].windows(2).all(|w| w[0] < w[1]), "{:?}", &u[..10]);
}

/// A loop's designed reference starts and ends at zero (no step into the position loop),
/// and a multisine, which starts away from zero, keeps its shape between the fades.
#[test]
fn a_loop_reference_starts_and_ends_at_rest() {
    let pr = in_loop(&[ix::R, ix::KE, ix::JJ], 0.3, 0.5);
    let d = Design::single(Segment::Multisine { f0: 5.0, f1: 100.0, lines: 8, tilt: 0.0 });
    let shape = d.shape(pr.limits.samples(), 1000.0);
    let e = super::search::evaluate(&pr, &d, &Criterion::D);
    let (u, n) = (&e.scaled.u, e.scaled.u.len());
    assert_eq!((u[0], u[n - 1]), (0.0, 0.0));
    let m = (super::input::FADE * n as f64).round() as usize;
    let a = e.scaled.amplitude;
    for k in m..n - m {
        assert!((u[k] - a * shape[k]).abs() <= 1e-12 * a, "{k}");
    }
    // Within the fades the reference is the shape attenuated, and the fades had work to do.
    let ends: Vec<usize> = (0..m).chain(n - m..n).collect();
    assert!(ends.iter().all(|&k| u[k].abs() <= a * shape[k].abs() * (1.0 + 1e-12)));
    assert!(ends.iter().any(|&k| shape[k].abs() > 0.1), "the shape is small at its ends");
    assert!((u[n - 2] / (a * shape[n - 2])).abs() < 0.05, "{} {}", u[n - 2], shape[n - 2]);
    assert!(e.scaled.peaks.reference <= 0.5 * (1.0 + 1e-9));
}

/// On a linear drive, where both encoders creep throughout (an input of a millivolt), their
/// samples carry no information: what is left is the current's alone, the information of the same record
/// with both encoders' noise a million million times larger (to 1e-9 of the diagonal).
/// At 12 V the encoders move and count: the information exceeds the current's.
#[test]
fn creeping_encoders_count_for_nothing() {
    let free = [ix::R, ix::KE, ix::JJ, ix::CJ];
    let mut pr = problem(&free, limits(0.2));
    // Linear (as above), so that every output's sensitivity scales with the amplitude alike.
    for k in [ix::SIGMA0, ix::SIGMA1, ix::MEM_A, ix::A, ix::B] {
        pr.values[k] = 0.0;
    }
    let shape =
        Design::single(Segment::Chirp { f0: 2.0, f1: 40.0 }).shape(pr.limits.samples(), 1000.0);
    let deaf = Problem {
        noise: Noise { motor: pr.noise.motor * 1e12, load: pr.noise.load * 1e12, ..pr.noise },
        ..pr.clone()
    };
    let at = |a: f64| shape.iter().map(|v| a * v).collect::<Vec<_>>();
    let (counted, current) =
        (pr.information(&at(1e-3)).unwrap(), deaf.information_all(&at(1e-3)).unwrap());
    let all = pr.information_all(&at(1e-3)).unwrap();
    for i in 0..free.len() {
        for j in 0..free.len() {
            let scale = (current[(i, i)] * current[(j, j)]).sqrt();
            assert!(
                (counted[(i, j)] - current[(i, j)]).abs() < 1e-9 * scale,
                "{i} {j}: {counted} {current}"
            );
        }
        assert!(
            all[(i, i)] > 1.5 * current[(i, i)],
            "the encoders' rows were there to drop: {all} {current}"
        );
    }
    let (moving, current) =
        (pr.information(&at(12.0)).unwrap(), deaf.information_all(&at(12.0)).unwrap());
    assert!((0..free.len()).all(|i| moving[(i, i)] > 1.5 * current[(i, i)]), "{moving} {current}");
}
