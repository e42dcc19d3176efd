//! Forward-mode derivatives of the drive's discrete-time recursion: a number that carries its
//! value and its partial derivatives with respect to `N` parameters (`N` is a compile-time
//! size: the fit picks the smallest of [`SIZES`] that holds its free parameters, so a
//! four-parameter law does not carry twelve derivatives through every operation).
//!
//! Running the closed-loop simulation with [`Dual`] instead of `f64` propagates the forward
//! sensitivities ∂state/∂parameter through every operation of the same code — the exact
//! within-sample solution, the stop time of a sliding phase, the controller, the saturation —
//! so the Jacobian is the derivative of the recursion itself, not a difference quotient.
//! [`Scalar`] is the arithmetic the simulation needs, implemented by `f64` and [`Dual`].

use std::ops::{Add, Div, Mul, Neg, Sub};

/// Largest number of parameters differentiated at once.
pub const NP: usize = 12;

/// The derivative counts the fit is compiled for (the smallest that holds the free
/// parameters is used).
pub const SIZES: [usize; 3] = [4, 8, NP];

/// A value with its partial derivatives ∂value/∂pₖ, k < N.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual<const N: usize> {
    /// The value.
    pub v: f64,
    /// Its partial derivatives.
    pub d: [f64; N],
}

/// The arithmetic of the simulation: `f64` for plain runs, [`Dual`] for sensitivities.
pub trait Scalar:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
{
    /// A constant (no derivative).
    fn cst(v: f64) -> Self;
    /// The value.
    fn re(self) -> f64;
    /// e^x.
    fn exp(self) -> Self;
    /// ln(1 + x).
    fn ln_1p(self) -> Self;
    /// e^x − 1.
    fn exp_m1(self) -> Self;
    /// A value computed outside the generic code (by an `f64` law) with its partial
    /// derivatives with respect to inputs of this type: `parts` holds (∂value/∂input,
    /// input) pairs. For `f64`, the value itself; for [`Dual`], the chain rule.
    fn lift(value: f64, parts: &[(f64, Self)]) -> Self;
    /// |x| (derivative −1 or +1; +1 at 0).
    fn abs(self) -> Self {
        if self.re() < 0.0 { -self } else { self }
    }
    /// self·a + b; for `f64` rounded once where the CPU fuses it ([`crate::fma::fmadd`]).
    #[inline(always)]
    fn fmadd(self, a: Self, b: Self) -> Self {
        self * a + b
    }
    /// self·a + b with a plain factor `a`; for `f64` as [`Scalar::fmadd`].
    #[inline(always)]
    fn fmadd_f(self, a: f64, b: Self) -> Self {
        self * a + b
    }
}

impl Scalar for f64 {
    fn cst(v: f64) -> Self {
        v
    }
    fn re(self) -> f64 {
        self
    }
    fn exp(self) -> Self {
        f64::exp(self)
    }
    fn ln_1p(self) -> Self {
        f64::ln_1p(self)
    }
    fn exp_m1(self) -> Self {
        f64::exp_m1(self)
    }
    fn lift(value: f64, _parts: &[(f64, Self)]) -> Self {
        value
    }
    #[inline(always)]
    fn fmadd(self, a: f64, b: f64) -> f64 {
        crate::fma::fmadd(self, a, b)
    }
    #[inline(always)]
    fn fmadd_f(self, a: f64, b: f64) -> f64 {
        crate::fma::fmadd(self, a, b)
    }
}

impl<const N: usize> Dual<N> {
    /// Parameter `k` at value `v` (∂/∂pₖ = 1).
    pub fn var(v: f64, k: usize) -> Self {
        let mut d = [0.0; N];
        d[k] = 1.0;
        Dual { v, d }
    }

    /// The value with derivatives scaled by `f'(v)` = `slope`: the chain rule for a function
    /// of one argument.
    fn chain(self, value: f64, slope: f64) -> Self {
        let mut d = self.d;
        for x in &mut d {
            *x *= slope;
        }
        Dual { v: value, d }
    }
}

impl<const N: usize> Scalar for Dual<N> {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        Dual { v, d: [0.0; N] }
    }
    #[inline(always)]
    fn re(self) -> f64 {
        self.v
    }
    fn exp(self) -> Self {
        let e = self.v.exp();
        self.chain(e, e)
    }
    fn ln_1p(self) -> Self {
        self.chain(self.v.ln_1p(), 1.0 / (1.0 + self.v))
    }
    fn exp_m1(self) -> Self {
        self.chain(self.v.exp_m1(), self.v.exp())
    }
    fn lift(value: f64, parts: &[(f64, Self)]) -> Self {
        let mut d = [0.0; N];
        for (slope, x) in parts {
            if *slope != 0.0 {
                for (a, b) in d.iter_mut().zip(x.d) {
                    *a += slope * b;
                }
            }
        }
        Dual { v: value, d }
    }
}

impl<const N: usize> Add for Dual<N> {
    type Output = Dual<N>;
    #[inline(always)]
    fn add(mut self, o: Dual<N>) -> Dual<N> {
        self.v += o.v;
        for (a, b) in self.d.iter_mut().zip(o.d) {
            *a += b;
        }
        self
    }
}

impl<const N: usize> Sub for Dual<N> {
    type Output = Dual<N>;
    #[inline(always)]
    fn sub(mut self, o: Dual<N>) -> Dual<N> {
        self.v -= o.v;
        for (a, b) in self.d.iter_mut().zip(o.d) {
            *a -= b;
        }
        self
    }
}

impl<const N: usize> Mul for Dual<N> {
    type Output = Dual<N>;
    #[inline(always)]
    fn mul(self, o: Dual<N>) -> Dual<N> {
        let mut d = [0.0; N];
        for (k, x) in d.iter_mut().enumerate() {
            *x = self.d[k] * o.v + self.v * o.d[k];
        }
        Dual { v: self.v * o.v, d }
    }
}

impl<const N: usize> Div for Dual<N> {
    type Output = Dual<N>;
    #[inline(always)]
    fn div(self, o: Dual<N>) -> Dual<N> {
        // The derivatives are scaled by the reciprocal (one division, not N).
        let inv = 1.0 / o.v;
        let q = self.v / o.v;
        let mut d = [0.0; N];
        for (k, x) in d.iter_mut().enumerate() {
            *x = (self.d[k] - q * o.d[k]) * inv;
        }
        Dual { v: q, d }
    }
}

impl<const N: usize> Neg for Dual<N> {
    type Output = Dual<N>;
    #[inline(always)]
    fn neg(self) -> Dual<N> {
        self.chain(-self.v, -1.0)
    }
}

impl<const N: usize> Add<f64> for Dual<N> {
    type Output = Dual<N>;
    #[inline(always)]
    fn add(mut self, o: f64) -> Dual<N> {
        self.v += o;
        self
    }
}

impl<const N: usize> Sub<f64> for Dual<N> {
    type Output = Dual<N>;
    #[inline(always)]
    fn sub(mut self, o: f64) -> Dual<N> {
        self.v -= o;
        self
    }
}

impl<const N: usize> Mul<f64> for Dual<N> {
    type Output = Dual<N>;
    #[inline(always)]
    fn mul(self, o: f64) -> Dual<N> {
        self.chain(self.v * o, o)
    }
}

impl<const N: usize> Div<f64> for Dual<N> {
    type Output = Dual<N>;
    #[inline(always)]
    fn div(self, o: f64) -> Dual<N> {
        self.chain(self.v / o, 1.0 / o)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f(x, y) = exp(x·y)/(1 + y) − ln(1 + x) + expm1(y) − x, against its hand derivatives.
    #[test]
    fn derivatives_match_the_hand_derived_ones() {
        let (x, y) = (0.3, -0.45);
        let f =
            |x: Dual<3>, y: Dual<3>| (x * y).exp() / (y + 1.0) - x.ln_1p() + y.exp_m1() - x * 2.0;
        let r = f(Dual::var(x, 0), Dual::var(y, 1));
        let e = (x * y).exp();
        let fx = y * e / (1.0 + y) - 1.0 / (1.0 + x) - 2.0;
        let fy = x * e / (1.0 + y) - e / ((1.0 + y) * (1.0 + y)) + y.exp();
        assert!((r.v - (e / (1.0 + y) - x.ln_1p() + y.exp_m1() - 2.0 * x)).abs() < 1e-15);
        assert!((r.d[0] - fx).abs() < 1e-14 && (r.d[1] - fy).abs() < 1e-14, "{r:?}");
        assert!(r.d[2..].iter().all(|&d| d == 0.0));
    }
}
