//! Gaussian measurement noise, reproducible from a seed.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Noise settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Noise {
    /// Standard deviation relative to the RMS of the clean torque [–], e.g. 0.01 for 1 %.
    pub relative: f64,
    /// Seed of the random generator (ChaCha8).
    pub seed: u64,
}

impl Default for Noise {
    fn default() -> Self {
        Self { relative: 0.01, seed: 1 }
    }
}

/// Add zero-mean Gaussian noise of standard deviation `noise.relative × RMS(signal)` to
/// `signal` (Box–Muller on a seeded ChaCha8 stream); returns that standard deviation.
pub fn add_noise(signal: &mut [f64], noise: &Noise) -> f64 {
    let n = signal.len().max(1) as f64;
    let rms = (signal.iter().map(|v| v * v).sum::<f64>() / n).sqrt();
    let sd = noise.relative * rms;
    if sd == 0.0 {
        return 0.0;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(noise.seed);
    let mut spare: Option<f64> = None;
    for v in signal.iter_mut() {
        let g = match spare.take() {
            Some(g) => g,
            None => {
                let u1 = 1.0 - rng.random::<f64>(); // (0, 1]
                let u2: f64 = rng.random();
                let r = (-2.0 * u1.ln()).sqrt();
                let phi = std::f64::consts::TAU * u2;
                spare = Some(r * phi.sin());
                r * phi.cos()
            }
        };
        *v += sd * g;
    }
    sd
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_has_the_asked_size_and_is_reproducible() {
        let clean = vec![2.0; 40_000];
        let mut a = clean.clone();
        let sd = add_noise(&mut a, &Noise { relative: 0.05, seed: 7 });
        assert_eq!(sd, 0.1);
        let mean = a.iter().sum::<f64>() / a.len() as f64;
        let var = a.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / a.len() as f64;
        assert!((mean - 2.0).abs() < 3e-3, "{mean}");
        assert!((var.sqrt() / 0.1 - 1.0).abs() < 0.02, "{}", var.sqrt());
        let mut b = clean;
        add_noise(&mut b, &Noise { relative: 0.05, seed: 7 });
        assert_eq!(a, b);
    }
}
