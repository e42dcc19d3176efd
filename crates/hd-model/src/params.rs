//! Physical parameters of the motor–gear–load system, with the seed study's tables as
//! defaults (docs/model.md §1).

use crate::laws::maxwell_slip::SlipElement;
use serde::{Deserialize, Serialize};

/// Every physical parameter of the drive. Field names follow the parameter registry
/// (see [`crate::registry`]); the serde names are the registry names.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// Cubic stiffness coefficient `a` [N·m/rad³]; default 0.12.
    #[serde(rename = "a")]
    pub a: f64,
    /// Quadratic stiffness coefficient `b` [N·m/rad²]; default 0.56.
    #[serde(rename = "b")]
    pub b: f64,
    /// Linear stiffness coefficient `c` [N·m/rad]; default 52 000.
    #[serde(rename = "c")]
    pub c: f64,
    /// Memory intensity `mem_A` (the seed's `A`) [N·m/rad] (kernel `A·e^{−B·age}` acting
    /// on the deflection rate); default 40 000.
    #[serde(rename = "mem_A", alias = "A")]
    pub mem_a: f64,
    /// Memory decay rate `mem_B` (the seed's `B`) [1/s]; default 300.
    #[serde(rename = "mem_B", alias = "B")]
    pub mem_b: f64,
    /// LuGre bristle stiffness σ0 [N·m/rad]; default 1.2e5.
    pub sigma0: f64,
    /// LuGre bristle damping σ1 [N·m·s/rad]; default 0.8.
    pub sigma1: f64,
    /// LuGre viscous coefficient σ2 [N·m·s/rad]; default 0.
    pub sigma2: f64,
    /// Coulomb friction torque Tc [N·m]; default 0.15.
    #[serde(rename = "Tc")]
    pub tc: f64,
    /// Static (break-away) friction torque Ts [N·m]; default 0.25.
    #[serde(rename = "Ts")]
    pub ts: f64,
    /// Stribeck velocity ωs [rad/s]; default 0.01.
    pub ws: f64,
    /// Coulomb friction torque for negative sliding speeds `Tc_neg` [N·m]; unset (the
    /// default) means equal to Tc, a symmetric law.
    #[serde(rename = "Tc_neg", skip_serializing_if = "Option::is_none")]
    pub tc_neg: Option<f64>,
    /// Static friction torque for negative sliding speeds `Ts_neg` [N·m]; unset (the
    /// default) means equal to Ts.
    #[serde(rename = "Ts_neg", skip_serializing_if = "Option::is_none")]
    pub ts_neg: Option<f64>,
    /// Growth of the Coulomb level with the transmitted torque while driving forward
    /// (`Tc + mu_c_fwd·|Tb|`) [–]; default 0.
    pub mu_c_fwd: f64,
    /// Growth of the static level with the transmitted torque while driving forward
    /// (`Ts + mu_s_fwd·|Tb|`) [–]; default 0.
    pub mu_s_fwd: f64,
    /// Growth of the Coulomb level with the transmitted torque while back-driven [–];
    /// default 0.
    pub mu_c_back: f64,
    /// Growth of the static level with the transmitted torque while back-driven [–];
    /// default 0.
    pub mu_s_back: f64,
    /// Armature resistance R [Ω]; default 6.
    #[serde(rename = "R")]
    pub r: f64,
    /// Motor torque constant Km [N·m/A]; default 0.52.
    #[serde(rename = "Km")]
    pub km: f64,
    /// Back-EMF constant Ke [V·s/rad]; default 0.52.
    #[serde(rename = "Ke")]
    pub ke: f64,
    /// Armature inductance L [H]; default 0 (current is algebraic, as in the seed).
    #[serde(rename = "L")]
    pub l: f64,
    /// Motor (wave-generator side) inertia Jj [kg·m²]; default 6.8e-4.
    #[serde(rename = "Jj")]
    pub jj: f64,
    /// Load inertia Jz [kg·m²]; default 2.4e-2.
    #[serde(rename = "Jz")]
    pub jz: f64,
    /// Motor viscous damping Cj [N·m·s/rad]; default 0.003.
    #[serde(rename = "Cj")]
    pub cj: f64,
    /// Load viscous damping Cz [N·m·s/rad]; default 0.005.
    #[serde(rename = "Cz")]
    pub cz: f64,
    /// Constant load torque `TL` [N·m] acting against positive load motion (gravity on an
    /// unbalanced arm, a spring preload, a process force), added to any time-varying load
    /// torque of the run; default 0. Left out of the JSON form at 0, so configurations
    /// without it keep the run identifiers they had before it existed.
    #[serde(rename = "TL", skip_serializing_if = "is_zero")]
    pub tl: f64,
    /// Load-side LuGre law (`*_load`, docs/model.md §2.6): a second friction law on the
    /// load's speed ωz, beside the gear's own, present when its Coulomb or static level is
    /// above 0. Coulomb level `Tc_load` [N·m]; default 0 (no load-side law). Each `*_load`
    /// field is left out of the JSON form at 0, so run identifiers are unchanged without it.
    #[serde(rename = "Tc_load", skip_serializing_if = "is_zero")]
    pub tc_load: f64,
    /// Static level of the load-side law `Ts_load` [N·m]; default 0.
    #[serde(rename = "Ts_load", skip_serializing_if = "is_zero")]
    pub ts_load: f64,
    /// Coulomb level of the load-side law for negative load speeds `Tc_neg_load` [N·m];
    /// unset (the default) means equal to `Tc_load`, a symmetric law.
    #[serde(rename = "Tc_neg_load", skip_serializing_if = "Option::is_none")]
    pub tc_neg_load: Option<f64>,
    /// Static level of the load-side law for negative load speeds `Ts_neg_load` [N·m];
    /// unset (the default) means equal to `Ts_load`.
    #[serde(rename = "Ts_neg_load", skip_serializing_if = "Option::is_none")]
    pub ts_neg_load: Option<f64>,
    /// Stribeck velocity of the load-side law `ws_load` [rad/s]; default 0 (must be set
    /// when the law is present).
    #[serde(skip_serializing_if = "is_zero")]
    pub ws_load: f64,
    /// Bristle stiffness of the load-side law `sigma0_load` [N·m/rad]; default 0 (must be
    /// set when the law is present).
    #[serde(skip_serializing_if = "is_zero")]
    pub sigma0_load: f64,
    /// Bristle damping of the load-side law `sigma1_load` [N·m·s/rad]; default 0.
    #[serde(skip_serializing_if = "is_zero")]
    pub sigma1_load: f64,
    /// Viscous coefficient of the load-side law `sigma2_load` [N·m·s/rad]; default 0.
    #[serde(skip_serializing_if = "is_zero")]
    pub sigma2_load: f64,
    /// Gear ratio N [–]; default 100.
    #[serde(rename = "N")]
    pub n: f64,
    /// Nominal (average) gear stiffness K̄ [N·m/rad] of the `linear` and `damped`
    /// variants; default 7.8e5.
    #[serde(rename = "Kbar")]
    pub kbar: f64,
    /// Nominal viscous friction coefficient C̄0 [N·m·s/rad] of the `damped` variant;
    /// default 0.16.
    #[serde(rename = "C0bar")]
    pub c0bar: f64,
    /// Number of Maxwell-slip elements `ms_n` of the `maxwell-slip` law (spread evenly up to
    /// `ms_delta`) [–]; default 8, at most 12.
    pub ms_n: f64,
    /// Total stiffness of the Maxwell-slip elements `ms_k` [N·m/rad]; default 40 000 (the
    /// memory law's A).
    pub ms_k: f64,
    /// Largest yield deflection of the Maxwell-slip elements `ms_delta` [rad]; default 2e-5
    /// (twice the seed case's deflection amplitude).
    pub ms_delta: f64,
    /// Explicit Maxwell-slip elements (`ms_k<i>` [N·m/rad], `ms_f<i>` [N·m], i from 1), as
    /// `hdw fit hysteresis --law maxwell-slip` reports them; when any has a stiffness > 0
    /// they replace the even set of `ms_n`, `ms_k`, `ms_delta`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub ms_elements: Vec<SlipElement>,
    /// Bouc–Wen hysteretic stiffness α `bw_alpha` [N·m/rad]; default 40 000.
    pub bw_alpha: f64,
    /// Bouc–Wen rate gain A `bw_A` [–]; default 1.
    #[serde(rename = "bw_A")]
    pub bw_a: f64,
    /// Bouc–Wen shape constant β `bw_beta` [rad^−n]; default 5e4.
    pub bw_beta: f64,
    /// Bouc–Wen shape constant γ `bw_gamma` [rad^−n]; default 5e4 (with β: saturation at
    /// w = 1e-5 rad).
    pub bw_gamma: f64,
    /// Bouc–Wen smoothness exponent n `bw_n` [–]; default 1.
    pub bw_n: f64,
    /// Catalogue spring rate below T1 `cat_K1` [N·m/rad]; default 6.7e4.
    #[serde(rename = "cat_K1")]
    pub cat_k1: f64,
    /// Catalogue spring rate from T1 to T2 `cat_K2` [N·m/rad]; default 1.1e5.
    #[serde(rename = "cat_K2")]
    pub cat_k2: f64,
    /// Catalogue spring rate above T2 `cat_K3` [N·m/rad]; default 1.2e5.
    #[serde(rename = "cat_K3")]
    pub cat_k3: f64,
    /// Catalogue corner torque T1 `cat_T1` [N·m]; default 29.
    #[serde(rename = "cat_T1")]
    pub cat_t1: f64,
    /// Catalogue corner torque T2 `cat_T2` [N·m]; default 108.
    #[serde(rename = "cat_T2")]
    pub cat_t2: f64,
    /// Catalogue hysteresis loss `cat_loss` (loop width at zero torque after ±`cat_rated`)
    /// [rad]; default 0 (no hysteresis).
    pub cat_loss: f64,
    /// Rated torque `cat_rated` at which the catalogue's hysteresis loss is given [N·m];
    /// default 108.
    #[serde(alias = "rated_torque")]
    pub cat_rated: f64,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            a: 0.12,
            b: 0.56,
            c: 52_000.0,
            mem_a: 40_000.0,
            mem_b: 300.0,
            sigma0: 1.2e5,
            sigma1: 0.8,
            sigma2: 0.0,
            tc: 0.15,
            ts: 0.25,
            ws: 0.01,
            tc_neg: None,
            ts_neg: None,
            mu_c_fwd: 0.0,
            mu_s_fwd: 0.0,
            mu_c_back: 0.0,
            mu_s_back: 0.0,
            r: 6.0,
            km: 0.52,
            ke: 0.52,
            l: 0.0,
            jj: 6.8e-4,
            jz: 2.4e-2,
            cj: 0.003,
            cz: 0.005,
            tl: 0.0,
            tc_load: 0.0,
            ts_load: 0.0,
            tc_neg_load: None,
            ts_neg_load: None,
            ws_load: 0.0,
            sigma0_load: 0.0,
            sigma1_load: 0.0,
            sigma2_load: 0.0,
            n: 100.0,
            kbar: 7.8e5,
            c0bar: 0.16,
            ms_n: 8.0,
            ms_k: 40_000.0,
            ms_delta: 2e-5,
            ms_elements: Vec::new(),
            bw_alpha: 40_000.0,
            bw_a: 1.0,
            bw_beta: 5e4,
            bw_gamma: 5e4,
            bw_n: 1.0,
            cat_k1: 6.7e4,
            cat_k2: 1.1e5,
            cat_k3: 1.2e5,
            cat_t1: 29.0,
            cat_t2: 108.0,
            cat_loss: 0.0,
            cat_rated: 108.0,
        }
    }
}

/// Whether `v` is zero (serde's test for leaving a parameter out).
fn is_zero(v: &f64) -> bool {
    *v == 0.0
}
