//! The colour scale of heatmaps: a perceptually ordered dark-blue → green → yellow ramp
//! (close to matplotlib's "viridis"), and the neutral grey used for missing values.

use plotters::style::RGBColor;

/// Colour of a cell without a finite value.
pub(crate) const MISSING: RGBColor = RGBColor(190, 190, 190);

/// Stops of the ramp, evenly spaced from 0 to 1.
const STOPS: [(f64, f64, f64); 6] = [
    (68.0, 1.0, 84.0),
    (65.0, 68.0, 135.0),
    (42.0, 120.0, 142.0),
    (34.0, 168.0, 132.0),
    (122.0, 209.0, 81.0),
    (253.0, 231.0, 37.0),
];

/// Colour at position `f` of the ramp; `f` is clamped to `[0, 1]`, NaN gives [`MISSING`].
pub(crate) fn ramp(f: f64) -> RGBColor {
    if f.is_nan() {
        return MISSING;
    }
    let pos = f.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let i = (pos.floor() as usize).min(STOPS.len() - 2);
    let w = pos - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let mix = |p: f64, q: f64| (p + w * (q - p)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Maps values in `[lo, hi]` onto the ramp.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ColorScale {
    /// Value shown darkest.
    pub lo: f64,
    /// Value shown brightest.
    pub hi: f64,
}

impl ColorScale {
    /// Colour of `v`; non-finite values get [`MISSING`], an all-equal scale the middle.
    pub(crate) fn color(&self, v: f64) -> RGBColor {
        if !v.is_finite() {
            return MISSING;
        }
        if self.hi > self.lo { ramp((v - self.lo) / (self.hi - self.lo)) } else { ramp(0.5) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_ends_and_missing() {
        assert_eq!(ramp(0.0), RGBColor(68, 1, 84));
        assert_eq!(ramp(1.0), RGBColor(253, 231, 37));
        assert_eq!(ramp(2.0), ramp(1.0));
        let scale = ColorScale { lo: 0.0, hi: 1.0 };
        assert_eq!(scale.color(f64::NAN), MISSING);
    }
}
