//! A secant estimate of the residual curvature for Levenberg–Marquardt on large-residual
//! problems (Dennis, Gay & Welsch, the NL2SOL idea).
//!
//! For f = ½‖r‖² with r = data − model and J = ∂model/∂x, the Hessian is `JᵀJ + S` with
//! `S = −Σ rᵢ·∇²modelᵢ`. Gauss–Newton drops S; where the residuals stay large at the
//! optimum (a real record that the law fits only to within its noise and misfit), it then
//! converges only linearly. S is estimated from the steps taken: after a step s, with
//! g = Jᵀr (so ∇f = −g) at both ends, the secant condition is `S₊·s = y♯`,
//! `y♯ = (g − g₊) − J₊ᵀJ₊·s`, met by the symmetric rank-two update of Dennis, Gay and
//! Welsch (with their sizing of the old S). Each accepted step also says which quadratic
//! model, Gauss–Newton's or the augmented one, predicted its actual reduction better; the
//! next step uses that one. The iteration's stopping rules do not change, so the optimum
//! is the same; only the path to it is shorter.

use nalgebra::{DMatrix, DVector};

/// The estimate and which model to use next.
pub(crate) struct Secant {
    /// S, the curvature the Gauss–Newton model leaves out (p × p).
    s: DMatrix<f64>,
    /// The last accepted step and g = Jᵀr where it started.
    last: Option<(DVector<f64>, DVector<f64>)>,
    /// Whether the next step uses JᵀJ + S (true) or JᵀJ.
    augmented: bool,
}

impl Secant {
    /// No curvature known yet (the first steps are Gauss–Newton's).
    pub(crate) fn new(p: usize) -> Self {
        Self { s: DMatrix::zeros(p, p), last: None, augmented: false }
    }

    /// The model Hessian for the next step, from the Gauss–Newton part `a` = JᵀJ.
    pub(crate) fn hessian(&self, a: &DMatrix<f64>) -> Option<DMatrix<f64>> {
        self.augmented.then(|| a + &self.s)
    }

    /// Update S at a new point with JᵀJ `a` and Jᵀr `g`, after the step recorded by
    /// [`Secant::accepted`].
    pub(crate) fn update(&mut self, a: &DMatrix<f64>, g: &DVector<f64>) {
        let Some((step, g_old)) = self.last.take() else { return };
        let y = &g_old - g; // ∇f₊ − ∇f
        let y_sharp = &y - a * &step;
        let rho = y.dot(&step);
        if !(rho > 0.0 && rho.is_finite()) {
            return; // no positive curvature along the step: keep S as it is
        }
        let ss = step.dot(&(&self.s * &step));
        let tau = if ss.abs() > 0.0 { (step.dot(&y_sharp).abs() / ss.abs()).min(1.0) } else { 1.0 };
        let sized = &self.s * tau;
        let z = &y_sharp - &sized * &step;
        let zs = z.dot(&step);
        let update = (&z * y.transpose() + &y * z.transpose()) / rho
            - (&y * y.transpose()) * (zs / (rho * rho));
        let next = sized + update;
        if next.iter().all(|v| v.is_finite()) {
            self.s = next;
        }
    }

    /// Record an accepted step `step` from a point with JᵀJ `a` and Jᵀr `g`, whose
    /// actual reduction of ½‖r‖² was `actual`, and choose the next model.
    pub(crate) fn accepted(
        &mut self,
        step: &DVector<f64>,
        a: &DMatrix<f64>,
        g: &DVector<f64>,
        actual: f64,
    ) {
        let linear = g.dot(step);
        let gn = linear - 0.5 * step.dot(&(a * step));
        let aug = gn - 0.5 * step.dot(&(&self.s * step));
        self.augmented = (actual - aug).abs() < (actual - gn).abs();
        self.last = Some((step.clone(), g.clone()));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a quadratic f whose Hessian is JᵀJ + S₀ with constant J, each update meets the
    /// secant condition exactly.
    #[test]
    fn meets_the_secant_condition() {
        let a = DMatrix::from_row_slice(2, 2, &[2.0, 0.3, 0.3, 1.0]);
        let s0 = DMatrix::from_row_slice(2, 2, &[0.5, -0.2, -0.2, 0.8]);
        let h = &a + &s0;
        let grad = |x: &DVector<f64>| -(&h * x); // g = −∇f for f = ½xᵀHx
        let mut sec = Secant::new(2);
        let mut x = DVector::from_vec(vec![1.0, -2.0]);
        for step in [[0.3, 0.1], [-0.2, 0.4], [0.05, -0.3]] {
            let s = DVector::from_vec(step.to_vec());
            sec.accepted(&s, &a, &grad(&x), 0.0);
            x += &s;
            sec.update(&a, &grad(&x));
            let secant = &sec.s * &s;
            let want = (&h - &a) * &s;
            assert!((secant - want).amax() < 1e-12, "{}", sec.s);
        }
    }
}
