//! The triangular factor of a tall matrix's QR factorisation, accumulated row by row in
//! blocks: the p×p factor R of an n×p matrix without holding the matrix (memory O(p²)
//! plus one block). Each full block is stacked under the R so far and factorised again
//! (Householder, nalgebra), which is as stable as one QR of the whole matrix.
//!
//! R is what the least-squares solves and the covariance need: with the right-hand side
//! as the last column, R's last column holds Qᵀy and its corner the residual norm.

use nalgebra::DMatrix;

/// Rows per block.
const BLOCK: usize = 512;

/// R of a QR factorisation, built from rows.
pub struct StreamingQr {
    p: usize,
    /// The factor so far (p×p, upper triangular), or none before the first block.
    r: Option<DMatrix<f64>>,
    /// Rows waiting, row-major.
    rows: Vec<f64>,
}

impl StreamingQr {
    /// An empty factorisation of a matrix with `p` columns.
    pub fn new(p: usize) -> Self {
        Self { p, r: None, rows: Vec::with_capacity(BLOCK * p) }
    }

    /// Append one row (length p).
    pub fn push(&mut self, row: &[f64]) {
        debug_assert_eq!(row.len(), self.p);
        self.rows.extend_from_slice(row);
        if self.rows.len() == BLOCK * self.p {
            self.flush();
        }
    }

    fn flush(&mut self) {
        let p = self.p;
        let b = self.rows.len() / p;
        if b == 0 {
            return;
        }
        let top = self.r.as_ref().map_or(0, |_| p);
        let mut m = DMatrix::<f64>::zeros(top + b, p);
        if let Some(r) = &self.r {
            m.view_mut((0, 0), (p, p)).copy_from(r);
        }
        for i in 0..b {
            for j in 0..p {
                m[(top + i, j)] = self.rows[i * p + j];
            }
        }
        self.rows.clear();
        let r = m.qr().r();
        // Fewer rows than columns so far: pad R to p×p.
        let mut full = DMatrix::<f64>::zeros(p, p);
        full.view_mut((0, 0), (r.nrows(), p)).copy_from(&r);
        self.r = Some(full);
    }

    /// The p×p upper-triangular factor (zeros when no row was pushed).
    pub fn finish(mut self) -> DMatrix<f64> {
        self.flush();
        self.r.unwrap_or_else(|| DMatrix::zeros(self.p, self.p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// RᵀR = AᵀA (R is unique up to the signs of its rows), on a matrix that spans
    /// several blocks and whose columns differ in size by nine decades.
    #[test]
    fn gram_matrix_is_kept() {
        let n = 1300;
        let row = |i: usize| {
            let x = 1e-3 * ((i as f64) * 0.37).sin();
            [x * x * x, x, 1.0, (i as f64 * 0.011).cos()]
        };
        let mut s = StreamingQr::new(4);
        for i in 0..n {
            s.push(&row(i));
        }
        let r = s.finish();
        let a = DMatrix::from_fn(n, 4, |i, j| row(i)[j]);
        let g = a.transpose() * &a;
        let h = r.transpose() * &r;
        for i in 0..4 {
            for j in 0..4 {
                let scale = (g[(i, i)] * g[(j, j)]).sqrt();
                assert!((g[(i, j)] - h[(i, j)]).abs() <= 1e-13 * scale, "{i},{j}");
            }
        }
    }
}
