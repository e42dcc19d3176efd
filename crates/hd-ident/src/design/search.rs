//! The search over a family's few parameters: Nelder–Mead within bounds (a point outside is
//! clamped onto the box), each candidate scaled to the limits and judged by the criterion
//! on the prior plus its information.

use super::criterion::Criterion;
use super::info::{Problem, Scaled};
use super::input::{Design, FADE, Family, fade};
use nalgebra::DMatrix;
use rayon::prelude::*;

/// A candidate input, scaled and judged.
#[derive(Clone, Debug)]
pub struct Evaluated {
    /// The input's shape.
    pub design: Design,
    /// Scaled to the limits.
    pub scaled: Scaled,
    /// Its information (log coordinates, no prior).
    pub info: DMatrix<f64>,
    /// The criterion on prior + info (lower is better; infinite where it cannot be run).
    pub cost: f64,
}

/// Scale `design` to the limits (faded in and out first in closed loop, [`fade`]) and judge
/// it by `criterion`.
pub fn evaluate(problem: &Problem, design: &Design, criterion: &Criterion) -> Evaluated {
    let mut shape = design.shape(problem.limits.samples(), problem.limits.rate);
    if problem.closed.is_some() {
        fade(&mut shape, FADE);
    }
    let scaled = problem.scaled(&shape);
    let k = problem.free.len();
    let (info, cost) = match problem.information(&scaled.u) {
        Some(info) if scaled.within => {
            let cost = criterion.cost(&(&problem.prior + &info));
            (info, if cost.is_finite() { cost } else { f64::INFINITY })
        }
        Some(info) => (info, f64::INFINITY),
        None => (DMatrix::zeros(k, k), f64::INFINITY),
    };
    Evaluated { design: design.clone(), scaled, info, cost }
}

/// The result of [`optimise`].
#[derive(Clone, Debug)]
pub struct Optimised {
    /// The family searched.
    pub family: Family,
    /// Its parameters at the best point.
    pub x: Vec<f64>,
    /// The best candidate.
    pub best: Evaluated,
    /// Candidates evaluated.
    pub evaluations: usize,
}

/// Search `family`'s parameters for the input that minimises `criterion`, at most
/// `max_evaluations` candidates; `progress(evaluations, best cost)` after each.
pub fn optimise(
    problem: &Problem,
    family: Family,
    criterion: &Criterion,
    max_evaluations: usize,
    progress: &(dyn Fn(usize, f64) + Sync),
) -> Optimised {
    let params = family.params(problem.limits.rate, problem.limits.duration);
    let lo: Vec<f64> = params.iter().map(|p| p.1).collect();
    let hi: Vec<f64> = params.iter().map(|p| p.2).collect();
    let x0: Vec<f64> = params.iter().map(|p| p.3).collect();
    let count = std::sync::atomic::AtomicUsize::new(0);
    let f = |x: &[f64]| {
        let e = evaluate(problem, &family.design(x), criterion);
        let n = count.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        progress(n, e.cost);
        e
    };
    let (x, best) = nelder_mead(&f, &x0, &lo, &hi, max_evaluations, |e: &Evaluated| e.cost);
    Optimised { family, x, best, evaluations: count.into_inner() }
}

/// Nelder–Mead on `f` (judged by `cost`) from `x0` within [`lo`, `hi`], at most
/// `max_evaluations` evaluations; the first simplex is evaluated in parallel. Returns the
/// best point and its value.
pub fn nelder_mead<E: Clone + Send>(
    f: &(dyn Fn(&[f64]) -> E + Sync),
    x0: &[f64],
    lo: &[f64],
    hi: &[f64],
    max_evaluations: usize,
    cost: impl Fn(&E) -> f64,
) -> (Vec<f64>, E) {
    let n = x0.len();
    let clamp = |x: Vec<f64>| -> Vec<f64> {
        x.iter().zip(lo.iter().zip(hi)).map(|(v, (a, b))| v.clamp(*a, *b)).collect()
    };
    let mut pts: Vec<Vec<f64>> = vec![clamp(x0.to_vec())];
    for i in 0..n {
        let mut x = pts[0].clone();
        let step = 0.2 * (hi[i] - lo[i]);
        x[i] = if x[i] + step <= hi[i] { x[i] + step } else { x[i] - step };
        pts.push(clamp(x));
    }
    let vals: Vec<E> = pts.par_iter().map(|x| f(x)).collect();
    let mut simplex: Vec<(Vec<f64>, E, f64)> = pts
        .into_iter()
        .zip(vals)
        .map(|(x, e)| {
            let c = cost(&e);
            (x, e, c)
        })
        .collect();
    let mut used = n + 1;
    let key = |c: f64| if c.is_nan() { f64::INFINITY } else { c };
    while used < max_evaluations {
        simplex.sort_by(|a, b| key(a.2).total_cmp(&key(b.2)));
        let (best, worst) = (key(simplex[0].2), key(simplex[n].2));
        if best.is_finite() && (worst - best).abs() <= 1e-6 * best.abs().max(1e-12) {
            break;
        }
        let centroid: Vec<f64> =
            (0..n).map(|i| simplex[..n].iter().map(|s| s.0[i]).sum::<f64>() / n as f64).collect();
        let along = |t: f64| -> Vec<f64> {
            clamp((0..n).map(|i| centroid[i] + t * (simplex[n].0[i] - centroid[i])).collect())
        };
        let try_at = |x: Vec<f64>, used: &mut usize| {
            let e = f(&x);
            *used += 1;
            let c = key(cost(&e));
            (x, e, c)
        };
        let r = try_at(along(-1.0), &mut used);
        if r.2 < key(simplex[0].2) {
            let e = try_at(along(-2.0), &mut used);
            simplex[n] = if e.2 < r.2 { e } else { r };
        } else if r.2 < key(simplex[n - 1].2) {
            simplex[n] = r;
        } else {
            let c = if r.2 < worst {
                try_at(along(-0.5), &mut used)
            } else {
                try_at(along(0.5), &mut used)
            };
            if c.2 < worst.min(r.2) {
                simplex[n] = c;
            } else {
                // Shrink towards the best.
                let b = simplex[0].0.clone();
                let pts: Vec<Vec<f64>> = simplex[1..]
                    .iter()
                    .map(|s| clamp(s.0.iter().zip(&b).map(|(x, y)| y + 0.5 * (x - y)).collect()))
                    .collect();
                let vals: Vec<E> = pts.par_iter().map(|x| f(x)).collect();
                used += n;
                for (s, (x, e)) in simplex[1..].iter_mut().zip(pts.into_iter().zip(vals)) {
                    let c = key(cost(&e));
                    *s = (x, e, c);
                }
            }
        }
    }
    simplex.sort_by(|a, b| key(a.2).total_cmp(&key(b.2)));
    let (x, e, _) = simplex.swap_remove(0);
    (x, e)
}
