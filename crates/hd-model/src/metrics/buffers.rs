//! A per-thread pool of sample buffers, so that the runs of a sweep reuse the metric
//! collectors' buffers (20 000 samples each for a non-periodic run, cycles × samples per
//! cycle for a periodic window) instead of allocating, growing and freeing them, and
//! touching fresh pages, for every run.

use std::cell::RefCell;

/// Buffers kept per thread at most [–] (a collector holds five: three for a run's
/// uniform samples, two for a periodic window).
const KEEP: usize = 8;

thread_local! {
    static POOL: RefCell<Vec<Vec<f64>>> = const { RefCell::new(Vec::new()) };
}

/// An empty buffer with room for at least `capacity` values, reused when one is free.
pub fn take(capacity: usize) -> Vec<f64> {
    if capacity == 0 {
        return Vec::new();
    }
    let mut v = POOL.with(|p| p.borrow_mut().pop()).unwrap_or_default();
    v.clear();
    v.reserve(capacity);
    v
}

/// Return a buffer to this thread's pool.
pub fn give(v: Vec<f64>) {
    if v.capacity() == 0 {
        return;
    }
    POOL.with(|p| {
        let mut p = p.borrow_mut();
        if p.len() < KEEP {
            p.push(v);
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_returned_buffer_is_reused_empty_and_large_enough() {
        let mut a = take(1000);
        a.extend([1.0, 2.0]);
        let ptr = a.as_ptr();
        give(a);
        let b = take(500);
        assert!(b.is_empty());
        assert!(b.capacity() >= 1000);
        assert_eq!(b.as_ptr(), ptr);
        assert!(take(0).capacity() == 0);
    }
}
