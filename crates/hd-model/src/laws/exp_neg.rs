//! e^(−x) for the friction laws' Stribeck factor, which every stage of a solve evaluates.
//!
//! libm's `exp` cost about 60 instructions a call in the solver (callgrind: the call, the
//! wrapper that sets errno, the body), 8 % of a seed-case solve. Here x ≥ 0 is bounded
//! (the caller takes e^(−x) as 0 above [`LIMIT`]), so no overflow, NaN or subnormal path is
//! needed. The argument is split as −x = (32·k + j)·ln2/32 + r with |r| ≤ ln2/64, so that
//! e^(−x) = 2^k · 2^(j/32) · e^r: 2^(j/32) comes from a table of correctly rounded values,
//! 2^k is written into the exponent bits, and e^r is its Taylor series to r⁶ (the first
//! term left out is below 4e-18 relative). The result is within one unit in the last place
//! of libm's (measured by the test; the construction bounds it by about 1.5).

/// The largest x [–] taken: e^(−x) stays a normal number (above 1e-304) below it.
pub const LIMIT: f64 = 700.0;

/// 2^(j/32), j = 0…31, correctly rounded.
const TWO_POW: [f64; 32] = [
    1.0,
    1.0218971486541166,
    1.0442737824274138,
    1.0671404006768237,
    1.0905077326652577,
    1.1143867425958924,
    1.1387886347566916,
    1.1637248587775775,
    1.189207115002721,
    1.215247359980469,
    1.241857812073484,
    1.2690509571917332,
    1.2968395546510096,
    1.3252366431597413,
    1.3542555469368927,
    1.383909881963832,
    1.4142135623730951,
    1.4451808069770467,
    1.4768261459394993,
    1.5091644275934228,
    1.5422108254079407,
    1.5759808451078865,
    1.6104903319492543,
    1.645755478153965,
    1.681792830507429,
    1.718619298122478,
    1.7562521603732995,
    1.7947090750031072,
    1.8340080864093424,
    1.8741676341103,
    1.9152065613971474,
    1.9571441241754002,
];

/// 32/ln2, ln2/32 split so that n·LN2_32_HI is exact for |n| < 2^21, and the rest.
const INV_LN2_32: f64 = 46.16624130844683;
const LN2_32_HI: f64 = 0.02166084938653512;
const LN2_32_LO: f64 = 5.9631716539705866e-12;
/// Adding and subtracting 1.5·2^52 rounds a value below 2^51 to the nearest integer.
const ROUNDER: f64 = 6_755_399_441_055_744.0;

/// e^(−x) [–] for 0 ≤ x < [`LIMIT`] (x outside that range is the caller's error).
#[inline(always)]
pub fn exp_neg(x: f64) -> f64 {
    debug_assert!((0.0..LIMIT).contains(&x), "exp_neg({x})");
    let y = -x;
    // n = round(y·32/ln2), read from the mantissa of the rounded sum.
    let shifted = y * INV_LN2_32 + ROUNDER;
    let n = shifted.to_bits() as i64 - ROUNDER.to_bits() as i64;
    let nf = shifted - ROUNDER;
    let r = (y - nf * LN2_32_HI) - nf * LN2_32_LO;
    let r2 = r * r;
    let tail = 0.5 + r * (1.0 / 6.0) + r2 * (1.0 / 24.0 + r * (1.0 / 120.0) + r2 * (1.0 / 720.0));
    // e^r − 1, kept apart from the 1 so that the table value is rounded into once.
    let q = r + r2 * tail;
    let (k, j) = (n >> 5, (n & 31) as usize);
    let t = TWO_POW[j];
    let scale = f64::from_bits(((k + 1023) as u64) << 52);
    (t + t * q) * scale
}

#[cfg(test)]
mod tests;
