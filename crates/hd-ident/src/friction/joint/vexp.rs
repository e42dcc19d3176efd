//! e^x and e^x − 1 for x ≤ 0 without branches or library calls, so that a loop over a
//! chunk of samples compiles to vector instructions (the library's `exp` and `expm1` are
//! calls, one sample at a time). Both agree with the library to a few units in the last
//! place (`tests`).

/// ln 2 split so that k·LN2_HI is exact for |k| < 2¹¹ [–].
const LN2_HI: f64 = f64::from_bits(0x3FE6_2E42_FEE0_0000);
/// ln 2 − LN2_HI [–].
const LN2_LO: f64 = f64::from_bits(0x3DEA_39EF_3579_3C76);
/// Below this argument e^x is taken as 0 (it is below 2⁻¹⁰²² there) [–].
const FLUSH: f64 = -708.0;

/// 1/j! for j = 0 … 16.
const INV_FACT: [f64; 17] = {
    let mut c = [1.0; 17];
    let mut j = 1;
    while j < 17 {
        c[j] = c[j - 1] / j as f64;
        j += 1;
    }
    c
};

/// Σ_{j=0..=13} r^j/j! by Horner's rule: e^r to under 1e-17 relative for |r| ≤ ln2/2.
#[inline(always)]
fn taylor_exp(r: f64) -> f64 {
    let mut p = INV_FACT[13];
    for j in (0..13).rev() {
        p = p.mul_add(r, INV_FACT[j]);
    }
    p
}

/// e^x [–] for x ≤ 0 (0 below −708; NaN gives NaN).
#[inline(always)]
pub fn exp_neg(x: f64) -> f64 {
    let xc = if x > FLUSH { x } else { FLUSH };
    let k = (xc * std::f64::consts::LOG2_E).round();
    let r = k.mul_add(-LN2_LO, k.mul_add(-LN2_HI, xc));
    let scale = f64::from_bits(((k as i64 + 1023) as u64) << 52);
    let e = taylor_exp(r) * scale;
    if x < FLUSH {
        0.0
    } else if x.is_nan() {
        x
    } else {
        e
    }
}

/// e^x − 1 [–] for −0.5 ≤ x ≤ 0, without the cancellation of `exp_neg(x) − 1`:
/// Σ_{j=1..=16} x^j/j! by Horner's rule (the first omitted term is under 1e-18 of the
/// result).
#[inline(always)]
pub fn expm1_small(x: f64) -> f64 {
    let mut p = INV_FACT[16];
    for j in (1..16).rev() {
        p = p.mul_add(x, INV_FACT[j]);
    }
    p * x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Units in the last place between a and b.
    fn ulps(a: f64, b: f64) -> f64 {
        if a == b {
            return 0.0;
        }
        let unit = f64::EPSILON * a.abs().max(b.abs());
        (a - b).abs() / unit
    }

    #[test]
    fn agree_with_the_library() {
        let mut worst = (0.0f64, 0.0f64);
        for i in 0..200_000 {
            let x = -(i as f64) * 3.6e-3 - 1e-9 * (i % 7) as f64; // 0 … −720
            let e = exp_neg(x);
            let want = x.exp();
            if x >= FLUSH {
                worst.0 = worst.0.max(ulps(e, want));
            } else {
                assert_eq!(e, 0.0, "{x}");
            }
            let y = -(i as f64) * 2.5e-6; // 0 … −0.5
            worst.1 = worst.1.max(ulps(expm1_small(y), y.exp_m1()));
        }
        println!("worst: exp {:.2} ulp, expm1 {:.2} ulp", worst.0, worst.1);
        assert!(worst.0 <= 4.0 && worst.1 <= 4.0, "{worst:?}");
        assert_eq!(exp_neg(0.0), 1.0);
        assert_eq!(exp_neg(-800.0), 0.0);
        assert_eq!(expm1_small(0.0), 0.0);
        assert!(exp_neg(f64::NAN).is_nan());
    }
}
