//! The residuals' exact Jacobian for the compliant fit: the free parameters' columns carried
//! as dual numbers through the fit's simulation, in blocks that keep both cores busy.

use super::fit::{CompliantSpec, residuals_of};
use super::model::P;
use super::record::VoltageRecord;
use crate::drive::dual::{Dual, Scalar};
use nalgebra::DMatrix;
use rayon::prelude::*;

/// Residuals and their exact Jacobian with respect to the free parameters `free_idx`.
fn jacobian<const N: usize>(
    spec: &CompliantSpec,
    p: &[f64; P],
    free_idx: &[usize],
    records: &[VoltageRecord],
) -> (Vec<f64>, DMatrix<f64>) {
    let mut pd: [Dual<N>; P] = p.map(Dual::cst);
    for (slot, &k) in free_idx.iter().enumerate() {
        pd[k] = Dual::var(p[k], slot);
    }
    let pd = spec.tied(pd);
    let rd = residuals_of(spec, pd, records);
    let r: Vec<f64> = rd.iter().map(|d| d.v).collect();
    let j = DMatrix::from_fn(r.len(), free_idx.len(), |i, c| rd[i].d[c]);
    (r, j)
}

/// Widest dual number a block of Jacobian columns is computed with.
const WIDEST_DUAL: usize = 16;

/// Residuals and Jacobian at `p`. The free columns are split into blocks, each run on the
/// smallest dual size that holds it: at most [`WIDEST_DUAL`] columns a block, and, where the
/// records are fewer than the threads, as many blocks as keep every thread busy (each block
/// re-runs the values, and the blocks run in parallel). Every column is computed by the
/// same operations whatever its block, so the split never changes a value.
pub fn residuals_and_jacobian(
    spec: &CompliantSpec,
    p: &[f64; P],
    free_idx: &[usize],
    records: &[VoltageRecord],
) -> (Vec<f64>, DMatrix<f64>) {
    let k = free_idx.len();
    let threads = rayon::current_num_threads();
    let per_record = threads.div_ceil(records.len().max(1));
    // Blocks narrower than four columns would spend more on values than on derivatives
    // (measured: a motor pass's four columns as two blocks of two on two threads took as
    // long as one block of four on one, 0.18-0.20 s against 0.17 s; its time is the
    // values' chain of operations, which every block repeats).
    let blocks = k.div_ceil(WIDEST_DUAL).max(per_record.min(k.div_ceil(4))).max(1);
    let width = k.div_ceil(blocks).max(1);
    if width >= k {
        return jacobian_block(spec, p, free_idx, records);
    }
    let parts: Vec<(Vec<f64>, DMatrix<f64>)> =
        free_idx.par_chunks(width).map(|cols| jacobian_block(spec, p, cols, records)).collect();
    let r = parts[0].0.clone();
    let mut j = DMatrix::zeros(r.len(), k);
    for (b, (_, part)) in parts.iter().enumerate() {
        j.columns_mut(b * width, part.ncols()).copy_from(part);
    }
    (r, j)
}

/// One block of columns on the smallest dual size that holds it. Six is among the sizes:
/// eleven or twelve free parameters split over two threads make blocks of six, which an
/// eight-wide dual would carry with a quarter of its work wasted.
fn jacobian_block(
    spec: &CompliantSpec,
    p: &[f64; P],
    free_idx: &[usize],
    records: &[VoltageRecord],
) -> (Vec<f64>, DMatrix<f64>) {
    match free_idx.len() {
        k if k <= 4 => jacobian::<4>(spec, p, free_idx, records),
        k if k <= 6 => jacobian::<6>(spec, p, free_idx, records),
        k if k <= 8 => jacobian::<8>(spec, p, free_idx, records),
        k if k <= 12 => jacobian::<12>(spec, p, free_idx, records),
        _ => jacobian::<WIDEST_DUAL>(spec, p, free_idx, records),
    }
}
