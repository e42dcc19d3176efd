//! The compliant drive's parameters: their order in a parameter vector (hd-model's registry
//! names), which of them each gear law and the load-side friction law own, and how a
//! vector is put on a law.

use crate::HystLaw;

/// Number of parameters of the compliant drive.
pub const P: usize = 42;

/// The parameters of the compliant drive, in the order of a parameter vector (hd-model's
/// registry names, so a fitted set is a params file `hdw simulate` reads).
#[rustfmt::skip]
pub const NAMES: [&str; P] = [
    "R", "Km", "Ke", "Jj", "Jz", "Cj", "Cz", "c", "a", "b", "mem_A", "mem_B", "sigma0", "sigma1",
    "sigma2", "Tc", "Ts", "ws", "bw_alpha", "bw_A", "bw_beta", "bw_gamma", "bw_n", "ms_k",
    "ms_delta", "ms_n", "Tc_neg", "Ts_neg", "TL", "Tc_load", "Ts_load", "ws_load", "sigma0_load",
    "sigma1_load", "sigma2_load", "cat_K1", "cat_K2", "cat_K3", "cat_T1", "cat_T2",
    "Tc_neg_load", "Ts_neg_load",
];

/// The load-side law's parameters ([`has_load_law`]).
pub const LOAD_LAW: [usize; 8] = [
    ix::TC_L,
    ix::TS_L,
    ix::WS_L,
    ix::SIGMA0_L,
    ix::SIGMA1_L,
    ix::SIGMA2_L,
    ix::TC_NEG_L,
    ix::TS_NEG_L,
];

/// Whether parameters `p` have hd-model's load-side friction law: one of its levels
/// (Tc_load, Ts_load, Tc_neg_load, Ts_neg_load) ≠ 0.
pub fn has_load_law(p: &[f64; P]) -> bool {
    [ix::TC_L, ix::TS_L, ix::TC_NEG_L, ix::TS_NEG_L].iter().any(|&k| p[k] != 0.0)
}

/// Whether parameter `k` belongs to the drive of parameters `p`: its gear law's
/// ([`in_law`]), and the load-side law's only when it has one.
pub fn in_drive(k: usize, p: &[f64; P]) -> bool {
    in_law(k, gear_law(p)) && (has_load_law(p) || !LOAD_LAW.contains(&k))
}

/// The gear laws of the compliant drive.
pub const LAWS: [HystLaw; 4] =
    [HystLaw::Memory, HystLaw::BoucWen, HystLaw::MaxwellSlip, HystLaw::Catalogue];

/// The cubic spring's coefficients, which the catalogue law's curve replaces.
const CUBIC: [usize; 3] = [ix::C, ix::A, ix::B];

/// The hysteretic parameters of each gear law the compliant drive takes.
pub fn hysteresis_of(law: HystLaw) -> &'static [usize] {
    use ix::*;
    match law {
        HystLaw::BoucWen => &[BW_ALPHA, BW_A, BW_BETA, BW_GAMMA, BW_N],
        HystLaw::MaxwellSlip => &[MS_K, MS_DELTA, MS_N],
        HystLaw::Catalogue => &[CAT_K1, CAT_K2, CAT_K3, CAT_T1, CAT_T2],
        _ => &[MEM_A, MEM_B],
    }
}

/// The gear law of parameters `p`: the catalogue curve where its first rate cat_K1 is
/// non-zero, Maxwell-slip where the elements' stiffness ms_k is, Bouc–Wen where its
/// stiffness α is, the fading memory otherwise.
pub fn gear_law(p: &[f64; P]) -> HystLaw {
    if p[ix::CAT_K1] != 0.0 {
        HystLaw::Catalogue
    } else if p[ix::MS_K] != 0.0 {
        HystLaw::MaxwellSlip
    } else if p[ix::BW_ALPHA] != 0.0 {
        HystLaw::BoucWen
    } else {
        HystLaw::Memory
    }
}

/// Whether parameter `k` belongs to a drive with gear law `law` (every parameter but the
/// other law's hysteretic ones, and, for the catalogue law, the cubic spring's).
pub fn in_law(k: usize, law: HystLaw) -> bool {
    LAWS.into_iter().filter(|&l| l != law).all(|l| !hysteresis_of(l).contains(&k))
        && !(law == HystLaw::Catalogue && CUBIC.contains(&k))
}

/// Put `p` on gear law `law`: the other law's hysteretic parameters to zero (and the cubic
/// spring's, for the catalogue law, whose curve is the whole spring).
pub fn on_law(p: &mut [f64; P], law: HystLaw) {
    if law == HystLaw::Catalogue {
        for k in CUBIC {
            p[k] = 0.0;
        }
    }
    for l in LAWS {
        if l != law {
            for &k in hysteresis_of(l) {
                p[k] = 0.0;
            }
        }
    }
}

/// Index of each parameter in [`NAMES`].
pub mod ix {
    pub const R: usize = 0;
    pub const KM: usize = 1;
    pub const KE: usize = 2;
    pub const JJ: usize = 3;
    pub const JZ: usize = 4;
    pub const CJ: usize = 5;
    pub const CZ: usize = 6;
    pub const C: usize = 7;
    pub const A: usize = 8;
    pub const B: usize = 9;
    pub const MEM_A: usize = 10;
    pub const MEM_B: usize = 11;
    pub const SIGMA0: usize = 12;
    pub const SIGMA1: usize = 13;
    pub const SIGMA2: usize = 14;
    pub const TC: usize = 15;
    pub const TS: usize = 16;
    pub const WS: usize = 17;
    pub const BW_ALPHA: usize = 18;
    pub const BW_A: usize = 19;
    pub const BW_BETA: usize = 20;
    pub const BW_GAMMA: usize = 21;
    pub const BW_N: usize = 22;
    pub const MS_K: usize = 23;
    pub const MS_DELTA: usize = 24;
    pub const MS_N: usize = 25;
    pub const TC_NEG: usize = 26;
    pub const TS_NEG: usize = 27;
    pub const TL: usize = 28;
    pub const TC_L: usize = 29;
    pub const TS_L: usize = 30;
    pub const WS_L: usize = 31;
    pub const SIGMA0_L: usize = 32;
    pub const SIGMA1_L: usize = 33;
    pub const SIGMA2_L: usize = 34;
    pub const CAT_K1: usize = 35;
    pub const CAT_K2: usize = 36;
    pub const CAT_K3: usize = 37;
    pub const CAT_T1: usize = 38;
    pub const CAT_T2: usize = 39;
    pub const TC_NEG_L: usize = 40;
    pub const TS_NEG_L: usize = 41;
}
