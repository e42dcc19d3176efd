//! `hdw design`: the input that determines what a fit could not (issue #54).
//!
//! Given the compliant drive ([`crate::drive::compliant`]) at its fitted (or given)
//! parameters, the free ones, the noise levels of a new record and the rig's limits, a
//! candidate input's Fisher information is the compliant fit's own exact Jacobian on a
//! noise-free record of it, JᵀJ with each output divided by its noise ([`info`]). The
//! input families ([`input`]) are multisines, chirps, slow ramps with dwell and their
//! concatenation; each candidate is scaled to the largest amplitude whose simulated peaks
//! (voltage, current, motor speed, gear deflection, transmitted torque, load travel) stay
//! within the limits; a few family parameters are searched by Nelder–Mead ([`search`]) on a
//! D-, A- or targeted criterion of the prior (the fitted records') plus the candidate's
//! information ([`criterion`]). The spectrum family chooses a multisine's every line from
//! the information of each line alone ([`spectrum`]).
//!
//! A drive logged in its own loop is designed for through its position reference
//! ([`closed`]).
//!
//! Main items: [`Problem`], [`Limits`], [`Criterion`], [`Family`], [`design`], [`Outcome`].

pub mod closed;
pub mod criterion;
pub mod info;
pub mod input;
pub mod search;
pub mod spectrum;

#[cfg(test)]
mod tests;

pub use closed::{Loop, command_noise};
pub use criterion::{Criterion, Prediction, direction_variance, predict, weakest};
pub use info::{Limits, Noise, Peaks, Problem, Response, Scaled, prior_information};
pub use input::{Design, Family, Piece, Segment};
pub use search::{Evaluated, Optimised, evaluate, optimise};

use nalgebra::{DMatrix, DVector};

/// Tones of the default multisine (`hdw synth drive`'s) [–].
pub const DEFAULT_TONES: usize = 12;

/// The default inputs a design is compared with, at the same duration and limits: `hdw
/// synth drive`'s chirp and multisine of its default band, 2–200 Hz (the top at most
/// 0.45 × the rate).
pub fn defaults(rate: f64) -> Vec<(&'static str, Design)> {
    let f1 = 200f64.min(0.45 * rate);
    let f0 = 2f64.min(0.5 * f1);
    vec![
        ("default chirp", Design::single(Segment::Chirp { f0, f1 })),
        (
            "default multisine",
            Design::single(Segment::Multisine { f0, f1, lines: DEFAULT_TONES, tilt: 0.0 }),
        ),
    ]
}

/// What [`design`] found.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The criterion optimised.
    pub criterion: Criterion,
    /// The best input per family searched, best first.
    pub searched: Vec<Optimised>,
    /// The default inputs, scaled and judged by the same criterion.
    pub defaults: Vec<(&'static str, Evaluated)>,
    /// The prior's weakest direction (unit, log coordinates) and its eigenvalue.
    pub weakest: (DVector<f64>, f64),
}

impl Outcome {
    /// The designed input: the best family's best candidate.
    pub fn best(&self) -> &Evaluated {
        &self.searched[0].best
    }

    /// Variance along the prior's weakest direction with the prior and `info` [–].
    pub fn weakest_variance(&self, prior: &DMatrix<f64>, info: &DMatrix<f64>) -> f64 {
        direction_variance(&(prior + info), &self.weakest.0)
    }
}

/// Design the input for `problem`: search each of `families` (at most `evaluations`
/// candidates each) on `criterion`, and judge the defaults likewise. `progress(family,
/// evaluations, best cost)`.
pub fn design(
    problem: &Problem,
    criterion: Criterion,
    families: &[Family],
    evaluations: usize,
    progress: &(dyn Fn(Family, usize, f64) + Sync),
) -> Outcome {
    let (dirs, eig) = weakest(&problem.prior);
    let weakest = (dirs.column(0).into_owned(), eig[0]);
    // The Nelder–Mead families first: their best inputs are elements of the spectrum's.
    let mut searched: Vec<Optimised> = families
        .iter()
        .filter(|&&f| f != Family::Spectrum)
        .map(|&f| optimise(problem, f, &criterion, evaluations, &|n, c| progress(f, n, c)))
        .collect();
    if families.contains(&Family::Spectrum) {
        let f = Family::Spectrum;
        let others: Vec<&Evaluated> = searched.iter().map(|o| &o.best).collect();
        let o = spectrum::optimise(problem, &criterion, &others, &|n, c| progress(f, n, c));
        searched.push(o);
    }
    searched.sort_by(|a, b| a.best.cost.total_cmp(&b.best.cost));
    let defaults = defaults(problem.limits.rate)
        .into_iter()
        .map(|(name, d)| (name, evaluate(problem, &d, &criterion)))
        .collect();
    Outcome { criterion, searched, defaults, weakest }
}

/// The targeted criterion of `problem`: the prior's weakest directions.
pub fn targeted(problem: &Problem) -> Criterion {
    Criterion::Targeted(weakest(&problem.prior).0)
}

/// A given input `u` [V, or rad of a closed loop's reference] judged for `problem` as it is (not rescaled): its peaks against
/// the limits, its information, and the defaults beside it.
pub fn given(problem: &Problem, criterion: Criterion, u: &[f64]) -> Outcome {
    let (dirs, eig) = weakest(&problem.prior);
    let weakest = (dirs.column(0).into_owned(), eig[0]);
    let (peaks, response) = problem.response(u);
    let (worst, ratio) = peaks.worst(&problem.limits);
    let scaled = Scaled {
        u: u.to_vec(),
        peaks,
        response,
        binds: worst,
        within: ratio <= 1.0 + 1e-9,
        amplitude: if problem.closed.is_some() { peaks.reference } else { peaks.voltage },
    };
    let k = problem.free.len();
    let info = problem.information(u).unwrap_or_else(|| DMatrix::zeros(k, k));
    let cost = criterion.cost(&(&problem.prior + &info));
    let best = Evaluated { design: Design { pieces: Vec::new() }, scaled, info, cost };
    let defaults = defaults(problem.limits.rate)
        .into_iter()
        .map(|(name, d)| (name, evaluate(problem, &d, &criterion)))
        .collect();
    Outcome {
        criterion,
        searched: vec![Optimised { family: Family::Mix, x: Vec::new(), best, evaluations: 0 }],
        defaults,
        weakest,
    }
}
