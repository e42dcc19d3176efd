//! One step of the explicit Runge–Kutta pair of order 8 of Dormand and Prince with the
//! error estimate of Hairer's DOP853 (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.10):
//! twelve stages, the last evaluation at the new point reused as the next step's first
//! (first-same-as-last), and an error built from a fifth- and a third-order difference.
//! The coefficients are the published ones (as tabulated with Hairer's code and SciPy).
//!
//! For tight tolerances: where Dopri5 is held by accuracy, not stability, an eighth-order
//! step goes several times as far for twice the evaluations.

// The coefficients keep every digit of the published values.
#![allow(clippy::excessive_precision)]

use super::{OdeSystem, combine, combine_coupled, combine_coupled_from, stiffness_indicator};
use nalgebra::SVector;

/// Number of stages (evaluations per step, counting the one at the new point).
pub(crate) const STAGES: usize = 12;

const C: [f64; STAGES] = [
    0.0,
    0.052_600_151_958_767_73,
    0.078_900_227_938_151_6,
    0.118_350_341_907_227_4,
    0.281_649_658_092_772_6,
    1.0 / 3.0,
    0.25,
    4.0 / 13.0,
    127.0 / 195.0,
    0.6,
    6.0 / 7.0,
    1.0,
];

/// Stage coefficients a_ij (j < i); row i holds the weights of stages 0..i.
const A: [[f64; STAGES - 1]; STAGES] = [
    [0.0; 11],
    [0.052_600_151_958_767_73, 0., 0., 0., 0., 0., 0., 0., 0., 0., 0.],
    [0.019_725_056_984_537_9, 0.059_175_170_953_613_7, 0., 0., 0., 0., 0., 0., 0., 0., 0.],
    [0.029_587_585_476_806_85, 0., 0.088_762_756_430_420_55, 0., 0., 0., 0., 0., 0., 0., 0.],
    [
        0.241_365_134_159_266_7,
        0.,
        -0.884_549_479_328_286_1,
        0.924_834_003_261_792,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
    ],
    [
        1.0 / 27.0,
        0.,
        0.,
        0.170_828_608_729_473_87,
        0.125_467_687_566_822_43,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
    ],
    [
        0.037_109_375,
        0.,
        0.,
        0.170_252_211_019_544_04,
        0.060_216_538_980_455_96,
        -0.017_578_125,
        0.,
        0.,
        0.,
        0.,
        0.,
    ],
    [
        0.037_092_000_118_504_79,
        0.,
        0.,
        0.170_383_925_712_24,
        0.107_262_030_446_373_28,
        -0.015_319_437_748_624_4,
        0.008_273_789_163_814_023,
        0.,
        0.,
        0.,
        0.,
    ],
    [
        0.624_110_958_716_075_7,
        0.,
        0.,
        -3.360_892_629_446_941,
        -0.868_219_346_841_726,
        27.592_099_699_446_708,
        20.154_067_550_477_893,
        -43.489_884_181_069_96,
        0.,
        0.,
        0.,
    ],
    [
        0.477_662_536_438_264_4,
        0.,
        0.,
        -2.488_114_619_971_667_7,
        -0.590_290_826_836_843,
        21.230_051_448_181_194,
        15.279_233_632_882_424,
        -33.288_210_968_984_86,
        -0.020_331_201_708_508_626,
        0.,
        0.,
    ],
    [
        -0.937_142_430_085_987_3,
        0.,
        0.,
        5.186_372_428_844_064,
        1.091_437_348_996_729_6,
        -8.149_787_010_746_926,
        -18.520_065_659_996_96,
        22.739_487_099_350_504,
        2.493_605_552_679_652_4,
        -3.046_764_471_898_219_5,
        0.,
    ],
    [
        2.273_310_147_516_538,
        0.,
        0.,
        -10.534_495_466_737_25,
        -2.000_872_058_224_862_5,
        -17.958_931_863_118_8,
        27.948_884_529_419_96,
        -2.858_998_277_135_023_7,
        -8.872_856_933_530_63,
        12.360_567_175_794_303,
        0.643_392_746_015_763_5,
    ],
];

/// Eighth-order weights.
const B: [f64; STAGES] = [
    0.054_293_734_116_568_76,
    0.,
    0.,
    0.,
    0.,
    4.450_312_892_752_409,
    1.891_517_899_314_500_3,
    -5.801_203_960_010_585,
    0.311_164_366_957_819_9,
    -0.152_160_949_662_516_08,
    0.201_365_400_804_030_35,
    0.044_710_615_727_772_59,
];

/// Weights whose difference from [`B`] gives the third-order error estimate: B with these
/// subtracted at stages 0, 8 and 11.
const BHH: [f64; 3] =
    [0.244_094_488_188_976_38, 0.733_846_688_281_611_9, 0.022_058_823_529_411_766];

/// Third-order error weights: [`B`] less [`BHH`] at stages 0, 8 and 11.
const E3: [f64; STAGES] = {
    let mut e = B;
    e[0] -= BHH[0];
    e[8] -= BHH[1];
    e[11] -= BHH[2];
    e
};

/// Fifth-order error weights.
const E5: [f64; STAGES] = [
    0.013_120_044_994_194_88,
    0.,
    0.,
    0.,
    0.,
    -1.225_156_446_376_204_4,
    -0.495_758_949_657_250_2,
    1.664_377_182_454_986_5,
    -0.350_328_848_749_973_7,
    0.334_179_118_713_017_5,
    0.081_923_206_485_115_71,
    -0.022_355_307_863_886_295,
];

/// Result of a trial step.
pub(crate) struct Trial<const D: usize> {
    pub y1: SVector<f64, D>,
    pub f1: SVector<f64, D>,
    /// Fifth-order error estimate.
    pub err5: SVector<f64, D>,
    /// Third-order error estimate.
    pub err3: SVector<f64, D>,
    /// Stiffness indicator h·ρ from the last stage and the new point (as for Dopri5;
    /// this pair's stability boundary on the negative real axis is about 6).
    pub stiffness: f64,
    /// The stage rates, for the dense output of an accepted step.
    pub k: [SVector<f64, D>; STAGES],
}

/// Take a trial step of size h from (t, y) with f0 = f(t, y); uses 12 evaluations. Only
/// the first [`OdeSystem::live`] components are advanced; the rest are copied from y.
pub(crate) fn step<const D: usize, S: OdeSystem<D>>(
    sys: &S,
    t: f64,
    y: &SVector<f64, D>,
    f0: &SVector<f64, D>,
    h: f64,
) -> Trial<D> {
    let n = sys.live();
    let mut k = [SVector::<f64, D>::zeros(); STAGES];
    k[0] = *f0;
    // Each stage rewrites the coupled block only (no rate reads a quadrature).
    let mut y_last = *y;
    for i in 1..STAGES {
        combine_coupled(sys, &mut y_last, y, h, &A[i][..i], &k);
        sys.rhs_into(t + C[i] * h, &y_last, &mut k[i]);
    }
    let y1 = combine(y, h, &B, &k, n);
    let f1 = sys.rhs(t + h, &y1);
    let err5 = combine_coupled_from(sys, &SVector::zeros(), h, &E5, &k);
    let err3 = combine_coupled_from(sys, &SVector::zeros(), h, &E3, &k);
    let stiffness = stiffness_indicator(h, (&y_last, &k[STAGES - 1]), (&y1, &f1), sys.coupled());
    Trial { y1, f1, err5, err3, stiffness, k }
}

/// Hairer's combined error norm from the norms of the fifth- and third-order estimates:
/// ‖e5‖²/√(‖e5‖² + 0.01·‖e3‖²), which behaves like an eighth-order estimate as h → 0.
pub(crate) fn combined_norm(n5: f64, n3: f64) -> f64 {
    let den = n5 * n5 + 0.01 * n3 * n3;
    if den > 0.0 { n5 * n5 / den.sqrt() } else { 0.0 }
}

/// Nodes of the three extra stages of the dense output [–].
const C_DENSE: [f64; 3] = [0.1, 0.2, 7.0 / 9.0];

/// Stage coefficients of the dense output's extra stages over stages 0..=12 (stage 12 is
/// the rate at the new point) and the extra stages before them (13 and 14).
const A_DENSE: [[f64; 15]; 3] = [
    [
        0.056_167_502_283_047_95,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.253_500_210_216_624_8,
        -0.246_239_037_470_802_5,
        -0.124_191_423_263_816_36,
        0.153_291_798_278_765_7,
        0.008_201_052_295_634_69,
        0.007_567_897_660_545_7,
        -0.008_298,
        0.,
        0.,
    ],
    [
        0.031_834_648_163_502_14,
        0.,
        0.,
        0.,
        0.,
        0.028_300_909_672_366_776,
        0.053_541_988_307_438_57,
        -0.054_923_748_571_390_99,
        0.,
        0.,
        -0.000_108_347_328_697_249_32,
        0.000_382_571_090_835_658_4,
        -0.000_340_465_008_687_404_56,
        0.141_312_443_674_632_5,
        0.,
    ],
    [
        -0.428_896_301_583_791_9,
        0.,
        0.,
        0.,
        0.,
        -4.697_621_415_361_164,
        7.683_421_196_062_599,
        4.068_989_818_397_11,
        0.356_727_187_455_281_1,
        0.,
        0.,
        0.,
        -0.001_399_024_165_159_014_6,
        2.947_514_789_152_772_4,
        -9.150_958_472_179_87,
    ],
];

/// Weights of the dense output's four highest polynomial coefficients over the sixteen
/// stages (Hairer's d coefficients).
const D_DENSE: [[f64; 16]; 4] = [
    [
        -8.428_938_276_109_013,
        0.,
        0.,
        0.,
        0.,
        0.566_714_953_519_377_8,
        -3.068_949_945_949_891_7,
        2.384_667_656_512_07,
        2.117_034_582_445_028,
        -0.871_391_583_777_973,
        2.240_437_430_260_788_3,
        0.631_578_778_769_468_8,
        -0.088_990_336_451_333_31,
        18.148_505_520_854_727,
        -9.194_632_392_478_356,
        -4.436_036_387_594_894,
    ],
    [
        10.427_508_642_579_134,
        0.,
        0.,
        0.,
        0.,
        242.283_491_775_258_2,
        165.200_451_717_270_28,
        -374.546_754_722_690_2,
        -22.113_666_853_125_306,
        7.733_432_668_472_264,
        -30.674_084_731_089_398,
        -9.332_130_526_430_229,
        15.697_238_121_770_845,
        -31.139_403_219_565_178,
        -9.352_924_358_844_479,
        35.816_841_486_394_08,
    ],
    [
        19.985_053_242_002_433,
        0.,
        0.,
        0.,
        0.,
        -387.037_308_749_351_8,
        -189.178_138_195_167_57,
        527.808_159_205_423_6,
        -11.573_902_539_959_63,
        6.881_232_694_696_3,
        -1.000_605_096_691_083_8,
        0.777_713_779_805_344_3,
        -2.778_205_752_353_508,
        -60.196_695_231_264_12,
        84.320_405_506_677_16,
        11.992_291_136_182_79,
    ],
    [
        -25.693_933_462_703_75,
        0.,
        0.,
        0.,
        0.,
        -154.189_748_690_236_43,
        -231.529_379_176_045_5,
        357.639_117_910_614_1,
        93.405_324_183_624_31,
        -37.458_323_136_451_63,
        104.099_649_508_962_3,
        29.840_293_426_660_503,
        -43.533_456_590_011_14,
        96.324_553_959_188_28,
        -39.177_261_675_615_44,
        -149.726_836_257_985_63,
    ],
];

/// The seventh-order continuous extension of an accepted step: a polynomial in
/// θ = (t − t0)/h that matches the step's end points and their rates.
#[derive(Clone, Debug)]
pub struct Dense<const D: usize> {
    /// y0, then the seven coefficients r1..r7 of the nested form
    /// y0 + θ(r1 + (1−θ)(r2 + θ(r3 + (1−θ)(r4 + θ(r5 + (1−θ)(r6 + θ·r7)))))).
    r: [SVector<f64, D>; 8],
}

impl<const D: usize> Dense<D> {
    /// Build the extension of the step of size `h` from (t, y, k[0]) to (y1, f1), with
    /// `k` the step's twelve stage rates; three more evaluations.
    pub(crate) fn new<S: OdeSystem<D>>(
        sys: &S,
        t: f64,
        h: f64,
        y: &SVector<f64, D>,
        k: &[SVector<f64, D>; STAGES],
        y1: &SVector<f64, D>,
        f1: &SVector<f64, D>,
    ) -> Self {
        let n = sys.live();
        let mut all = [SVector::<f64, D>::zeros(); 16];
        all[..STAGES].copy_from_slice(k);
        all[STAGES] = *f1;
        for (e, (a, c)) in A_DENSE.iter().zip(C_DENSE).enumerate() {
            let i = STAGES + 1 + e;
            let yi = combine_coupled_from(sys, y, h, &a[..i], &all);
            sys.rhs_into(t + c * h, &yi, &mut all[i]);
        }
        let dy = y1 - y;
        let mut r = [SVector::<f64, D>::zeros(); 8];
        r[0] = *y;
        r[1] = dy;
        r[2] = h * k[0] - dy;
        r[3] = 2.0 * dy - h * (k[0] + f1);
        for (row, d) in D_DENSE.iter().enumerate() {
            r[4 + row] = combine(&SVector::zeros(), h, d, &all, n);
        }
        Dense { r }
    }

    /// Component i at θ ∈ [0, 1].
    #[inline]
    pub fn component(&self, theta: f64, i: usize) -> f64 {
        let s1 = 1.0 - theta;
        let r = &self.r;
        let mut v = r[7][i];
        for (k, rk) in r[1..7].iter().enumerate().rev() {
            // Factors alternate θ, (1−θ), … from the innermost coefficient outwards.
            v = rk[i] + if k % 2 == 1 { theta } else { s1 } * v;
        }
        r[0][i] + theta * v
    }

    /// The whole state at θ ∈ [0, 1].
    pub fn state(&self, theta: f64) -> SVector<f64, D> {
        SVector::from_fn(|i, _| self.component(theta, i))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows sum to c; the weights meet the quadrature conditions ∫ s^q = 1/(q+1) up to
    /// order 8 and c_i^q conditions of the bushy trees; the error weights sum to zero.
    #[test]
    fn coefficients_meet_the_quadrature_and_row_sum_conditions() {
        for i in 0..STAGES {
            let s: f64 = A[i].iter().sum();
            assert!((s - C[i]).abs() < 1e-14, "row {i}: {s} vs {}", C[i]);
        }
        for q in 0..8 {
            let s: f64 = (0..STAGES).map(|j| B[j] * C[j].powi(q)).sum();
            let want = 1.0 / f64::from(q + 1);
            assert!((s - want).abs() < 1e-13, "Σ b c^{q} = {s}, want {want}");
        }
        // Σ b_i c_i Σ_j a_ij c_j = 1/8 (a tree of order 4) and Σ b_i a_ij c_j = 1/6.
        let ac: Vec<f64> = (0..STAGES).map(|i| (0..i).map(|j| A[i][j] * C[j]).sum()).collect();
        let s6: f64 = (0..STAGES).map(|i| B[i] * ac[i]).sum();
        let s8: f64 = (0..STAGES).map(|i| B[i] * C[i] * ac[i]).sum();
        assert!((s6 - 1.0 / 6.0).abs() < 1e-13, "{s6}");
        assert!((s8 - 1.0 / 8.0).abs() < 1e-13, "{s8}");
        assert!(E5.iter().sum::<f64>().abs() < 1e-14);
        for (a, c) in A_DENSE.iter().zip(C_DENSE) {
            let s: f64 = a.iter().sum();
            assert!((s - c).abs() < 1e-13, "dense row sums to {s}, node {c}");
        }
        assert!((BHH.iter().sum::<f64>() - 1.0).abs() < 1e-14);
    }
}
