//! The variation operators every strategy shares: binomial crossover and
//! the bound repair applied to the coordinates a trial takes from its
//! mutant.
//!
//! Binomial crossover is the "bin" of DE/x/y/bin (Storn & Price 1997);
//! the repair is the midpoint rule SHADE uses (Tanabe & Fukunaga 2013),
//! applied to all strategies so their results are comparable.

use rand::Rng;

use super::sampling;

/// Brings a mutant coordinate back into `[0, 1]`.
///
/// A coordinate past a bound is put halfway between the target's own
/// coordinate and that bound. Why not clip: clipping piles individuals
/// onto the faces of the cube and collapses diversity there, while the
/// midpoint still moves towards the bound the mutation pointed at. It is
/// deterministic, so it consumes no random numbers.
pub fn repair(value: f64, parent: f64) -> f64 {
    if value < 0.0 {
        parent / 2.0
    } else if value > 1.0 {
        (parent + 1.0) / 2.0
    } else if value.is_nan() {
        // Cannot come from finite inputs; kept so a bad F can never put
        // NaN into the population.
        parent
    } else {
        value
    }
}

/// Binomial crossover of `target` with `mutant` at rate `cr`, with bound
/// repair of the mutant coordinates taken.
///
/// One coordinate, `jrand`, always comes from the mutant so that a trial
/// can never be a copy of its target. A uniform is drawn for every
/// coordinate, including `jrand`, so each trial consumes the same count of
/// random numbers whatever `cr` is.
pub fn binomial_crossover<R: Rng>(
    target: &[f64],
    mutant: &[f64],
    cr: f64,
    rng: &mut R,
) -> Vec<f64> {
    if target.is_empty() {
        return Vec::new();
    }
    let jrand = sampling::index(rng, target.len());
    target
        .iter()
        .zip(mutant)
        .enumerate()
        .map(|(j, (&x, &v))| {
            let from_mutant = sampling::unit(rng) < cr || j == jrand;
            if from_mutant {
                repair(v, x)
            } else {
                x
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn repair_goes_halfway_to_the_violated_bound() {
        assert_eq!(repair(-0.3, 0.4), 0.2);
        assert_eq!(repair(1.7, 0.4), 0.7);
        assert_eq!(repair(0.25, 0.4), 0.25);
        assert_eq!(repair(1.0, 0.4), 1.0);
        assert_eq!(repair(f64::NAN, 0.4), 0.4);
    }

    #[test]
    fn crossover_with_zero_rate_takes_exactly_one_mutant_coordinate() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let target = [0.1; 8];
        let mutant = [0.9; 8];
        for _ in 0..100 {
            let trial = binomial_crossover(&target, &mutant, 0.0, &mut rng);
            assert_eq!(trial.iter().filter(|&&x| x == 0.9).count(), 1);
        }
    }

    #[test]
    fn crossover_with_full_rate_takes_the_whole_mutant() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let trial = binomial_crossover(&[0.1; 5], &[0.9; 5], 1.0, &mut rng);
        assert_eq!(trial, vec![0.9; 5]);
    }
}
