//! LU factorisation of the Rosenbrock iteration matrix `W = d·I − J` (d = 1/(h·γ)) that
//! exploits the system's block structure: only the leading `m × m` block of coupled
//! states is factorised (partial pivoting, on the stack); the quadrature rows below it,
//! whose own columns of J are zero, are solved by substitution; states beyond the live
//! ones have zero rates and are not touched.

use nalgebra::{SMatrix, SVector};

/// Largest coupled block the factorisation holds (the drive has at most 11).
pub(crate) const MAX_BLOCK: usize = 12;

/// The factorised coupled block of an iteration matrix.
pub(crate) struct BlockLu {
    /// L (unit diagonal, below) and U (on and above the diagonal), row-major.
    a: [[f64; MAX_BLOCK]; MAX_BLOCK],
    piv: [usize; MAX_BLOCK],
    /// Reciprocals of U's diagonal.
    inv_u: [f64; MAX_BLOCK],
    /// Reciprocals of the quadrature rows' diagonal `d − J_ii`, from row m on.
    inv_q: [f64; 32],
    m: usize,
    n: usize,
}

impl BlockLu {
    /// Factorise the coupled block of `d·I − jac` (m coupled states, n live states);
    /// `None` if it is singular.
    pub(crate) fn new<const D: usize>(
        jac: &SMatrix<f64, D, D>,
        d: f64,
        m: usize,
        n: usize,
    ) -> Option<Self> {
        assert!(m <= MAX_BLOCK, "a coupled block of {m} states exceeds {MAX_BLOCK}");
        let mut a = [[0.0; MAX_BLOCK]; MAX_BLOCK];
        for (r, row) in a.iter_mut().enumerate().take(m) {
            for (c, v) in row.iter_mut().enumerate().take(m) {
                *v = -jac[(r, c)];
            }
            row[r] += d;
        }
        let mut piv = [0usize; MAX_BLOCK];
        for k in 0..m {
            let mut p = k;
            let mut best = a[k][k].abs();
            for (r, row) in a.iter().enumerate().take(m).skip(k + 1) {
                if row[k].abs() > best {
                    best = row[k].abs();
                    p = r;
                }
            }
            if best == 0.0 || !best.is_finite() {
                return None;
            }
            piv[k] = p;
            a.swap(k, p);
            let inv = 1.0 / a[k][k];
            let pivot_row = a[k];
            for row in a.iter_mut().take(m).skip(k + 1) {
                let l = row[k] * inv;
                row[k] = l;
                if l != 0.0 {
                    for c in k + 1..m {
                        row[c] -= l * pivot_row[c];
                    }
                }
            }
        }
        assert!(n - m <= 32, "{} quadrature states exceed 32", n - m);
        let mut inv_u = [0.0; MAX_BLOCK];
        for (k, v) in inv_u.iter_mut().enumerate().take(m) {
            *v = 1.0 / a[k][k];
        }
        let mut inv_q = [0.0; 32];
        for i in m..n {
            let w = d - jac[(i, i)];
            if w == 0.0 {
                return None;
            }
            inv_q[i - m] = 1.0 / w;
        }
        Some(Self { a, piv, inv_u, inv_q, m, n })
    }

    /// Solve `W·x = b`, W being `d·I − jac` with the `jac` the factorisation was made from.
    pub(crate) fn solve<const D: usize>(
        &self,
        jac: &SMatrix<f64, D, D>,
        b: &SVector<f64, D>,
    ) -> SVector<f64, D> {
        let (m, n) = (self.m, self.n);
        let mut x = SVector::<f64, D>::zeros();
        let mut z = [0.0; MAX_BLOCK];
        z[..m].copy_from_slice(&b.as_slice()[..m]);
        for k in 0..m {
            z.swap(k, self.piv[k]);
        }
        for r in 1..m {
            let dot: f64 = self.a[r][..r].iter().zip(&z[..r]).map(|(l, zc)| l * zc).sum();
            z[r] -= dot;
        }
        for r in (0..m).rev() {
            let dot: f64 = self.a[r][r + 1..m].iter().zip(&z[r + 1..m]).map(|(u, zc)| u * zc).sum();
            z[r] = (z[r] - dot) * self.inv_u[r];
        }
        x.as_mut_slice()[..m].copy_from_slice(&z[..m]);
        // Quadrature rows: (d − J_ii)·x_i − Σ_{j<m} J_ij·x_j = b_i.
        for i in m..n {
            let mut s = b[i];
            for (c, zc) in z.iter().enumerate().take(m) {
                s += jac[(i, c)] * zc;
            }
            x[i] = s * self.inv_q[i - m];
        }
        x
    }
}
