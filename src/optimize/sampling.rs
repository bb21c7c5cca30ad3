//! Random variates the strategies need beyond plain uniforms: Gaussian and
//! Cauchy draws for SHADE's parameter sampling, and picks of distinct
//! population indices for the difference vectors.
//!
//! Written here (instead of pulling in `rand_distr`) so that exactly how
//! many numbers each draw consumes from the one shared generator is fixed
//! by this crate: a dependency upgrade must never change a seeded run.

use std::f64::consts::PI;

use rand::Rng;

/// A uniform draw in `[0, 1)`.
pub fn unit<R: Rng>(rng: &mut R) -> f64 {
    rng.gen::<f64>()
}

/// A uniform index in `0..n`. `n` must be positive; every caller passes a
/// population or archive size that construction guarantees is non-zero.
pub fn index<R: Rng>(rng: &mut R, n: usize) -> usize {
    rng.gen_range(0..n)
}

/// Normal(`mean`, `sd`) by Box–Muller. Always consumes exactly two
/// uniforms; the second variate of the pair is discarded so that no hidden
/// cache has to live in the serialised state.
pub fn normal<R: Rng>(rng: &mut R, mean: f64, sd: f64) -> f64 {
    // 1 - u lies in (0, 1], so the logarithm is finite.
    let u1 = 1.0 - unit(rng);
    let u2 = unit(rng);
    mean + sd * (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
}

/// Cauchy(`location`, `scale`) by inversion. Consumes exactly one uniform.
pub fn cauchy<R: Rng>(rng: &mut R, location: f64, scale: f64) -> f64 {
    location + scale * (PI * (unit(rng) - 0.5)).tan()
}

/// An index in `0..n` that differs from every entry of `exclude`, by
/// rejection. The caller must ensure `n > exclude.len()` distinct values
/// remain; [`crate::optimize::DeConfig`] enforces a population of at least
/// four so every strategy's picks can succeed.
pub fn index_excluding<R: Rng>(rng: &mut R, n: usize, exclude: &[usize]) -> usize {
    loop {
        let candidate = index(rng, n);
        if !exclude.contains(&candidate) {
            return candidate;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn normal_has_the_requested_mean_and_spread() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let n = 20_000;
        let draws: Vec<f64> = (0..n).map(|_| normal(&mut rng, 0.5, 0.1)).collect();
        let mean = draws.iter().sum::<f64>() / n as f64;
        let var = draws.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        assert!((mean - 0.5).abs() < 0.005, "mean {mean}");
        assert!((var.sqrt() - 0.1).abs() < 0.005, "sd {}", var.sqrt());
    }

    #[test]
    fn cauchy_median_and_quartiles_match() {
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        let mut draws: Vec<f64> = (0..20_001).map(|_| cauchy(&mut rng, 0.5, 0.1)).collect();
        draws.sort_by(f64::total_cmp);
        // Cauchy quartiles sit at location ± scale.
        let q = |p: f64| draws[(p * (draws.len() - 1) as f64) as usize];
        assert!((q(0.5) - 0.5).abs() < 0.01, "median {}", q(0.5));
        assert!((q(0.25) - 0.4).abs() < 0.01, "q1 {}", q(0.25));
        assert!((q(0.75) - 0.6).abs() < 0.01, "q3 {}", q(0.75));
    }

    #[test]
    fn index_excluding_never_returns_an_excluded_index() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let mut seen = [false; 5];
        for _ in 0..2_000 {
            let k = index_excluding(&mut rng, 5, &[1, 3]);
            assert!(k != 1 && k != 3);
            seen[k] = true;
        }
        assert_eq!(seen, [true, false, true, false, true]);
    }
}
