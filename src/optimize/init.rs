//! Initial populations: uniform in the cube, Latin hypercube, or a cloud
//! around a known point (to refine an earlier fit).
//!
//! Each sampler draws its numbers in a fixed order (individual by
//! individual, coordinate by coordinate, except the Latin hypercube which
//! goes coordinate by coordinate) so a seed fixes the population exactly.

use rand::Rng;

use super::sampling;

/// `np` points drawn independently and uniformly from `[0,1]^dim`.
pub fn uniform<R: Rng>(np: usize, dim: usize, rng: &mut R) -> Vec<Vec<f64>> {
    (0..np)
        .map(|_| (0..dim).map(|_| sampling::unit(rng)).collect())
        .collect()
}

/// `np` points such that, along every axis, each of the `np` equal slices
/// of `[0,1]` holds exactly one point. Why: it spreads a small population
/// over every parameter's whole range, which plain uniform draws often
/// fail to do.
pub fn latin_hypercube<R: Rng>(np: usize, dim: usize, rng: &mut R) -> Vec<Vec<f64>> {
    let mut population = vec![vec![0.0; dim]; np];
    let mut slices: Vec<usize> = (0..np).collect();
    for j in 0..dim {
        // Fisher–Yates shuffle, written out so the draw count is ours.
        for k in (1..np).rev() {
            slices.swap(k, sampling::index(rng, k + 1));
        }
        for (individual, &slice) in population.iter_mut().zip(&slices) {
            individual[j] = (slice as f64 + sampling::unit(rng)) / np as f64;
        }
    }
    population
}

/// `np` points around `center`: individual 0 is the center itself and the
/// others are uniform in the box `center ± radius` cut to the cube.
///
/// Why cut the box instead of clamping the points: clamping would stack
/// many individuals exactly on a face, where their difference vectors
/// vanish. The center is first made usable: missing coordinates and
/// non-finite ones become 0.5, extra ones are ignored, all are clamped into
/// `[0,1]`. A negative or NaN radius counts as 0, which puts every
/// individual on the center (DE then cannot move: a caller wants a
/// positive radius).
pub fn around<R: Rng>(
    np: usize,
    dim: usize,
    center: &[f64],
    radius: f64,
    rng: &mut R,
) -> Vec<Vec<f64>> {
    around_each(np, dim, center, &vec![radius; dim], rng)
}

/// [`around`] with a spread per coordinate (a missing one counts as 0):
/// a refit that adds parameters spreads them over their own range while
/// the fitted ones stay close.
pub fn around_each<R: Rng>(
    np: usize,
    dim: usize,
    center: &[f64],
    radii: &[f64],
    rng: &mut R,
) -> Vec<Vec<f64>> {
    let center: Vec<f64> = (0..dim)
        .map(|j| match center.get(j) {
            Some(c) if c.is_finite() => c.clamp(0.0, 1.0),
            _ => 0.5,
        })
        .collect();
    let radii: Vec<f64> = (0..dim)
        .map(|j| match radii.get(j) {
            Some(&r) if r > 0.0 => r.min(1.0),
            _ => 0.0,
        })
        .collect();
    let mut population = Vec::with_capacity(np);
    population.push(center.clone());
    for _ in 1..np {
        let individual = center
            .iter()
            .zip(&radii)
            .map(|(&c, &radius)| {
                let low = (c - radius).max(0.0);
                let high = (c + radius).min(1.0);
                (low + sampling::unit(rng) * (high - low)).clamp(low, high)
            })
            .collect();
        population.push(individual);
    }
    population
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn latin_hypercube_fills_every_slice_once() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let np = 17;
        let population = latin_hypercube(np, 4, &mut rng);
        for j in 0..4 {
            let mut slices: Vec<usize> = population
                .iter()
                .map(|x| (x[j] * np as f64).floor() as usize)
                .collect();
            slices.sort_unstable();
            assert_eq!(slices, (0..np).collect::<Vec<_>>());
        }
    }

    #[test]
    fn around_repairs_a_bad_center() {
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        let population = around(5, 3, &[f64::NAN, 2.0], -1.0, &mut rng);
        for individual in &population {
            assert_eq!(individual, &vec![0.5, 1.0, 0.5]);
        }
    }
}
