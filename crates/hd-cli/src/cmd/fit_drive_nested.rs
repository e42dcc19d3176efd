//! `friction = "all"`: a richer law is never ranked below a law it contains because its
//! own fit ended in a worse valley ([`hd_ident::drive::nested`]).

use hd_ident::drive::nested::{nested_in, nested_start};
use hd_ident::drive::{DriveFit, FitSpec, FrictionLaw};

/// The fits of one stage: per law, its set-up and its fit with the fit's time [s].
pub(super) struct Stage<'a> {
    pub laws: &'a [FrictionLaw],
    pub specs: &'a [FitSpec],
    pub fits: &'a mut [(DriveFit, f64)],
}

/// Refit every law whose cost ended above a law it contains (both among the fitted ones)
/// from that law's optimum, and keep the lower fit; the fit's termination says so. `fit_all`
/// runs a batch of set-ups (in parallel) and gives each fit with its time [s].
pub(super) fn keep_nested<E>(
    stages: &mut [Stage],
    fit_all: impl Fn(&[FitSpec]) -> Vec<(Result<DriveFit, E>, f64)>,
) {
    let cost_of = |stages: &[Stage], law: FrictionLaw| {
        stages.iter().find_map(|s| {
            s.laws.iter().position(|&l| l == law).map(|k| (s.fits[k].0.cost, s.fits[k].0.clone()))
        })
    };
    // (stage, index, nested law, set-up from its optimum)
    let mut repairs = Vec::new();
    for (si, stage) in stages.iter().enumerate() {
        for (k, &law) in stage.laws.iter().enumerate() {
            let own = stage.fits[k].0.cost;
            for &inner in nested_in(law) {
                let Some((cost, fit)) = cost_of(stages, inner) else { continue };
                if cost < own
                    && let Some(spec) = nested_start(&stage.specs[k], &fit)
                {
                    repairs.push((si, k, inner, spec));
                }
            }
        }
    }
    if repairs.is_empty() {
        return;
    }
    let specs: Vec<FitSpec> = repairs.iter().map(|r| r.3.clone()).collect();
    for ((si, k, inner, _), (fit, secs)) in repairs.into_iter().zip(fit_all(&specs)) {
        let Ok(mut fit) = fit else { continue };
        let slot = &mut stages[si].fits[k];
        if fit.cost < slot.0.cost {
            fit.termination = format!(
                "{} (refitted from the {} optimum: the first fit ended at cost {:.6e}, above that law's, which this law contains)",
                fit.termination,
                inner.name(),
                slot.0.cost
            );
            *slot = (fit, slot.1 + secs);
        } else {
            slot.1 += secs;
        }
    }
}
