//! DE/rand/1/bin trial generation (Storn & Price 1997).
//!
//! `v = x_r1 + F (x_r2 - x_r3)` with `r1, r2, r3` distinct and different
//! from the target `i`, then binomial crossover with the target. jDE uses
//! the same operator with its per-individual F and CR.

use rand::Rng;

use super::{operators, sampling};

/// The trial vector for target `i` of `population`.
pub fn trial<R: Rng>(population: &[Vec<f64>], i: usize, f: f64, cr: f64, rng: &mut R) -> Vec<f64> {
    let np = population.len();
    let r1 = sampling::index_excluding(rng, np, &[i]);
    let r2 = sampling::index_excluding(rng, np, &[i, r1]);
    let r3 = sampling::index_excluding(rng, np, &[i, r1, r2]);
    let mutant: Vec<f64> = population[r1]
        .iter()
        .zip(&population[r2])
        .zip(&population[r3])
        .map(|((a, b), c)| a + f * (b - c))
        .collect();
    operators::binomial_crossover(&population[i], &mutant, cr, rng)
}
