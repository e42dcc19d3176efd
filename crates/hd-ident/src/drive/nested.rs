//! Nested friction laws of the rigid drive, so that a richer law never scores worse than
//! a law it contains because its own fit stopped in a worse valley.
//!
//! The directional laws contain the symmetric ones: with the same viscous coefficient on
//! both sides and the offset moved into the levels (the positive side's levels raised by
//! it, the negative side's lowered), `directional` reproduces `coulomb-viscous` in sliding,
//! and `directional-lugre` reproduces `lugre`. The LuGre laws already start from their
//! Coulomb–viscous base ([`super::setup::spec`]). [`nested_start`] maps a fitted nested
//! law's values onto the richer law's parameters; a fit whose cost ends above a nested
//! law's is refitted from that start and the lower of the two kept.

use super::fit::{DriveFit, FitSpec};
use super::model::FrictionLaw;

/// The laws `law` contains that [`nested_start`] maps exactly in sliding.
pub fn nested_in(law: FrictionLaw) -> &'static [FrictionLaw] {
    match law {
        FrictionLaw::Directional => &[FrictionLaw::CoulombViscous],
        FrictionLaw::DirectionalLuGre => &[FrictionLaw::LuGre],
        _ => &[],
    }
}

/// `spec` started from the fitted nested law `nested` (one of [`nested_in`]`(spec.law)`),
/// by [`mapped_values`]. None where `nested` is not nested in `spec.law`.
pub fn nested_start(spec: &FitSpec, nested: &DriveFit) -> Option<FitSpec> {
    if !nested_in(spec.law).contains(&nested.law) {
        return None;
    }
    let mut out = spec.clone();
    out.start = mapped_values(
        spec.law,
        &spec.start,
        &spec.free,
        (&spec.lower, &spec.upper),
        (&nested.names, &nested.values),
    );
    Some(out)
}

/// The start of `law` (current `start`, `free` flags, `bounds` lower and upper) with every
/// free parameter it shares with the nested law's fit (`nested`: names, values) at its
/// fitted value and the directional levels
/// at the symmetric level with the offset moved into them, each clamped to its bounds; a
/// parameter held fixed keeps its value.
pub fn mapped_values(
    law: FrictionLaw,
    start: &[f64],
    free: &[bool],
    bounds: (&[f64], &[f64]),
    nested: (&[&str], &[f64]),
) -> Vec<f64> {
    let (lower, upper) = bounds;
    let get = |name: &str| nested.0.iter().position(|n| *n == name).map(|k| nested.1[k]);
    let offset = get("offset").unwrap_or(0.0);
    let mut out = start.to_vec();
    for (k, name) in law.names().iter().enumerate() {
        if !free[k] {
            continue;
        }
        let value = match *name {
            "Fv_pos" | "Fv_neg" => get("Fv"),
            "Fc_pos" => get("Fc").map(|v| v + offset),
            "Fc_neg" => get("Fc").map(|v| v - offset),
            "Fs_pos" => get("Fs").map(|v| v + offset),
            "Fs_neg" => get("Fs").map(|v| v - offset),
            n => get(n),
        };
        if let Some(v) = value.filter(|v| v.is_finite()) {
            out[k] = v.clamp(lower[k], upper[k]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Steady sliding force [N] of `law` with parameters `p` at speed v [m/s]: the force
    /// the drive must overcome, offset included.
    fn sliding(law: FrictionLaw, p: &[f64], v: f64) -> f64 {
        let at = |name: &str| p[law.names().iter().position(|n| *n == name).unwrap()];
        let has = |name: &str| law.names().contains(&name);
        let side = if v > 0.0 { "_pos" } else { "_neg" };
        let pick = |name: &str| {
            if has(name) { at(name) } else { at(&format!("{name}{side}")) }
        };
        let (fv, fc) = (pick("Fv"), pick("Fc"));
        let level = if law.is_lugre() {
            let fs = pick("Fs");
            fc + (fs - fc) * (-(v / at("vs")).powi(2)).exp()
        } else {
            fc
        };
        let offset = if has("offset") { at("offset") } else { 0.0 };
        fv * v + v.signum() * level + offset
    }

    /// The mapped directional law slides as the symmetric one it contains, at speeds of
    /// either sign.
    #[test]
    fn the_mapped_directional_law_slides_as_the_symmetric_one() {
        for (rich, base, p) in [
            (
                FrictionLaw::Directional,
                FrictionLaw::CoulombViscous,
                vec![2.0, 15.0, 20.0, -3.0, 30.0],
            ),
            (
                FrictionLaw::DirectionalLuGre,
                FrictionLaw::LuGre,
                vec![2.0, 15.0, 20.0, -3.0, 26.0, 0.01, 1e6, 300.0, 30.0],
            ),
        ] {
            let n = rich.names().len();
            let (lo, hi) = (vec![-1e9; n], vec![1e9; n]);
            let q =
                mapped_values(rich, &vec![1.0; n], &vec![true; n], (&lo, &hi), (base.names(), &p));
            for v in [-0.5, -0.02, -1e-4, 1e-4, 0.02, 0.5] {
                let (a, b) = (sliding(base, &p, v), sliding(rich, &q, v));
                println!("{} at {v}: {a} vs {b}", rich.name());
                assert!((a - b).abs() <= 1e-12 * a.abs().max(1.0), "{a} vs {b}");
            }
        }
    }
}
