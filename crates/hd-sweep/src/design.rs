//! Point sets: the product of grid axes (with zipped groups) and seeded random designs
//! (plain uniform and Latin hypercube) inside bounds, optionally in log space.

use crate::axis::{Knob, Value};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A checked grid axis.
#[derive(Clone, Debug)]
pub struct Axis {
    /// What it sets.
    pub knob: Knob,
    /// Its values, in order.
    pub values: Vec<Value>,
    /// Zip label: axes sharing one advance together.
    pub zip: Option<String>,
}

/// A sampled dimension with bounds.
#[derive(Clone, Debug)]
pub struct Bound {
    /// What it sets.
    pub knob: Knob,
    /// Lower bound.
    pub lo: f64,
    /// Upper bound.
    pub hi: f64,
    /// Uniform in log space.
    pub log: bool,
}

impl Bound {
    /// Map a unit coordinate u ∈ [0, 1] into the bounds.
    pub fn map(&self, u: f64) -> f64 {
        if self.log {
            (self.lo.ln() + u * (self.hi.ln() - self.lo.ln())).exp()
        } else {
            self.lo + u * (self.hi - self.lo)
        }
    }
}

/// Random design kinds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleMethod {
    /// Latin hypercube: each dimension's range split in n strata, one point per stratum.
    Lhs,
    /// Independent uniform points.
    Random,
}

/// A random design.
#[derive(Clone, Debug)]
pub struct Sample {
    /// Kind of design.
    pub method: SampleMethod,
    /// Number of points.
    pub n: usize,
    /// Seed.
    pub seed: u64,
    /// Sampled dimensions.
    pub bounds: Vec<Bound>,
}

/// One point: the knobs and values it sets.
pub type Point = Vec<(Knob, Value)>;

/// All points of the grid: zipped groups advance together; groups form a product with the
/// first group varying slowest. No axes gives one empty point.
pub fn grid_points(axes: &[Axis]) -> Vec<Point> {
    // Groups in order of first appearance; an axis without a zip label is its own group.
    let mut groups: Vec<Vec<&Axis>> = Vec::new();
    let mut labels: Vec<Option<&str>> = Vec::new();
    for a in axes {
        match a.zip.as_deref().and_then(|z| labels.iter().position(|l| *l == Some(z))) {
            Some(g) => groups[g].push(a),
            None => {
                groups.push(vec![a]);
                labels.push(a.zip.as_deref());
            }
        }
    }
    let mut points: Vec<Point> = vec![Vec::new()];
    for group in groups {
        let len = group[0].values.len();
        let mut next = Vec::with_capacity(points.len() * len);
        for p in &points {
            for k in 0..len {
                let mut q = p.clone();
                q.extend(group.iter().map(|a| (a.knob, a.values[k])));
                next.push(q);
            }
        }
        points = next;
    }
    points
}

/// The points of a random design.
pub fn sample_points(s: &Sample) -> Vec<Point> {
    let mut rng = ChaCha8Rng::seed_from_u64(s.seed);
    let d = s.bounds.len();
    let mut unit = vec![vec![0.0; d]; s.n];
    match s.method {
        SampleMethod::Random => {
            for row in unit.iter_mut() {
                for u in row.iter_mut() {
                    *u = rng.random::<f64>();
                }
            }
        }
        SampleMethod::Lhs => {
            for j in 0..d {
                let mut strata: Vec<usize> = (0..s.n).collect();
                // Fisher–Yates shuffle of the strata for this dimension.
                for i in (1..s.n).rev() {
                    let k = rng.random_range(0..=i);
                    strata.swap(i, k);
                }
                for (i, row) in unit.iter_mut().enumerate() {
                    row[j] = (strata[i] as f64 + rng.random::<f64>()) / s.n as f64;
                }
            }
        }
    }
    unit.into_iter()
        .map(|row| s.bounds.iter().zip(row).map(|(b, u)| (b.knob, Value::Num(b.map(u)))).collect())
        .collect()
}
