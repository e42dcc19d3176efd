//! Physical parameters of the motor–gear–load system, with the seed study's tables as
//! defaults (docs/model.md §1).

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
            n: 100.0,
            kbar: 7.8e5,
            c0bar: 0.16,
        }
    }
}
