//! The ask/tell Differential Evolution engine ([`De`]): population,
//! selection, counters and the one random generator.
//!
//! Ask/tell (instead of taking an objective closure) lets the caller
//! evaluate a whole batch however it likes (in parallel, on a render farm,
//! across a checkpoint) without the optimiser knowing. Every random draw
//! happens inside [`De::ask`] and [`De::tell`], in a fixed order, from one
//! seeded ChaCha8 generator, so a seed fixes the whole run bit for bit
//! however the batch was evaluated.
//!
//! Selection is the greedy one-to-one rule of Storn & Price (1997); the
//! trial generation of each strategy lives in `rand1bin.rs`, `jde.rs`
//! (Brest et al. 2006) and `shade.rs` (Tanabe & Fukunaga 2013).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use thiserror::Error;

use super::jde::JdeState;
use super::shade::{ShadeState, Success};
use super::{exact, init, rand1bin, DeConfig, Progress, Strategy};

/// A Differential Evolution search in `[0,1]^dim`, driven by
/// [`ask`](De::ask) and [`tell`](De::tell).
///
/// The whole state, generator included, serialises (see
/// [`crate::optimize::checkpoint`]); deserialising checks the state's
/// invariants, so a damaged file is an error, never a later panic.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(remote = "Self")]
pub struct De {
    #[serde(with = "exact::config")]
    pub(super) config: DeConfig,
    pub(super) dim: usize,
    #[serde(with = "exact::matrix")]
    pub(super) population: Vec<Vec<f64>>,
    /// +inf for failed evaluations and before the first tell.
    #[serde(with = "exact::vector")]
    pub(super) fitness: Vec<f64>,
    /// Whether the initial population has been told its fitness.
    pub(super) evaluated: bool,
    /// Trials handed out by `ask` and not yet told.
    pub(super) pending: Option<Batch>,
    pub(super) adaptation: Adaptation,
    pub(super) rng: ChaCha8Rng,
    pub(super) generation: usize,
    pub(super) evaluations: usize,
    pub(super) progress: Progress,
}

/// One generation's trials and the F and CR each was made with (needed at
/// selection time by jDE and SHADE).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub(super) struct Batch {
    #[serde(with = "exact::matrix")]
    pub(super) trials: Vec<Vec<f64>>,
    #[serde(with = "exact::vector")]
    pub(super) f: Vec<f64>,
    #[serde(with = "exact::vector")]
    pub(super) cr: Vec<f64>,
}

/// Strategy-specific adaptive state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub(super) enum Adaptation {
    Fixed,
    Jde(JdeState),
    Shade(ShadeState),
}

impl Adaptation {
    fn for_strategy(strategy: Strategy, np: usize) -> Self {
        match strategy {
            Strategy::Rand1Bin => Adaptation::Fixed,
            Strategy::Jde => Adaptation::Jde(JdeState::new(np)),
            Strategy::Shade | Strategy::Hybrid => Adaptation::Shade(ShadeState::new(np)),
        }
    }

    pub(super) fn strategy(&self) -> Strategy {
        match self {
            Adaptation::Fixed => Strategy::Rand1Bin,
            Adaptation::Jde(_) => Strategy::Jde,
            Adaptation::Shade(_) => Strategy::Shade,
        }
    }
}

/// Misuse of [`De::try_tell`].
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum TellError {
    #[error("tell() called with no batch pending: call ask() first")]
    NothingPending,
    #[error("tell() got {got} fitness values for a batch of {expected}")]
    WrongLength { expected: usize, got: usize },
}

/// Failed evaluations are stored as +inf so that every comparison treats
/// them as worse than any success.
fn normalise(value: f64) -> f64 {
    if value.is_finite() {
        value
    } else {
        f64::INFINITY
    }
}

impl De {
    /// A search whose initial population is uniform in the cube.
    ///
    /// The config is [sanitised](DeConfig::sanitized) first, so this never
    /// panics; [`De::config`] returns the values actually used.
    pub fn new(dim: usize, config: DeConfig) -> De {
        De::with_population(dim, config, |np, rng| init::uniform(np, dim, rng))
    }

    /// Like [`De::new`] but with a Latin hypercube initial population, which
    /// covers every coordinate's range evenly even with few individuals.
    pub fn latin_hypercube(dim: usize, config: DeConfig) -> De {
        De::with_population(dim, config, |np, rng| init::latin_hypercube(np, dim, rng))
    }

    /// Initial population drawn around `center` (in unit coords) with
    /// per-coordinate spread `radius` (clamped to the cube); individual 0
    /// is `center` itself. Used to seed a refinement stage from an earlier
    /// fit.
    ///
    /// The others are uniform in `[c - radius, c + radius] ∩ [0, 1]` per
    /// coordinate. Never panics: a `center` of the wrong length is cut or
    /// padded with 0.5, non-finite coordinates become 0.5, coordinates are
    /// clamped into the cube, and a negative or NaN `radius` counts as 0.
    pub fn around(dim: usize, config: DeConfig, center: &[f64], radius: f64) -> De {
        De::with_population(dim, config, |np, rng| {
            init::around(np, dim, center, radius, rng)
        })
    }

    /// [`De::around`] with a spread per coordinate ([`init::around_each`]).
    pub fn around_each(dim: usize, config: DeConfig, center: &[f64], radii: &[f64]) -> De {
        De::with_population(dim, config, |np, rng| {
            init::around_each(np, dim, center, radii, rng)
        })
    }

    /// A [`Strategy::Hybrid`] config becomes SHADE (the hybrid's global
    /// phase): a `De` never runs, nor reports, a non-DE strategy.
    fn with_population(
        dim: usize,
        config: DeConfig,
        sample: impl FnOnce(usize, &mut ChaCha8Rng) -> Vec<Vec<f64>>,
    ) -> De {
        let mut config = config.sanitized();
        config.strategy = config.strategy.de_scheme();
        let np = config.population;
        let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
        let population = sample(np, &mut rng);
        De {
            adaptation: Adaptation::for_strategy(config.strategy, np),
            config,
            dim,
            population,
            fitness: vec![f64::INFINITY; np],
            evaluated: false,
            pending: None,
            rng,
            generation: 0,
            evaluations: 0,
            progress: Progress::default(),
        }
    }

    /// The points to evaluate next.
    ///
    /// The first batch is the initial population; every later batch holds
    /// one trial vector per individual, in population order. Calling `ask`
    /// again before [`tell`](De::tell) is harmless: it returns the same
    /// pending batch and draws no random numbers, so a caller that retries
    /// after a crash keeps the run on its seeded course.
    pub fn ask(&mut self) -> Vec<Vec<f64>> {
        if !self.evaluated {
            return self.population.clone();
        }
        if self.pending.is_none() {
            self.pending = Some(self.make_batch());
        }
        self.pending
            .as_ref()
            .map(|batch| batch.trials.clone())
            .unwrap_or_default()
    }

    /// Trials for every individual, in index order: the order of random
    /// draws is part of the seeded contract.
    fn make_batch(&mut self) -> Batch {
        let np = self.population.len();
        let mut batch = Batch {
            trials: Vec::with_capacity(np),
            f: Vec::with_capacity(np),
            cr: Vec::with_capacity(np),
        };
        let ranking = match &self.adaptation {
            Adaptation::Shade(_) => ShadeState::ranking(&self.fitness),
            _ => Vec::new(),
        };
        for i in 0..np {
            let (f, cr) = match &self.adaptation {
                Adaptation::Fixed => (self.config.f, self.config.cr),
                Adaptation::Jde(jde) => jde.propose(i, &mut self.rng),
                Adaptation::Shade(shade) => shade.sample_parameters(&mut self.rng),
            };
            let trial = match &self.adaptation {
                Adaptation::Shade(shade) => {
                    shade.trial(&self.population, &ranking, i, (f, cr), &mut self.rng)
                }
                _ => rand1bin::trial(&self.population, i, f, cr, &mut self.rng),
            };
            batch.trials.push(trial);
            batch.f.push(f);
            batch.cr.push(cr);
        }
        batch
    }

    /// Reports the fitness of the batch the last [`ask`](De::ask) returned,
    /// in the same order.
    ///
    /// NaN and ±inf mark failed evaluations: a failed trial never replaces
    /// its target, and a failed individual is replaced by any successful
    /// trial. (-inf counts as failed too: no real objective reaches it, so
    /// it signals a bug that must not become the best.) Otherwise the trial
    /// replaces its target when its fitness is lower or equal; accepting
    /// ties lets the population drift across flat regions.
    ///
    /// # Panics
    /// If no batch is pending (only possible after a `tell` without a new
    /// `ask`) or `fitness` has the wrong length. Use [`De::try_tell`] to get
    /// an error instead.
    pub fn tell(&mut self, fitness: &[f64]) {
        if let Err(error) = self.try_tell(fitness) {
            panic!("{error}");
        }
    }

    /// [`De::tell`] that reports misuse as an error and then leaves the
    /// state unchanged.
    pub fn try_tell(&mut self, fitness: &[f64]) -> Result<(), TellError> {
        let np = self.population.len();
        if fitness.len() != np {
            return Err(TellError::WrongLength {
                expected: np,
                got: fitness.len(),
            });
        }
        if !self.evaluated {
            self.fitness = fitness.iter().copied().map(normalise).collect();
            self.evaluated = true;
        } else {
            let batch = self.pending.take().ok_or(TellError::NothingPending)?;
            self.select(batch, fitness);
            self.generation += 1;
        }
        self.evaluations += np;
        let best = self.best().1;
        self.progress.observe(self.generation, best);
        Ok(())
    }

    /// Greedy one-to-one selection, then the strategy's end-of-generation
    /// bookkeeping.
    fn select(&mut self, batch: Batch, fitness: &[f64]) {
        let mut successes = Vec::new();
        let trials = batch.trials.into_iter().zip(fitness).enumerate();
        for (i, (trial, &trial_fitness)) in trials {
            let trial_fitness = normalise(trial_fitness);
            let target_fitness = self.fitness[i];
            if !(trial_fitness.is_finite() && trial_fitness <= target_fitness) {
                continue;
            }
            let parent = std::mem::replace(&mut self.population[i], trial);
            self.fitness[i] = trial_fitness;
            let (f, cr) = (batch.f[i], batch.cr[i]);
            match &mut self.adaptation {
                Adaptation::Fixed => {}
                Adaptation::Jde(jde) => jde.accept(i, f, cr),
                // SHADE learns only from strict improvements (the paper's
                // rule); ties are accepted but teach nothing.
                Adaptation::Shade(shade) if trial_fitness < target_fitness => {
                    shade.archive_parent(parent);
                    successes.push(Success {
                        f,
                        cr,
                        gain: target_fitness - trial_fitness,
                    });
                }
                Adaptation::Shade(_) => {}
            }
        }
        if let Adaptation::Shade(shade) = &mut self.adaptation {
            shade.end_generation(&successes, self.population.len(), &mut self.rng);
        }
    }

    /// Puts an already evaluated point into the population in place of the
    /// worst individual, if it is better than that one (a local search's
    /// result handed back). Draws no random numbers; a pending batch is
    /// dropped, so the next [`ask`](De::ask) makes a new one.
    pub fn inject(&mut self, point: &[f64], fitness: f64) {
        if !self.evaluated || point.len() != self.dim || !fitness.is_finite() {
            return;
        }
        let mut worst = 0;
        for (i, &value) in self.fitness.iter().enumerate() {
            // Failed (+inf) individuals are the worst; ties go to the
            // highest index so the best (lowest index on ties) is kept.
            if value.total_cmp(&self.fitness[worst]).is_ge() {
                worst = i;
            }
        }
        if fitness < self.fitness[worst] {
            self.population[worst] = point.to_vec();
            self.fitness[worst] = fitness;
            self.pending = None;
        }
    }

    /// The best individual and its fitness. Failed evaluations never count;
    /// before the first [`tell`](De::tell), or while every evaluation has
    /// failed, this is individual 0 with fitness +inf. Ties go to the lowest
    /// index.
    pub fn best(&self) -> (&[f64], f64) {
        let mut best = 0;
        for (i, &value) in self.fitness.iter().enumerate() {
            if value < self.fitness[best] {
                best = i;
            }
        }
        (&self.population[best], self.fitness[best])
    }

    /// Completed generations: tells after the initial population's
    /// (which is generation 0).
    pub fn generation(&self) -> usize {
        self.generation
    }

    /// Objective evaluations told so far, failed ones included.
    pub fn evaluations(&self) -> usize {
        self.evaluations
    }

    /// The current individuals, in unit coordinates.
    pub fn population(&self) -> &[Vec<f64>] {
        &self.population
    }

    /// Fitness of each individual (+inf when failed or not yet evaluated).
    pub fn fitness(&self) -> &[f64] {
        &self.fitness
    }

    /// The config in use (after sanitising).
    pub fn config(&self) -> &DeConfig {
        &self.config
    }

    /// Dimension of the search space.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// When the best fitness last improved, for stagnation stopping.
    pub fn progress(&self) -> &Progress {
        &self.progress
    }

    /// Whether a trial batch has been asked for and not yet told.
    pub fn has_pending(&self) -> bool {
        self.pending.is_some()
    }

    /// jDE's per-individual F values (None for other strategies).
    pub fn jde_f(&self) -> Option<&[f64]> {
        match &self.adaptation {
            Adaptation::Jde(jde) => Some(jde.f()),
            _ => None,
        }
    }

    /// SHADE's memory of F values and its archive (None for other
    /// strategies).
    pub fn shade_state(&self) -> Option<(&[f64], &[Vec<f64>])> {
        match &self.adaptation {
            Adaptation::Shade(shade) => Some((shade.memory_f(), shade.archive())),
            _ => None,
        }
    }
}

impl Serialize for De {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        De::serialize(self, serializer)
    }
}

impl<'de> Deserialize<'de> for De {
    /// Rejects states that break an invariant the engine indexes by, so
    /// that a hand-edited or truncated checkpoint fails to load instead of
    /// panicking later.
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let de = De::deserialize(deserializer)?;
        de.check_invariants().map_err(serde::de::Error::custom)?;
        Ok(de)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inject_replaces_the_worst_member_only_when_better() {
        let config = DeConfig {
            population: 5,
            ..DeConfig::default()
        };
        let mut de = De::new(2, config);
        let points = de.ask();
        de.tell(&[3.0, 1.0, 5.0, 2.0, 4.0]);
        de.inject(&[0.5, 0.5], 6.0);
        assert_eq!(de.population(), points.as_slice(), "a worse point got in");
        de.inject(&[0.5, 0.5], 0.5);
        assert_eq!(de.fitness(), &[3.0, 1.0, 0.5, 2.0, 4.0]);
        assert_eq!(de.population()[2], vec![0.5, 0.5]);
        assert_eq!(de.best(), (&[0.5, 0.5][..], 0.5));
    }
}
