//! One multiply–add, fused where the build's CPU has the instruction.
//!
//! A law evaluation waits on its chain of dependent operations, not on its operation
//! count (benches/README.md, "The evaluation's critical path"), and a fused multiply–add
//! finishes in about the time of the multiply alone. Rust never fuses `a * b + c` on its
//! own, so the hot chains ask for it here. Without hardware FMA (a build for the generic
//! x86-64 baseline) `f64::mul_add` would be a slow library call, so such a build keeps
//! the separate multiply and add; the two builds then differ in the last bits.

/// a·b + c [units of c], rounded once where the CPU fuses it.
#[inline(always)]
pub fn fmadd(a: f64, b: f64, c: f64) -> f64 {
    if cfg!(target_feature = "fma") { a.mul_add(b, c) } else { a * b + c }
}

#[cfg(test)]
mod tests {
    use super::fmadd;

    /// (1 + 2⁻³⁰)·(1 − 2⁻³⁰) − 1 = −2⁻⁶⁰ exactly; the product alone rounds to 1, so only a
    /// fused evaluation sees the −2⁻⁶⁰. The build decides which one it must be.
    #[test]
    fn fused_exactly_where_the_build_has_fma() {
        let e = 2f64.powi(-30);
        let r = fmadd(1.0 + e, 1.0 - e, -1.0);
        if cfg!(target_feature = "fma") {
            assert_eq!(r, -(2f64.powi(-60)));
        } else {
            assert_eq!(r, 0.0);
        }
        // Ordinary operands agree with the unfused form to rounding.
        let (a, b, c) = (0.1, 3.7, -0.25);
        assert!((fmadd(a, b, c) - (a * b + c)).abs() <= 2.0 * f64::EPSILON);
    }
}
