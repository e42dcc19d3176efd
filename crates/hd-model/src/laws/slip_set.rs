//! A fixed-size set of elastoplastic (Maxwell-slip) elements as the simulator carries it
//! (docs/model.md §2.11): `Copy`, allocation-free, at most [`MAX_SLIP`] elements.
//!
//! In the integrated state each element is held by its *offset* `oᵢ = eᵢ − θ` [rad] at the
//! start of the current step, where eᵢ is the element's spring deflection. Inside a step the
//! element follows the play operator exactly — `eᵢ(θ) = clamp(θ + oᵢ, −δᵢ, δᵢ)` as long as θ
//! moves one way — so the law costs no ODE states, stays rate-independent, and its torque is
//! a continuous function of θ (no switching rates for the step control to trip over). When
//! a step is accepted, [`SlipSet::commit`] moves every element along the step's deflection
//! path, split at its turning points, and returns the energy the sliders dissipated.

use super::maxwell_slip::SlipElement;

/// Largest number of slip elements the simulator carries.
pub const MAX_SLIP: usize = 12;

/// The elements of a Maxwell-slip law, by increasing yield deflection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlipSet {
    len: usize,
    el: [SlipElement; MAX_SLIP],
}

impl Default for SlipSet {
    fn default() -> Self {
        Self { len: 0, el: [SlipElement { k: 0.0, f: 0.0 }; MAX_SLIP] }
    }
}

impl SlipSet {
    /// The set of `elements` (sorted by yield deflection); an error if there are more than
    /// [`MAX_SLIP`] or one has a negative or non-finite constant.
    pub fn new(elements: &[SlipElement]) -> Result<Self, String> {
        if elements.len() > MAX_SLIP {
            return Err(format!("{} slip elements: expected at most {MAX_SLIP}", elements.len()));
        }
        let mut s = Self::default();
        for (i, e) in elements.iter().enumerate() {
            if !(e.k.is_finite() && e.k >= 0.0 && e.f.is_finite() && e.f >= 0.0) {
                return Err(format!(
                    "slip element {}: k = {}, F = {}: expected finite values >= 0",
                    i + 1,
                    e.k,
                    e.f
                ));
            }
            s.el[i] = *e;
        }
        s.len = elements.len();
        s.el[..s.len].sort_by(|a, b| a.yield_deflection().total_cmp(&b.yield_deflection()));
        Ok(s)
    }

    /// `n` elements of equal stiffness `k_total/n` [N·m/rad] whose yield deflections are
    /// spread evenly up to `delta_max` [rad] (δᵢ = i/n·δmax): a first loading bends
    /// smoothly from the slope `k_total` at rest to 0 at δmax.
    pub fn even(n: usize, k_total: f64, delta_max: f64) -> Result<Self, String> {
        let els: Vec<SlipElement> = (1..=n)
            .map(|i| SlipElement::from_yield(k_total / n as f64, delta_max * i as f64 / n as f64))
            .collect();
        Self::new(&els)
    }

    /// The elements.
    pub fn as_slice(&self) -> &[SlipElement] {
        &self.el[..self.len]
    }

    /// Number of elements.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the set is empty.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Deflection of element i [rad] at deflection θ [rad] with offset `o` [rad].
    #[inline]
    fn deflection(&self, i: usize, theta: f64, o: f64) -> f64 {
        let d = self.el[i].yield_deflection();
        (theta + o).clamp(-d, d)
    }

    /// The elements' torque Σ kᵢ·eᵢ [N·m] and its slope ∂/∂θ [N·m/rad] (the stiffness of
    /// the elements that are sticking) at θ [rad] with offsets `o` (missing ones are 0).
    #[inline]
    pub fn torque(&self, theta: f64, o: &[f64]) -> (f64, f64) {
        let (mut t, mut s) = (0.0, 0.0);
        for i in 0..self.len {
            let el = &self.el[i];
            let x = theta + o.get(i).copied().unwrap_or(0.0);
            let d = el.yield_deflection();
            if x.abs() < d {
                t += el.k * x;
                s += el.k;
            } else {
                t += el.k * d.copysign(x);
            }
        }
        (t, s)
    }

    /// Energy stored in the elements' springs, Σ ½·kᵢ·eᵢ² [J].
    pub fn stored(&self, theta: f64, o: &[f64]) -> f64 {
        (0..self.len)
            .map(|i| {
                let e = self.deflection(i, theta, o.get(i).copied().unwrap_or(0.0));
                0.5 * self.el[i].k * e * e
            })
            .sum()
    }

    /// Move every element along the deflection path `path` (θ at the step start, then at
    /// each turning point inside the step, then at its end; monotone between entries) and
    /// rewrite the offsets `o` for the end. Returns the energy the sliders dissipated [J].
    pub fn commit(&self, path: &[f64], o: &mut [f64]) -> f64 {
        let (Some(&first), Some(&last)) = (path.first(), path.last()) else { return 0.0 };
        let mut dissipated = 0.0;
        for (i, oi) in o.iter_mut().enumerate().take(self.len) {
            let el = &self.el[i];
            let mut e = self.deflection(i, first, *oi);
            let mut prev = first;
            for &th in &path[1..] {
                let (ne, slip) = el.step(e, th - prev);
                dissipated += el.f * slip;
                e = ne;
                prev = th;
            }
            *oi = e - last;
        }
        dissipated
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_follow_the_play_operator_and_dissipate_the_closed_form() {
        let set = SlipSet::even(5, 5e4, 5e-4).unwrap();
        let mut o = [0.0; MAX_SLIP];
        // One full cycle ±C after a first loading to +C: each element with δᵢ < C slips
        // 4·(C − δᵢ) at Fᵢ per cycle (the first loading adds C − δᵢ once).
        let c = 4e-4;
        let mut diss = set.commit(&[0.0, c], &mut o);
        let first: f64 =
            set.as_slice().iter().map(|e| e.f * (c - e.yield_deflection()).max(0.0)).sum();
        assert!((diss - first).abs() <= 1e-15 * first);
        diss = set.commit(&[c, -c, c], &mut o);
        let cycle: f64 =
            set.as_slice().iter().map(|e| 4.0 * e.f * (c - e.yield_deflection()).max(0.0)).sum();
        println!("cycle dissipation {diss:e} J, closed form {cycle:e} J");
        assert!((diss - cycle).abs() <= 1e-14 * cycle);
        // The torque at the end of the cycle is the first-loading torque at +C.
        let (t, _) = set.torque(c, &o);
        let virgin: f64 = set.as_slice().iter().map(|e| e.virgin_torque(c)).sum();
        assert!((t - virgin).abs() <= 1e-12 * virgin.abs());
    }

    #[test]
    fn rejects_too_many_or_negative_elements() {
        let e = SlipElement { k: 1.0, f: 1.0 };
        assert!(SlipSet::new(&[e; MAX_SLIP + 1]).unwrap_err().contains("at most 12"));
        assert!(SlipSet::new(&[SlipElement { k: -1.0, f: 1.0 }]).is_err());
    }
}
