//! Point sets: the product of grid axes (with zipped groups), seeded random designs
//! (plain uniform and Latin hypercube) and global-sensitivity designs (Saltelli, Morris)
//! inside bounds, optionally in log space.

use crate::axis::{Knob, Value};
use crate::sensitivity::{Design, DesignPoint};
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

/// Design kinds of a `[sample]` section.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleMethod {
    /// Latin hypercube: each dimension's range split in n strata, one point per stratum.
    Lhs,
    /// Independent uniform points.
    Random,
    /// Saltelli design for Sobol' indices: n base samples, n·(d + 2) points.
    Sobol,
    /// Morris trajectories for elementary-effects screening: n trajectories, n·(d + 1)
    /// points.
    Morris,
}

impl SampleMethod {
    /// Lower-case name, as written in study files.
    pub fn name(self) -> &'static str {
        match self {
            SampleMethod::Lhs => "lhs",
            SampleMethod::Random => "random",
            SampleMethod::Sobol => "sobol",
            SampleMethod::Morris => "morris",
        }
    }
}

/// A sampled design.
#[derive(Clone, Debug)]
pub struct Sample {
    /// Kind of design.
    pub method: SampleMethod,
    /// Points (lhs, random), base samples (sobol) or trajectories (morris).
    pub n: usize,
    /// Seed of the generator (for sobol: of the digital shift, when `Some`); `None` means
    /// 0 for lhs, random and morris, and the unshifted sequence for sobol.
    pub seed: Option<u64>,
    /// Sampled dimensions, in the order of the design's unit coordinates.
    pub bounds: Vec<Bound>,
    /// The unit-cube design of a sobol or morris sample (its points carry their tags);
    /// `None` for lhs and random. Built and checked when the study is parsed.
    pub design: Option<Design>,
}

impl Sample {
    /// Number of points the design gives: n for lhs and random, n·(d + 2) for sobol and
    /// n·(d + 1) for morris.
    pub fn n_points(&self) -> usize {
        self.design.as_ref().map_or(self.n, |d| d.points.len())
    }

    /// The tagged unit-cube points of a sobol or morris design, in generator order.
    pub fn design_points(&self) -> Option<&[DesignPoint]> {
        self.design.as_ref().map(|d| d.points.as_slice())
    }
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

/// The points of a sampled design (for sobol and morris, in the design's order).
pub fn sample_points(s: &Sample) -> Vec<Point> {
    sample_units(s)
        .iter()
        .map(|row| s.bounds.iter().zip(row).map(|(b, &u)| (b.knob, Value::Num(b.map(u)))).collect())
        .collect()
}

/// The unit-cube coordinates of a sampled design, one row of `bounds.len()` values per
/// point (for sobol and morris, in the design's order). Held once per part while a study
/// runs: n · d numbers, whatever the size of the grid it is combined with.
pub fn sample_units(s: &Sample) -> Vec<Vec<f64>> {
    if let Some(points) = s.design_points() {
        return points.iter().map(|p| p.unit.clone()).collect();
    }
    let mut rng = ChaCha8Rng::seed_from_u64(s.seed.unwrap_or(0));
    let d = s.bounds.len();
    let mut unit = vec![vec![0.0; d]; s.n];
    match s.method {
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
        // Sobol and Morris samples always carry their design; uniform points otherwise.
        SampleMethod::Random | SampleMethod::Sobol | SampleMethod::Morris => {
            for row in unit.iter_mut() {
                for u in row.iter_mut() {
                    *u = rng.random::<f64>();
                }
            }
        }
    }
    unit
}

#[cfg(test)]
mod tests {
    use super::*;
    use hd_model::registry::lookup;

    fn bound(name: &str, lo: f64, hi: f64, log: bool) -> Bound {
        Bound { knob: Knob::Param(lookup(name).unwrap()), lo, hi, log }
    }

    fn num(v: &Value) -> f64 {
        match v {
            Value::Num(x) => *x,
            _ => f64::NAN,
        }
    }

    #[test]
    fn latin_hypercube_puts_one_point_in_every_stratum_of_every_dimension() {
        let n = 50;
        let s = Sample {
            method: SampleMethod::Lhs,
            n,
            seed: Some(7),
            bounds: vec![bound("c", 1e4, 1e5, false), bound("sigma0", 1e4, 1e6, true)],
            design: None,
        };
        let pts = sample_points(&s);
        assert_eq!(pts.len(), n);
        for (j, b) in s.bounds.iter().enumerate() {
            let mut hit = vec![0; n];
            for p in &pts {
                let x = num(&p[j].1);
                let u = if b.log {
                    (x / b.lo).ln() / (b.hi / b.lo).ln()
                } else {
                    (x - b.lo) / (b.hi - b.lo)
                };
                hit[((u * n as f64) as usize).min(n - 1)] += 1;
            }
            assert!(hit.iter().all(|&h| h == 1), "dimension {j}: {hit:?}");
        }
        // Same seed, same design; another seed, another design.
        assert_eq!(num(&sample_points(&s)[3][0].1), num(&pts[3][0].1));
        let other = Sample { seed: Some(8), ..s.clone() };
        assert_ne!(num(&sample_points(&other)[3][0].1), num(&pts[3][0].1));
    }

    #[test]
    fn zipped_axes_advance_together_inside_a_product() {
        let axis = |name: &str, xs: &[f64], zip: Option<&str>| Axis {
            knob: Knob::Param(lookup(name).unwrap()),
            values: xs.iter().map(|x| Value::Num(*x)).collect(),
            zip: zip.map(str::to_string),
        };
        let axes = [
            axis("c", &[1.0, 2.0, 3.0], Some("g")),
            axis("A", &[5.0, 6.0], None),
            axis("B", &[10.0, 20.0, 30.0], Some("g")),
        ];
        let pts = grid_points(&axes);
        assert_eq!(pts.len(), 6);
        for p in &pts {
            assert_eq!(num(&p[0].1) * 10.0, num(&p[1].1), "c and B move together: {p:?}");
        }
    }
}
