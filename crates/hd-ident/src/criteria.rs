//! Information criteria of a least-squares fit, one formula for every fit that ranks models
//! (the stiffness laws, the drive's friction laws, the nested friction laws, the fleet's
//! covariate models): with n samples, residual sum of squares RSS and p parameters,
//! `AIC = n·ln(RSS/n) + 2p` and `BIC = n·ln(RSS/n) + p·ln n` (lower is better). RSS/n is
//! floored at the smallest positive number, so an exact fit ranks first instead of at −∞.

/// (AIC, BIC) of a fit with residual sum of squares `rss` over `n` samples and `p`
/// parameters [–].
pub fn criteria(rss: f64, n: usize, p: usize) -> (f64, f64) {
    let nf = n as f64;
    let ll = nf * (rss / nf).max(f64::MIN_POSITIVE).ln();
    (ll + 2.0 * p as f64, ll + p as f64 * nf.ln())
}

/// BIC alone ([`criteria`]) [–].
pub fn bic(rss: f64, n: usize, p: usize) -> f64 {
    criteria(rss, n, p).1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms: n = 100, RSS = 1 (RSS/n = 0.01), p = 3.
    #[test]
    fn criteria_match_their_closed_forms() {
        let (aic, bic) = criteria(1.0, 100, 3);
        let ll = 100.0 * 0.01f64.ln();
        assert!((aic - (ll + 6.0)).abs() < 1e-12);
        assert!((bic - (ll + 3.0 * 100f64.ln())).abs() < 1e-12);
        assert!(criteria(0.0, 10, 1).1.is_finite(), "an exact fit ranks, not -inf");
    }
}
