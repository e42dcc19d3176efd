//! LU factorisation of the Rosenbrock iteration matrix `W = I/(h·γ) − J` that exploits the
//! quadrature block: rows at and beyond `m` have a diagonal quadrature part, so only the
//! leading `m × m` block is factorised (partial pivoting) and the rest is substitution.

use nalgebra::{SMatrix, SVector};

/// A factorised iteration matrix.
pub(crate) struct BlockLu<const D: usize> {
    w: SMatrix<f64, D, D>,
    piv: [usize; D],
    m: usize,
}

impl<const D: usize> BlockLu<D> {
    /// Factorise `W = diag/(…) − J` given as the full matrix `w`; `None` if singular.
    pub(crate) fn new(mut w: SMatrix<f64, D, D>, m: usize) -> Option<Self> {
        let mut piv = [0usize; D];
        for k in 0..m {
            let mut p = k;
            let mut best = w[(k, k)].abs();
            for r in k + 1..m {
                let v = w[(r, k)].abs();
                if v > best {
                    best = v;
                    p = r;
                }
            }
            if best == 0.0 || !best.is_finite() {
                return None;
            }
            piv[k] = p;
            if p != k {
                w.swap_rows(k, p);
            }
            let inv = 1.0 / w[(k, k)];
            for r in k + 1..m {
                let l = w[(r, k)] * inv;
                w[(r, k)] = l;
                if l != 0.0 {
                    for c in k + 1..m {
                        w[(r, c)] -= l * w[(k, c)];
                    }
                }
            }
        }
        for i in m..D {
            if w[(i, i)] == 0.0 {
                return None;
            }
        }
        Some(Self { w, piv, m })
    }

    /// Solve `W·x = b`.
    pub(crate) fn solve(&self, b: &SVector<f64, D>) -> SVector<f64, D> {
        let m = self.m;
        let mut x = *b;
        for k in 0..m {
            x.swap_rows(k, self.piv[k]);
        }
        for r in 1..m {
            let mut s = x[r];
            for c in 0..r {
                s -= self.w[(r, c)] * x[c];
            }
            x[r] = s;
        }
        for r in (0..m).rev() {
            let mut s = x[r];
            for c in r + 1..m {
                s -= self.w[(r, c)] * x[c];
            }
            x[r] = s / self.w[(r, r)];
        }
        // Quadrature rows: W[i, i]·x_i + Σ_{j<m} W[i, j]·x_j = b_i (their rows were not
        // pivoted, and their columns are zero above the diagonal).
        for i in m..D {
            let mut s = b[i];
            for c in 0..m {
                s -= self.w[(i, c)] * x[c];
            }
            x[i] = s / self.w[(i, i)];
        }
        x
    }
}
