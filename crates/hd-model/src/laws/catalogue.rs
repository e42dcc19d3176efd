//! The manufacturer's stiffness curve (docs/model.md §2.13): three spring rates K1 up to
//! the torque T1, K2 up to T2 and K3 beyond, the same in both directions, with each
//! corner rounded so that the slope is continuous; optionally a hysteresis loss, realised
//! by Maxwell-slip elements sized to give the catalogue's loop width at zero torque.
//!
//! Corners: over a band of width `2h` centred on a corner deflection θⱼ the slope ramps
//! linearly from the rate below to the rate above. The band's torque increment equals the
//! sharp curve's, so outside the bands the rounded curve *is* the three-segment curve.

use super::maxwell_slip::{MaxwellSlip, SlipElement};
use super::slip_set::SlipSet;
use super::stiffness::ElasticCurve;
use serde::{Deserialize, Serialize};

/// Share of the shorter segment (in deflection) over which each corner is rounded.
pub const DEFAULT_SMOOTHING: f64 = 0.1;

/// Slip elements used to realise a hysteresis loss.
pub const LOSS_ELEMENTS: usize = 4;

/// The three-segment catalogue curve, symmetric in θ, with rounded corners.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CatalogueCurve {
    /// Spring rate up to T1 [N·m/rad].
    pub k1: f64,
    /// Spring rate from T1 to T2 [N·m/rad].
    pub k2: f64,
    /// Spring rate beyond T2 [N·m/rad].
    pub k3: f64,
    /// First corner torque [N·m].
    pub t1: f64,
    /// Second corner torque [N·m].
    pub t2: f64,
    /// Width of each rounded corner as a share of the shorter segment [–], in [0, 1).
    pub smoothing: f64,
}

impl CatalogueCurve {
    /// A curve with the default corner rounding, checked: every rate > 0 and
    /// 0 < T1 < T2, all finite. The error names the field and what was expected.
    pub fn new(k1: f64, k2: f64, k3: f64, t1: f64, t2: f64) -> Result<Self, String> {
        for (name, v) in [("K1", k1), ("K2", k2), ("K3", k3), ("T1", t1), ("T2", t2)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{name} = {v}: expected a finite value > 0"));
            }
        }
        if t2 <= t1 {
            return Err(format!("T2 = {t2}: expected a torque above T1 = {t1} [N·m]"));
        }
        Ok(Self { k1, k2, k3, t1, t2, smoothing: DEFAULT_SMOOTHING })
    }

    /// Corner deflections θ1 = T1/K1 and θ2 = θ1 + (T2 − T1)/K2 [rad].
    pub fn corners(&self) -> [f64; 2] {
        let th1 = self.t1 / self.k1;
        [th1, th1 + (self.t2 - self.t1) / self.k2]
    }

    /// Half-width h of each rounded band [rad].
    fn half_band(&self) -> f64 {
        let [a, b] = self.corners();
        0.5 * self.smoothing.clamp(0.0, 0.999) * a.min(b - a)
    }

    /// The sharp three-segment curve at θ ≥ 0 [N·m].
    pub fn sharp_torque(&self, x: f64) -> f64 {
        let [a, b] = self.corners();
        if x <= a {
            self.k1 * x
        } else if x <= b {
            self.t1 + self.k2 * (x - a)
        } else {
            self.t2 + self.k3 * (x - b)
        }
    }

    /// Torque and slope at θ ≥ 0.
    fn positive(&self, x: f64) -> (f64, f64) {
        let h = self.half_band();
        let [a, b] = self.corners();
        for (c, lo, hi) in [(a, self.k1, self.k2), (b, self.k2, self.k3)] {
            if h > 0.0 && (x - c).abs() < h {
                let u = x - (c - h);
                let t = self.sharp_torque(c - h) + lo * u + (hi - lo) * u * u / (4.0 * h);
                return (t, lo + (hi - lo) * u / (2.0 * h));
            }
        }
        let slope = if x <= a {
            self.k1
        } else if x <= b {
            self.k2
        } else {
            self.k3
        };
        (self.sharp_torque(x), slope)
    }

    /// Torque [N·m], slope [N·m/rad] and the torque's derivatives with respect to
    /// (K1, K2, K3, T1, T2) at deflection θ [rad] (odd in θ), the corners' rounding held at
    /// its share: the curve of [`ElasticCurve::spring_torque`], differentiated piece by
    /// piece (the corners and the bands' half-width move with the parameters).
    pub fn torque_grad(&self, theta: f64) -> (f64, f64, [f64; 5]) {
        let (x, sign) = (theta.abs(), if theta < 0.0 { -1.0 } else { 1.0 });
        let (k1, k2, k3, t1, t2) = (self.k1, self.k2, self.k3, self.t1, self.t2);
        let [a, b] = self.corners();
        // ∂a, ∂b and ∂h over (K1, K2, K3, T1, T2).
        let da = [-t1 / (k1 * k1), 0.0, 0.0, 1.0 / k1, 0.0];
        let db_own = [0.0, -(t2 - t1) / (k2 * k2), 0.0, -1.0 / k2, 1.0 / k2];
        let db: [f64; 5] = std::array::from_fn(|j| da[j] + db_own[j]);
        let share = 0.5 * self.smoothing.clamp(0.0, 0.999);
        let h = self.half_band();
        let dh: [f64; 5] =
            std::array::from_fn(|j| share * if a <= b - a { da[j] } else { db_own[j] });
        let unit = |j: usize| std::array::from_fn::<f64, 5, _>(|i| if i == j { 1.0 } else { 0.0 });
        let (t, slope, g): (f64, f64, [f64; 5]) = if h > 0.0 && (x - a).abs() < h {
            // K1·x + (K2 − K1)·q²/(4h), q = x − a + h.
            let q = x - a + h;
            let dk = k2 - k1;
            let g = std::array::from_fn(|j| {
                let d_dk = [-1.0, 1.0, 0.0, 0.0, 0.0][j];
                let own = if j == 0 { x } else { 0.0 };
                own + d_dk * q * q / (4.0 * h)
                    + dk * (2.0 * q * (dh[j] - da[j]) / (4.0 * h) - q * q * dh[j] / (4.0 * h * h))
            });
            (k1 * x + dk * q * q / (4.0 * h), k1 + dk * q / (2.0 * h), g)
        } else if h > 0.0 && (x - b).abs() < h {
            // T1 + K2·(x − a) + (K3 − K2)·r²/(4h), r = x − b + h.
            let r = x - b + h;
            let dk = k3 - k2;
            let base = unit(3);
            let g = std::array::from_fn(|j| {
                let d_dk = [0.0, -1.0, 1.0, 0.0, 0.0][j];
                let own = if j == 1 { x - a } else { 0.0 };
                base[j] + own - k2 * da[j]
                    + d_dk * r * r / (4.0 * h)
                    + dk * (2.0 * r * (dh[j] - db[j]) / (4.0 * h) - r * r * dh[j] / (4.0 * h * h))
            });
            (t1 + k2 * (x - a) + dk * r * r / (4.0 * h), k2 + dk * r / (2.0 * h), g)
        } else if x <= a {
            (k1 * x, k1, std::array::from_fn(|j| if j == 0 { x } else { 0.0 }))
        } else if x <= b {
            let g =
                std::array::from_fn(|j| unit(3)[j] + if j == 1 { x - a } else { 0.0 } - k2 * da[j]);
            (t1 + k2 * (x - a), k2, g)
        } else {
            let g =
                std::array::from_fn(|j| unit(4)[j] + if j == 2 { x - b } else { 0.0 } - k3 * db[j]);
            (t2 + k3 * (x - b), k3, g)
        };
        (sign * t, slope, g.map(|d| sign * d))
    }

    /// Deflection at which the (rounded) curve carries `torque` [rad], odd in the torque.
    pub fn deflection_at(&self, torque: f64) -> f64 {
        let target = torque.abs();
        let (mut lo, mut hi) = (0.0, 2.0 * target / self.k1.min(self.k2).min(self.k3));
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if self.positive(mid).0 < target {
                lo = mid
            } else {
                hi = mid
            }
            if hi - lo <= f64::EPSILON * hi {
                break;
            }
        }
        torque.signum() * 0.5 * (lo + hi)
    }
}

impl ElasticCurve for CatalogueCurve {
    fn spring_torque(&self, theta: f64) -> f64 {
        theta.signum() * self.positive(theta.abs()).0
    }
    fn spring_slope(&self, theta: f64) -> f64 {
        self.positive(theta.abs()).1
    }
    fn spring_energy(&self, theta: f64) -> f64 {
        // The torque is piecewise quadratic between the band edges: Simpson's rule is exact.
        let x = theta.abs();
        let h = self.half_band();
        let [a, b] = self.corners();
        let mut knots = vec![0.0];
        knots.extend([a - h, a + h, b - h, b + h].into_iter().filter(|&k| k > 0.0 && k < x));
        knots.push(x);
        knots
            .windows(2)
            .map(|w| {
                let m = 0.5 * (w[0] + w[1]);
                let f = |v: f64| self.positive(v).0;
                (w[1] - w[0]) / 6.0 * (f(w[0]) + 4.0 * f(m) + f(w[1]))
            })
            .sum()
    }
}

/// The catalogue curve less the first-loading torque of the slip elements, so that the
/// complete law (this plus the elements) loads along the catalogue curve from rest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CatalogueSpring {
    /// The catalogue curve.
    pub curve: CatalogueCurve,
    /// The slip elements whose first-loading torque is taken off.
    pub virgin: SlipSet,
}

impl ElasticCurve for CatalogueSpring {
    fn spring_torque(&self, theta: f64) -> f64 {
        self.curve.spring_torque(theta)
            - self.virgin.as_slice().iter().map(|e| e.virgin_torque(theta)).sum::<f64>()
    }
    fn spring_slope(&self, theta: f64) -> f64 {
        let yielded = |e: &&SlipElement| theta.abs() < e.yield_deflection();
        self.curve.spring_slope(theta)
            - self.virgin.as_slice().iter().filter(yielded).map(|e| e.k).sum::<f64>()
    }
    fn spring_energy(&self, theta: f64) -> f64 {
        self.curve.spring_energy(theta)
            - self.virgin.as_slice().iter().map(|e| e.virgin_work(theta)).sum::<f64>()
    }
}

/// The catalogue law: the curve, with the hysteresis loss's slip elements when a loss is
/// given (without, the element list is empty and the law is the curve alone).
pub type CatalogueLaw = MaxwellSlip<CatalogueSpring>;

/// The catalogue law without hysteresis.
pub fn without_loss(curve: CatalogueCurve) -> CatalogueLaw {
    MaxwellSlip {
        spring: CatalogueSpring { curve, virgin: SlipSet::default() },
        elements: Vec::new(),
    }
}

/// Width at zero torque [rad] of the loop the law traces between ±`theta_max` [rad],
/// from rest: rise to +θmax, fall to −θmax (downward zero crossing), rise to +θmax
/// (upward zero crossing).
pub fn loop_width(law: &CatalogueLaw, theta_max: f64) -> f64 {
    let steps = 4000;
    let path = (0..=steps)
        .map(|k| theta_max * k as f64 / steps as f64)
        .chain((1..=2 * steps).map(|k| theta_max * (1.0 - k as f64 / steps as f64)))
        .chain((1..=2 * steps).map(|k| theta_max * (-1.0 + k as f64 / steps as f64)));
    let th: Vec<f64> = path.collect();
    let tb = law.torque_along(&th);
    let crossing = |range: std::ops::Range<usize>| {
        range.into_iter().find_map(|i| {
            let (a, b) = (tb[i], tb[i + 1]);
            (a.signum() != b.signum()).then(|| th[i] + (th[i + 1] - th[i]) * a / (a - b))
        })
    };
    let down = crossing(steps..3 * steps).unwrap_or(f64::NAN);
    let up = crossing(3 * steps..5 * steps).unwrap_or(f64::NAN);
    down - up
}

/// The catalogue law with a hysteresis loss `loss` [rad] (the loop width at zero torque
/// after loading to ±`rated` [N·m]): [`LOSS_ELEMENTS`] slip elements of equal slip torque
/// whose yield deflections are spread evenly up to half the rated deflection, their total
/// slip torque found by bisection. The elements' stiffness is taken off the curve's, so a
/// first loading still follows the catalogue; that caps the loss (the unloading slope
/// must stay positive), and a larger request is an error saying the largest possible.
pub fn with_loss(curve: CatalogueCurve, loss: f64, rated: f64) -> Result<CatalogueLaw, String> {
    if !(loss.is_finite() && loss >= 0.0) {
        return Err(format!("hysteresis loss {loss} rad: expected a finite value >= 0"));
    }
    if !(rated.is_finite() && rated > 0.0) {
        return Err(format!("rated torque {rated}: expected a finite value > 0 [N·m]"));
    }
    if loss == 0.0 {
        return Ok(without_loss(curve));
    }
    let theta_r = curve.deflection_at(rated);
    let m = LOSS_ELEMENTS as f64;
    let harmonic: f64 = (1..=LOSS_ELEMENTS).map(|i| 1.0 / i as f64).sum();
    let k_min = curve.k1.min(curve.k2).min(curve.k3);
    let build = |f_total: f64| {
        let elements: Vec<SlipElement> = (1..=LOSS_ELEMENTS)
            .map(|i| {
                let delta = i as f64 / m * theta_r / 2.0;
                SlipElement { k: f_total / m / delta, f: f_total / m }
            })
            .collect();
        // LOSS_ELEMENTS (4) non-negative elements always fit a set.
        let virgin = SlipSet::new(&elements).unwrap_or_default();
        MaxwellSlip { spring: CatalogueSpring { curve, virgin }, elements }
    };
    let f_max = 0.9 * k_min * theta_r / (2.0 * harmonic);
    let widest = loop_width(&build(f_max), theta_r);
    if widest.is_nan() || widest < loss {
        return Err(format!(
            "hysteresis loss {loss:.4e} rad: expected at most {widest:.4e} rad for these spring rates at the rated torque {rated} N·m (more would need a negative unloading slope)"
        ));
    }
    let (mut lo, mut hi) = (0.0, f_max);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if loop_width(&build(mid), theta_r) < loss { lo = mid } else { hi = mid }
    }
    Ok(build(0.5 * (lo + hi)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn issue_curve() -> CatalogueCurve {
        CatalogueCurve::new(6.7e4, 1.1e5, 1.2e5, 29.0, 108.0).unwrap()
    }

    #[test]
    fn reproduces_the_catalogue_deflection() {
        let c = issue_curve();
        // Closed form of the three segments at 60 N·m: 29/K1 + (60 − 29)/K2.
        let exact = 29.0 / 6.7e4 + 31.0 / 1.1e5;
        let got = c.deflection_at(60.0);
        println!("deflection at 60 N·m: {got:e} rad (closed form {exact:e})");
        assert!((got / exact - 1.0).abs() < 1e-13, "{got} vs {exact}");
        // The issue quotes 7.146e-4 rad (7.14654e-4 cut to four digits).
        assert!((got - 7.146e-4).abs() < 1e-7);
        assert_eq!(c.deflection_at(-60.0), -got);
        // Beyond T2 and on the first segment, too.
        let beyond = 29.0 / 6.7e4 + 79.0 / 1.1e5 + 42.0 / 1.2e5;
        assert!((c.deflection_at(150.0) / beyond - 1.0).abs() < 1e-13);
        assert!((c.deflection_at(10.0) / (10.0 / 6.7e4) - 1.0).abs() < 1e-13);
    }

    #[test]
    fn slope_is_continuous_and_energy_is_the_integral_of_torque() {
        let c = issue_curve();
        let [a, b] = c.corners();
        for corner in [a, b] {
            let mut prev = c.spring_slope(corner * 0.8);
            for k in 1..=4000 {
                let x = corner * (0.8 + 0.4 * k as f64 / 4000.0);
                let s = c.spring_slope(x);
                assert!((s - prev).abs() < 1e-3 * c.k2, "slope jumps at {x}");
                prev = s;
            }
        }
        // Potential against a fine trapezoidal integral of the torque.
        let x = 1.5 * b;
        let n = 200_000;
        let trap: f64 = (0..n)
            .map(|k| {
                let (u, v) = (x * k as f64 / n as f64, x * (k + 1) as f64 / n as f64);
                0.5 * (c.spring_torque(u) + c.spring_torque(v)) * (v - u)
            })
            .sum();
        let e = c.spring_energy(x);
        println!("energy {e:e} J, trapezoid {trap:e} J");
        // Measured ≈ 2.4e-11 (the trapezoid's own error).
        assert!((e / trap - 1.0).abs() < 3e-10);
    }

    /// The torque and slope of `torque_grad` are the curve's own, and its derivatives match
    /// central differences in every piece: the segments, both rounded bands (at either
    /// corner setting the band's width), and negative deflections.
    #[test]
    fn torque_gradient_matches_differences() {
        let mut worst: f64 = 0.0;
        // The issue's curve (the first segment the shorter) and one whose middle segment is
        // the shorter.
        for c in [issue_curve(), CatalogueCurve::new(5e4, 2e5, 8e4, 40.0, 60.0).unwrap()] {
            let [a, b] = c.corners();
            let h = c.half_band();
            for x in [
                0.3 * a,
                a - 0.5 * h,
                a + 0.3 * h,
                0.5 * (a + b),
                b - 0.7 * h,
                b + 0.2 * h,
                1.4 * b,
            ] {
                for theta in [x, -x] {
                    let (t, s, g) = c.torque_grad(theta);
                    assert!((t - c.spring_torque(theta)).abs() <= 1e-12 * t.abs());
                    assert!((s - c.spring_slope(theta)).abs() <= 1e-12 * s.abs());
                    let p = [c.k1, c.k2, c.k3, c.t1, c.t2];
                    for j in 0..5 {
                        let at = |d: f64| {
                            let mut q = p;
                            q[j] += d;
                            let mut cc = CatalogueCurve::new(q[0], q[1], q[2], q[3], q[4]).unwrap();
                            cc.smoothing = c.smoothing;
                            cc.spring_torque(theta)
                        };
                        let step = 1e-6 * p[j];
                        let fd = (at(step) - at(-step)) / (2.0 * step);
                        let scale = t.abs() / p[j];
                        let err = (fd - g[j]).abs() / scale;
                        worst = worst.max(err);
                        assert!(err < 3e-9, "θ = {theta:e}, parameter {j}: {} vs {fd}", g[j]);
                    }
                }
            }
        }
        // Measured 2.9e-10 of T/p (the differences' own rounding).
        println!("catalogue torque gradient: worst {worst:.1e} of T/p");
    }

    #[test]
    fn hysteresis_loss_is_realised_and_first_loading_follows_the_curve() {
        let c = issue_curve();
        let loss = 1.0_f64.to_radians() / 60.0; // 1 arcmin
        let law = with_loss(c, loss, 108.0).unwrap();
        let width = loop_width(&law, c.deflection_at(108.0));
        println!("loop width {width:e} rad for a loss of {loss:e} rad");
        assert!((width / loss - 1.0).abs() < 1e-9, "{width}");
        let th: Vec<f64> = (0..=100).map(|k| 1e-5 * k as f64).collect();
        for (x, t) in th.iter().zip(law.torque_along(&th)) {
            assert!((t - c.spring_torque(*x)).abs() < 1e-9 * c.t2, "{x}: {t}");
        }
        assert!((0..100).all(|k| law.spring.spring_slope(1e-5 * k as f64) > 0.0));
        let e = with_loss(c, 100.0 * loss, 108.0).unwrap_err();
        assert!(e.contains("expected at most"), "{e}");
    }
}
