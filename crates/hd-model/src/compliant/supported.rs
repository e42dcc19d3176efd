//! What the compliant model can stand for. Its drive is the simulator's `full` variant with
//! the cubic spring plus the fading memory (`memory`, the seed's law), a Bouc–Wen element
//! (`bouc-wen`), `ms_n` evenly spread Maxwell-slip elements (`maxwell-slip`) or the
//! catalogue's three-segment curve without its hysteresis loss (`catalogue`), an
//! algebraic current, LuGre friction (its levels may differ by direction) that does not
//! grow with the transmitted torque, on the motor's side, on the load's or across the gear
//! (or a second, symmetric law on the load beside the gear's), and a constant load torque
//! TL. A params file
//! that asks for more would be fitted as something it is not and written back as a params
//! file `hdw simulate` runs differently, so each such setting is refused, named.

use super::model::P;
use crate::laws::catalogue::CatalogueCurve;
use crate::laws::slip_set::MAX_SLIP;
use crate::{HystLaw, Params};

/// Each setting of `p` (stiffness law `law`) that the compliant model cannot represent, as
/// one sentence; empty when it represents them all.
pub fn unsupported(p: &Params, law: Option<HystLaw>) -> Vec<String> {
    let mut out = Vec::new();
    if law == Some(HystLaw::Catalogue) {
        if p.cat_loss != 0.0 {
            out.push(format!(
                "cat_loss = {:e}: the compliant fit's catalogue gear is its curve without the hysteresis loss (the loss's slip elements are sized by a search, which has no exact derivative); set cat_loss = 0, or fit the loop as Maxwell-slip elements (\"maxwell-slip\")",
                p.cat_loss
            ));
        }
        if let Err(e) = CatalogueCurve::new(p.cat_k1, p.cat_k2, p.cat_k3, p.cat_t1, p.cat_t2) {
            out.push(format!("cat_{e}"));
        }
    }
    if law == Some(HystLaw::BoucWen) && !(p.bw_alpha > 0.0 && p.bw_a > 0.0 && p.bw_n > 0.0) {
        out.push(format!(
            "bw_alpha = {:e}, bw_A = {:e}, bw_n = {:e}: a Bouc–Wen gear needs a positive stiffness α, rate gain A and exponent n (α = 0 is the gear without the element: use the memory law with mem_A = 0)",
            p.bw_alpha, p.bw_a, p.bw_n
        ));
    }
    if law == Some(HystLaw::MaxwellSlip) {
        if p.ms_elements.iter().any(|e| e.k > 0.0) {
            out.push(
                "ms_k<i>, ms_f<i>: the compliant fit's slip elements are the even set of ms_n, ms_k and ms_delta; remove the explicit elements".to_string(),
            );
        }
        let whole = p.ms_n.fract() == 0.0 && (1.0..=MAX_SLIP as f64).contains(&p.ms_n);
        if !(whole && p.ms_k > 0.0 && p.ms_delta > 0.0) {
            out.push(format!(
                "ms_n = {}, ms_k = {:e}, ms_delta = {:e}: expected a whole number of elements in [1, {MAX_SLIP}] and a positive total stiffness and yield deflection",
                p.ms_n, p.ms_k, p.ms_delta
            ));
        }
    }
    if p.l != 0.0 {
        out.push(format!(
            "L = {:e}: the compliant fit's motor has an algebraic current (L = 0), so its electrical time constant L/R = {:.3e} s must lie well below the sample period; set L = 0",
            p.l,
            p.l / p.r
        ));
    }
    for (name, v) in [
        ("mu_c_fwd", p.mu_c_fwd),
        ("mu_s_fwd", p.mu_s_fwd),
        ("mu_c_back", p.mu_c_back),
        ("mu_s_back", p.mu_s_back),
    ] {
        if v != 0.0 {
            out.push(format!(
                "{name} = {v:e}: the compliant fit's friction does not grow with the transmitted torque; set {name} = 0"
            ));
        }
    }
    out
}

/// Why the load-side friction law of start values `start` ([`NAMES`] order) cannot be
/// simulated with the gear's friction where `fv` puts it, or at all (hd-model's
/// own check: a present law needs σ0_load and ωs_load above 0, and the gear law elsewhere);
/// `None` when it can, or when there is none.
pub fn load_law_problem(start: &[f64; P], fv: crate::FrictionVelocity) -> Option<String> {
    use super::model::ix::*;
    let p = Params {
        tc_load: start[TC_L],
        ts_load: start[TS_L],
        tc_neg_load: Some(start[TC_NEG_L]),
        ts_neg_load: Some(start[TS_NEG_L]),
        ws_load: start[WS_L],
        sigma0_load: start[SIGMA0_L],
        sigma1_load: start[SIGMA1_L],
        sigma2_load: start[SIGMA2_L],
        ..Params::default()
    };
    crate::variant::load_friction_law(&p, fv).err().map(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The seed's parameters are representable; each unsupported setting is named once.
    #[test]
    fn the_seed_passes_and_each_extra_is_named() {
        let seed = Params::default();
        assert!(unsupported(&seed, None).is_empty());
        assert!(unsupported(&seed, Some(HystLaw::Memory)).is_empty());
        assert!(unsupported(&seed, Some(HystLaw::BoucWen)).is_empty());
        assert!(unsupported(&seed, Some(HystLaw::MaxwellSlip)).is_empty());
        let flat = Params { bw_alpha: 0.0, ..Params::default() };
        let found = unsupported(&flat, Some(HystLaw::BoucWen));
        assert!(found.len() == 1 && found[0].starts_with("bw_alpha = 0"), "{found:?}");
        let odd = Params { ms_n: 2.5, ..Params::default() };
        let found = unsupported(&odd, Some(HystLaw::MaxwellSlip));
        assert!(found.len() == 1 && found[0].starts_with("ms_n = 2.5"), "{found:?}");
        let p = Params { l: 1e-3, tc_neg: Some(0.2), mu_s_back: 0.1, ..Params::default() };
        // Direction-dependent levels are the model's own (Tc_neg, Ts_neg).
        let found = unsupported(&p, Some(HystLaw::Memory));
        assert_eq!(found.len(), 2, "{found:?}");
        for key in ["L = 1e-3", "mu_s_back"] {
            assert!(found.iter().any(|s| s.starts_with(key)), "{key} in {found:?}");
        }
        // The catalogue curve is the model's own; its loss and a curve it cannot build are
        // named.
        assert!(unsupported(&seed, Some(HystLaw::Catalogue)).is_empty());
        let lossy = Params { cat_loss: 1e-4, cat_t2: 20.0, ..Params::default() };
        let found = unsupported(&lossy, Some(HystLaw::Catalogue));
        assert_eq!(found.len(), 2, "{found:?}");
        for key in ["cat_loss = 1e-4", "cat_T2 = 20"] {
            assert!(found.iter().any(|s| s.starts_with(key)), "{key} in {found:?}");
        }
    }
}
