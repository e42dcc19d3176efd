//! From a catalogue to model parameters: the seed law's spring f(θ) = a·θ³ + b·θ² + c·θ
//! that best matches the manufacturer's three-segment curve over the rated range, with the
//! error of that match, and the loop widths of the catalogue law.

use crate::linear::least_squares;
use hd_model::laws::catalogue::{CatalogueCurve, CatalogueLaw, loop_width};
use hd_model::laws::stiffness::{CubicSpring, ElasticCurve};
use serde::Serialize;

/// Points over the rated range at which the spring is matched.
pub const MATCH_POINTS: usize = 2001;

/// The best cubic spring over |θ| ≤ the rated deflection, and how far it is off.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SpringMatch {
    /// Cubic coefficient a [N·m/rad³].
    pub a: f64,
    /// Quadratic coefficient b [N·m/rad²] (0 for a symmetric curve, to rounding).
    pub b: f64,
    /// Linear coefficient c [N·m/rad].
    pub c: f64,
    /// Deflection at the rated torque on the catalogue curve [rad].
    pub rated_deflection: f64,
    /// RMS torque error over the uniformly sampled rated range [N·m].
    pub rms_error: f64,
    /// Largest torque error there [N·m].
    pub max_error: f64,
}

impl SpringMatch {
    /// The matched spring.
    pub fn spring(&self) -> CubicSpring {
        CubicSpring { a: self.a, b: self.b, c: self.c }
    }
}

/// Least-squares cubic spring through the catalogue curve at [`MATCH_POINTS`] deflections
/// evenly spread over ±(deflection at `rated` torque [N·m]).
pub fn match_spring(curve: &CatalogueCurve, rated: f64) -> SpringMatch {
    let th_r = curve.deflection_at(rated);
    let th: Vec<f64> = (0..MATCH_POINTS)
        .map(|k| th_r * (2.0 * k as f64 / (MATCH_POINTS - 1) as f64 - 1.0))
        .collect();
    let y: Vec<f64> = th.iter().map(|&x| curve.spring_torque(x)).collect();
    let cols: Vec<Vec<f64>> =
        (1..=3).rev().map(|p| th.iter().map(|t| t.powi(p)).collect()).collect();
    let refs: Vec<&[f64]> = cols.iter().map(Vec::as_slice).collect();
    let beta = least_squares(&refs, &y);
    let spring = CubicSpring { a: beta[0], b: beta[1], c: beta[2] };
    let err: Vec<f64> = th.iter().zip(&y).map(|(&x, &t)| spring.torque(x) - t).collect();
    SpringMatch {
        a: beta[0],
        b: beta[1],
        c: beta[2],
        rated_deflection: th_r,
        rms_error: (err.iter().map(|e| e * e).sum::<f64>() / err.len() as f64).sqrt(),
        max_error: err.iter().fold(0.0, |m, e| m.max(e.abs())),
    }
}

/// Lost motion of the law as catalogues measure it [rad]: the loop width at zero torque
/// between ±4 % of the rated torque `rated` [N·m].
pub fn lost_motion(law: &CatalogueLaw, rated: f64) -> f64 {
    loop_width(law, law.spring.curve.deflection_at(0.04 * rated))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_linear_catalogue_gives_a_linear_spring() {
        // K1 = K2 = K3: the curve is a straight line and the cubic matches it exactly.
        let curve = CatalogueCurve::new(1e5, 1e5, 1e5, 10.0, 50.0).unwrap();
        let m = match_spring(&curve, 80.0);
        assert!((m.c / 1e5 - 1.0).abs() < 1e-9 && m.rms_error < 1e-9, "{m:?}");
        // The curve stiffens: a > 0, c below K2.
        let m =
            match_spring(&CatalogueCurve::new(6.7e4, 1.1e5, 1.2e5, 29.0, 108.0).unwrap(), 108.0);
        assert!(m.a > 0.0 && m.c < 1.1e5 && m.b.abs() < 1e-6 * m.c, "{m:?}");
    }
}
