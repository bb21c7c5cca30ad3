//! SHADE: success-history based parameter adaptation
//! (Tanabe & Fukunaga 2013).
//!
//! Each trial draws its CR from Normal(`M_CR[r]`, 0.1) and its F from
//! Cauchy(`M_F[r]`, 0.1), where `r` picks a random slot of a history memory.
//! Trials use current-to-pbest/1/bin:
//! `v = x_i + F (x_pbest - x_i) + F (x_r1 - x_r2)`, where `x_pbest` is one
//! of the best `p·NP` individuals (p drawn per trial in [2/NP, 0.2]) and
//! `x_r2` may come from an archive of parents that lost to their trials.
//! After each generation, one memory slot becomes the mean of the
//! successful settings, weighted by how much fitness each one gained
//! (Lehmer mean for F, arithmetic mean for CR).
//!
//! Memory size H = NP, as in the paper's experiments (H = NP = 100); the
//! archive holds at most NP vectors.

use rand::Rng;
use serde::{Deserialize, Serialize};

use super::{exact, operators, sampling};

const MEMORY_INITIAL: f64 = 0.5;
const CR_SPREAD: f64 = 0.1;
const F_SPREAD: f64 = 0.1;
const P_MAX: f64 = 0.2;
/// Non-positive Cauchy draws of F are redrawn, as in the paper. The cap
/// only rules out an endless loop; with a positive memory entry each draw
/// is positive with probability at least 1/2, so it is never reached in
/// practice.
const F_REDRAWS: usize = 64;

/// A setting that produced a strictly better trial, with the gain.
#[derive(Clone, Copy, Debug)]
pub struct Success {
    pub f: f64,
    pub cr: f64,
    pub gain: f64,
}

/// The success-history memory and the archive.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShadeState {
    #[serde(with = "exact::vector")]
    memory_f: Vec<f64>,
    #[serde(with = "exact::vector")]
    memory_cr: Vec<f64>,
    next_slot: usize,
    #[serde(with = "exact::matrix")]
    archive: Vec<Vec<f64>>,
}

impl ShadeState {
    pub fn new(np: usize) -> Self {
        ShadeState {
            memory_f: vec![MEMORY_INITIAL; np],
            memory_cr: vec![MEMORY_INITIAL; np],
            next_slot: 0,
            archive: Vec::new(),
        }
    }

    /// Population indices sorted from best to worst (failed ones, stored
    /// as +inf, last; ties keep index order so the ranking is
    /// deterministic).
    pub fn ranking(fitness: &[f64]) -> Vec<usize> {
        let mut order: Vec<usize> = (0..fitness.len()).collect();
        order.sort_by(|&a, &b| fitness[a].total_cmp(&fitness[b]));
        order
    }

    /// Draws the F and CR for one trial.
    pub fn sample_parameters<R: Rng>(&self, rng: &mut R) -> (f64, f64) {
        let slot = sampling::index(rng, self.memory_f.len());
        let cr = sampling::normal(rng, self.memory_cr[slot], CR_SPREAD).clamp(0.0, 1.0);
        let mut f = self.memory_f[slot].clamp(F_SPREAD, 1.0);
        for _ in 0..F_REDRAWS {
            let draw = sampling::cauchy(rng, self.memory_f[slot], F_SPREAD);
            if draw > 0.0 {
                f = draw.min(1.0);
                break;
            }
        }
        (f, cr)
    }

    /// The current-to-pbest/1/bin trial for target `i`, given the
    /// population's `ranking` from [`ShadeState::ranking`].
    pub fn trial<R: Rng>(
        &self,
        population: &[Vec<f64>],
        ranking: &[usize],
        i: usize,
        (f, cr): (f64, f64),
        rng: &mut R,
    ) -> Vec<f64> {
        let np = population.len();
        let p_min = 2.0 / np as f64;
        let p = p_min + sampling::unit(rng) * (P_MAX.max(p_min) - p_min);
        let top = ((p * np as f64).round() as usize).clamp(1, np);
        let pbest = ranking[sampling::index(rng, top)];
        let r1 = sampling::index_excluding(rng, np, &[i]);
        // r2 indexes population then archive; archive slots (>= np) can
        // never equal i or r1.
        let r2 = sampling::index_excluding(rng, np + self.archive.len(), &[i, r1]);
        let x_r2 = match r2.checked_sub(np) {
            Some(a) => &self.archive[a],
            None => &population[r2],
        };
        let x = &population[i];
        let mutant: Vec<f64> = (0..x.len())
            .map(|j| x[j] + f * (population[pbest][j] - x[j]) + f * (population[r1][j] - x_r2[j]))
            .collect();
        operators::binomial_crossover(x, &mutant, cr, rng)
    }

    /// Keeps a parent that a strictly better trial replaced.
    pub fn archive_parent(&mut self, parent: Vec<f64>) {
        self.archive.push(parent);
    }

    /// End of a generation: trims the archive back to `np` by random
    /// deletion and writes the weighted means of the successes into the
    /// next memory slot.
    pub fn end_generation<R: Rng>(&mut self, successes: &[Success], np: usize, rng: &mut R) {
        while self.archive.len() > np {
            let victim = sampling::index(rng, self.archive.len());
            self.archive.swap_remove(victim);
        }
        // A gain over a failed (+inf) parent has no size, so it cannot
        // weight the means; such successes still entered the archive.
        let measured: Vec<&Success> = successes
            .iter()
            .filter(|s| s.gain.is_finite() && s.gain > 0.0)
            .collect();
        let Some(largest) = measured.iter().map(|s| s.gain).reduce(f64::max) else {
            return;
        };
        // Gains are divided by the largest first so their sum cannot
        // overflow, whatever the objective's scale.
        let total: f64 = measured.iter().map(|s| s.gain / largest).sum();
        let weight = |s: &Success| s.gain / largest / total;
        let cr_mean: f64 = measured.iter().map(|s| weight(s) * s.cr).sum();
        let f_square: f64 = measured.iter().map(|s| weight(s) * s.f * s.f).sum();
        let f_sum: f64 = measured.iter().map(|s| weight(s) * s.f).sum();
        let slot = self.next_slot;
        self.memory_cr[slot] = cr_mean;
        // Lehmer mean: leans towards larger F, which keeps the search from
        // converging prematurely (Tanabe & Fukunaga 2013, sec. III).
        self.memory_f[slot] = f_square / f_sum;
        self.next_slot = (slot + 1) % self.memory_f.len();
    }

    /// The memory's F entries (for inspection and tests).
    pub fn memory_f(&self) -> &[f64] {
        &self.memory_f
    }

    /// The archived parents.
    pub fn archive(&self) -> &[Vec<f64>] {
        &self.archive
    }

    /// Checks a loaded state against the population shape.
    pub fn check(&self, np: usize, dim: usize) -> Result<(), String> {
        let h = self.memory_f.len();
        if h == 0 || self.memory_cr.len() != h || self.next_slot >= h {
            return Err(format!(
                "SHADE memory has {h} F and {} CR slots, next slot {}",
                self.memory_cr.len(),
                self.next_slot
            ));
        }
        let memory = self.memory_f.iter().chain(&self.memory_cr);
        if !memory.clone().all(|v| v.is_finite()) || !self.memory_f.iter().all(|&f| f > 0.0) {
            return Err("SHADE memory holds a non-finite or non-positive value".to_string());
        }
        if self.archive.len() > np || self.archive.iter().any(|a| a.len() != dim) {
            return Err(format!(
                "SHADE archive has {} vectors (at most {np} of length {dim} allowed)",
                self.archive.len()
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn memory_takes_weighted_lehmer_and_arithmetic_means() {
        let mut state = ShadeState::new(4);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let successes = [
            Success {
                f: 0.2,
                cr: 0.1,
                gain: 1.0,
            },
            Success {
                f: 0.8,
                cr: 0.9,
                gain: 3.0,
            },
            Success {
                f: 0.9,
                cr: 0.9,
                gain: f64::INFINITY,
            },
        ];
        state.end_generation(&successes, 4, &mut rng);
        // weights 1/4 and 3/4; the infinite gain is left out.
        let lehmer = (0.25 * 0.04 + 0.75 * 0.64) / (0.25 * 0.2 + 0.75 * 0.8);
        assert!((state.memory_f[0] - lehmer).abs() < 1e-12);
        assert!((state.memory_cr[0] - (0.25 * 0.1 + 0.75 * 0.9)).abs() < 1e-12);
        assert_eq!(state.memory_f[1], MEMORY_INITIAL);
        assert_eq!(state.next_slot, 1);
    }

    #[test]
    fn no_success_leaves_memory_alone() {
        let mut state = ShadeState::new(4);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        state.end_generation(&[], 4, &mut rng);
        assert_eq!(state, ShadeState::new(4));
    }

    #[test]
    fn archive_is_trimmed_to_population_size() {
        let mut state = ShadeState::new(4);
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        for k in 0..7 {
            state.archive_parent(vec![k as f64 / 10.0]);
        }
        state.end_generation(&[], 4, &mut rng);
        assert_eq!(state.archive().len(), 4);
    }

    #[test]
    fn sampled_parameters_stay_in_range() {
        let state = ShadeState::new(10);
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for _ in 0..5_000 {
            let (f, cr) = state.sample_parameters(&mut rng);
            assert!(f > 0.0 && f <= 1.0, "F {f}");
            assert!((0.0..=1.0).contains(&cr), "CR {cr}");
        }
    }

    #[test]
    fn trials_are_current_to_pbest_1_with_archive() {
        // With CR = 1 a trial is the whole mutant
        // x_i + F (x_pbest - x_i) + F (x_r1 - x_r2); look for partners that
        // obey the paper's rules (pbest among the best p·NP, r1 != i,
        // r2 from population ∪ archive, r2 != r1, i) and reproduce it bit
        // for bit, repair included.
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let np = 8;
        let population: Vec<Vec<f64>> = (0..np)
            .map(|_| (0..3).map(|_| sampling::unit(&mut rng)).collect())
            .collect();
        let fitness: Vec<f64> = population.iter().map(|x| x.iter().sum()).collect();
        let ranking = ShadeState::ranking(&fitness);
        let mut state = ShadeState::new(np);
        for _ in 0..3 {
            let point = (0..3).map(|_| sampling::unit(&mut rng)).collect();
            state.archive_parent(point);
        }
        let pool: Vec<&Vec<f64>> = population.iter().chain(&state.archive).collect();
        // NP = 8 puts p_min = 2/8 above 0.2, so p·NP rounds to 2.
        let top = &ranking[..2];
        let f = 0.7;
        for i in 0..np {
            let trial = state.trial(&population, &ranking, i, (f, 1.0), &mut rng);
            let x = &population[i];
            let explains = |pbest: usize, r1: usize, r2: usize| {
                (0..3).all(|j| {
                    let v = x[j]
                        + f * (population[pbest][j] - x[j])
                        + f * (population[r1][j] - pool[r2][j]);
                    trial[j].to_bits() == operators::repair(v, x[j]).to_bits()
                })
            };
            let found = top.iter().any(|&pbest| {
                (0..np).filter(|&r1| r1 != i).any(|r1| {
                    (0..pool.len())
                        .filter(|&r2| r2 != i && r2 != r1)
                        .any(|r2| explains(pbest, r1, r2))
                })
            });
            assert!(found, "trial {i} is not current-to-pbest/1: {trial:?}");
        }
    }

    #[test]
    fn ranking_puts_failures_last() {
        let order = ShadeState::ranking(&[3.0, f64::INFINITY, 1.0, 3.0]);
        assert_eq!(order, vec![2, 0, 3, 1]);
    }
}
