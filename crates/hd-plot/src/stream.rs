//! A curve thinned while it is read, for curves too long to hold (a study's kept traces):
//! the points are grouped in consecutive buckets of `width` points, and each bucket keeps
//! its first, lowest, highest and last point. When the buckets outgrow their budget,
//! neighbours merge and `width` doubles, so memory stays bounded whatever the length,
//! while every extreme of the curve survives (the drawn envelope is the full curve's at
//! any resolution coarser than a bucket).

/// One bucket: its first, lowest, highest and last points, each with its index along the
/// curve (so they can be put back in order).
#[derive(Clone, Copy, Debug)]
struct Bucket {
    first: (u64, f64, f64),
    low: (u64, f64, f64),
    high: (u64, f64, f64),
    last: (u64, f64, f64),
}

impl Bucket {
    fn of(p: (u64, f64, f64)) -> Self {
        Bucket { first: p, low: p, high: p, last: p }
    }

    fn add(&mut self, p: (u64, f64, f64)) {
        if p.2 < self.low.2 {
            self.low = p;
        }
        if p.2 > self.high.2 {
            self.high = p;
        }
        self.last = p;
    }

    fn merge(self, next: Bucket) -> Bucket {
        Bucket {
            first: self.first,
            low: if next.low.2 < self.low.2 { next.low } else { self.low },
            high: if next.high.2 > self.high.2 { next.high } else { self.high },
            last: next.last,
        }
    }
}

/// A curve (x, y) thinned to at most `4 × buckets` points as its points arrive in order.
#[derive(Clone, Debug)]
pub struct ThinnedCurve {
    buckets: Vec<Bucket>,
    budget: usize,
    width: u64,
    count: u64,
}

impl ThinnedCurve {
    /// A curve that keeps at most `budget` buckets (at least 2).
    pub fn new(budget: usize) -> Self {
        ThinnedCurve { buckets: Vec::new(), budget: budget.max(2), width: 1, count: 0 }
    }

    /// Add the next point of the curve.
    pub fn push(&mut self, x: f64, y: f64) {
        let p = (self.count, x, y);
        if self.count.is_multiple_of(self.width) {
            if self.buckets.len() == self.budget {
                self.halve();
            }
            if self.count.is_multiple_of(self.width) {
                self.buckets.push(Bucket::of(p));
            } else if let Some(b) = self.buckets.last_mut() {
                b.add(p);
            }
        } else if let Some(b) = self.buckets.last_mut() {
            b.add(p);
        }
        self.count += 1;
    }

    /// Points read so far.
    pub fn len(&self) -> u64 {
        self.count
    }

    /// Whether no point was read.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Merge neighbouring buckets: twice the width, half as many.
    fn halve(&mut self) {
        let merged: Vec<Bucket> = self
            .buckets
            .chunks(2)
            .map(|pair| if pair.len() == 2 { pair[0].merge(pair[1]) } else { pair[0] })
            .collect();
        self.buckets = merged;
        self.width *= 2;
    }

    /// The kept points in their order along the curve, as x and y columns.
    pub fn points(&self) -> (Vec<f64>, Vec<f64>) {
        let mut x = Vec::with_capacity(4 * self.buckets.len());
        let mut y = Vec::with_capacity(4 * self.buckets.len());
        for b in &self.buckets {
            let mut four = [b.first, b.low, b.high, b.last];
            four.sort_by_key(|p| p.0);
            for (k, p) in four.iter().enumerate() {
                if k == 0 || p.0 != four[k - 1].0 {
                    x.push(p.1);
                    y.push(p.2);
                }
            }
        }
        (x, y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_short_curve_is_kept_whole() {
        let mut c = ThinnedCurve::new(100);
        for k in 0..50 {
            c.push(k as f64, (k * k) as f64);
        }
        let (x, y) = c.points();
        assert_eq!(x, (0..50).map(|k| k as f64).collect::<Vec<_>>());
        assert_eq!(y[49], 2401.0);
    }

    #[test]
    fn a_long_curve_stays_bounded_and_keeps_its_extremes_in_order() {
        let budget = 64;
        let mut c = ThinnedCurve::new(budget);
        let n = 1_000_003u64;
        // A sine with one spike up and one down far from the bucket edges.
        let y = |k: u64| match k {
            333_333 => 50.0,
            777_777 => -40.0,
            _ => (k as f64 * 1e-4).sin(),
        };
        for k in 0..n {
            c.push(k as f64, y(k));
        }
        assert_eq!(c.len(), n);
        let (xs, ys) = c.points();
        assert!(xs.len() <= 4 * budget, "{} points", xs.len());
        assert!(xs.windows(2).all(|w| w[0] < w[1]), "points out of order");
        assert_eq!(xs[0], 0.0);
        assert_eq!(*xs.last().unwrap(), (n - 1) as f64);
        let max = ys.iter().cloned().fold(f64::MIN, f64::max);
        let min = ys.iter().cloned().fold(f64::MAX, f64::min);
        assert_eq!((max, min), (50.0, -40.0));
        let at = |v: f64| xs[ys.iter().position(|&u| u == v).unwrap()];
        assert_eq!((at(50.0), at(-40.0)), (333_333.0, 777_777.0));
    }
}
