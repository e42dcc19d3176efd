//! Periodic-run metrics: the least-squares fundamental fit behind `thz_ripple`.

use std::f64::consts::TAU;

/// Least-squares fit of `m + a·sin(2πft) + b·cos(2πft)` to samples `(t, x)`; returns
/// `(m, a, b, rms_residual)`. NaN if there are fewer than 4 samples or the fit is singular.
pub fn fit_fundamental(t: &[f64], x: &[f64], freq: f64) -> (f64, f64, f64, f64) {
    let n = t.len();
    let nan = (f64::NAN, f64::NAN, f64::NAN, f64::NAN);
    if n < 4 || x.len() != n {
        return nan;
    }
    // Normal equations in a 3×3 system, centred on the mean of x for conditioning.
    let xm = x.iter().sum::<f64>() / n as f64;
    let mut g = [[0.0; 3]; 3];
    let mut r = [0.0; 3];
    for (&tk, &xk) in t.iter().zip(x) {
        let (s, c) = (TAU * freq * tk).sin_cos();
        let phi = [1.0, s, c];
        for i in 0..3 {
            for j in 0..3 {
                g[i][j] += phi[i] * phi[j];
            }
            r[i] += phi[i] * (xk - xm);
        }
    }
    let Some(sol) = solve3(g, r) else {
        return nan;
    };
    let (m, a, b) = (sol[0] + xm, sol[1], sol[2]);
    let mut ss = 0.0;
    for (&tk, &xk) in t.iter().zip(x) {
        let (s, c) = (TAU * freq * tk).sin_cos();
        let e = xk - m - a * s - b * c;
        ss += e * e;
    }
    (m, a, b, (ss / n as f64).sqrt())
}

/// Solve a 3×3 system by Gaussian elimination with partial pivoting.
fn solve3(mut g: [[f64; 3]; 3], mut r: [f64; 3]) -> Option<[f64; 3]> {
    for k in 0..3 {
        let p = (k..3).max_by(|&i, &j| g[i][k].abs().total_cmp(&g[j][k].abs()))?;
        if g[p][k].abs() < 1e-300 {
            return None;
        }
        g.swap(k, p);
        r.swap(k, p);
        let pivot_row = g[k];
        for i in k + 1..3 {
            let l = g[i][k] / pivot_row[k];
            for (gij, gkj) in g[i].iter_mut().zip(pivot_row).skip(k) {
                *gij -= l * gkj;
            }
            r[i] -= l * r[k];
        }
    }
    let mut x = [0.0; 3];
    for i in (0..3).rev() {
        let s: f64 = (i + 1..3).map(|j| g[i][j] * x[j]).sum();
        x[i] = (r[i] - s) / g[i][i];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_mean_fundamental_and_a_known_harmonic_ripple() {
        let f = 50.0;
        let t: Vec<f64> = (0..2560).map(|k| k as f64 * 5.0 / f / 2560.0).collect();
        // Ripple: third harmonic of amplitude 0.1 → RMS 0.1/√2.
        let x: Vec<f64> = t
            .iter()
            .map(|&t| {
                2.0 + 3.0 * (TAU * f * t).sin() - 1.5 * (TAU * f * t).cos()
                    + 0.1 * (3.0 * TAU * f * t).sin()
            })
            .collect();
        let (m, a, b, rms) = fit_fundamental(&t, &x, f);
        assert!((m - 2.0).abs() < 1e-12 && (a - 3.0).abs() < 1e-12 && (b + 1.5).abs() < 1e-12);
        assert!((rms - 0.1 / 2f64.sqrt()).abs() < 1e-12, "{rms}");
    }
}
