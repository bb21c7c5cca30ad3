//! [`Searcher`]: any search strategy as one serialisable value, so that a
//! checkpoint stores whichever one a run uses, and where a search starts.

use super::basins::Basins;
use super::{
    De, DeConfig, Evaluation, Hybrid, Identifiability, Progress, Request, Search, Strategy,
};
use serde::{Deserialize, Serialize};

/// Any strategy, as one value a checkpoint can hold.
///
/// Externally tagged (`{"de": {...}}`), not internally: an internal tag
/// makes serde buffer the value, and the buffer cannot hold the 128-bit
/// integers the random generator's state contains.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
// A run holds one searcher, so the variants' size difference costs nothing.
#[allow(clippy::large_enum_variant)]
pub enum Searcher {
    De(De),
    Hybrid(Hybrid),
}

/// Where a search starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Start<'a> {
    /// Uniformly in the cube ([`De::new`]).
    Uniform,
    /// Around a known point, per-coordinate spread `radius` ([`De::around`]).
    Around { center: &'a [f64], radius: f64 },
    /// Around a known point, a spread per coordinate ([`De::around_each`]).
    AroundEach { center: &'a [f64], radii: &'a [f64] },
}

impl Searcher {
    /// The search `config.strategy` names: a [`De`] for the DE schemes, a
    /// [`Hybrid`] (SHADE global phase) for [`Strategy::Hybrid`]. Never
    /// panics: the config is sanitised as [`De::new`] does.
    pub fn new(dim: usize, config: &DeConfig, start: Start) -> Searcher {
        let global = match start {
            Start::Uniform => De::new(dim, config.clone()),
            Start::Around { center, radius } => De::around(dim, config.clone(), center, radius),
            Start::AroundEach { center, radii } => {
                De::around_each(dim, config.clone(), center, radii)
            }
        };
        match config.strategy {
            Strategy::Hybrid => Searcher::Hybrid(Hybrid::new(global, config)),
            _ => Searcher::De(global),
        }
    }

    /// Other places the search saw that fit alike its best, in unit
    /// coordinates, best first, with their fitness (`basins.rs`): what
    /// the hybrid saw over its run, or a population search's final
    /// population.
    pub fn alternatives(&self) -> Vec<(Vec<f64>, f64)> {
        match self {
            Searcher::De(de) => {
                let (best, best_fitness) = de.best();
                let mut basins = Basins::default();
                for (point, &f) in de.population().iter().zip(de.fitness()) {
                    basins.offer(point, f, best_fitness);
                }
                basins.alternatives(best, best_fitness)
            }
            Searcher::Hybrid(h) => h.alternatives(),
        }
    }

    /// Standard errors and correlations at the best point in unit
    /// coordinates, when the strategy estimates them (the hybrid, once its
    /// local phase has run).
    pub fn identifiability(&self) -> Option<Identifiability> {
        match self {
            Searcher::De(_) => None,
            Searcher::Hybrid(h) => h.identifiability(),
        }
    }

    /// Makes a hybrid search end once it has settled ([`Hybrid::settle`]);
    /// a DE search is left as it is.
    pub fn settle(&mut self) {
        if let Searcher::Hybrid(h) = self {
            h.settle();
        }
    }

    /// Declares periodic coordinates for a hybrid search
    /// ([`Hybrid::set_periods`]); a DE search is left as it is.
    pub fn set_periods(&mut self, periods: Vec<f64>) {
        if let Searcher::Hybrid(h) = self {
            h.set_periods(periods);
        }
    }

    /// Declares coordinate swaps for a hybrid search
    /// ([`Hybrid::set_swaps`]); a DE search is left as it is.
    pub fn set_swaps(&mut self, perms: Vec<Vec<usize>>) {
        if let Searcher::Hybrid(h) = self {
            h.set_swaps(perms);
        }
    }

    /// The strategy this search runs.
    pub fn strategy(&self) -> Strategy {
        match self {
            Searcher::De(d) => d.config().strategy,
            Searcher::Hybrid(_) => Strategy::Hybrid,
        }
    }

    fn inner(&self) -> &dyn Search {
        match self {
            Searcher::De(d) => d,
            Searcher::Hybrid(h) => h,
        }
    }

    fn inner_mut(&mut self) -> &mut dyn Search {
        match self {
            Searcher::De(d) => d,
            Searcher::Hybrid(h) => h,
        }
    }
}

impl Search for Searcher {
    fn ask(&mut self) -> Request {
        self.inner_mut().ask()
    }
    fn tell(&mut self, evaluations: &[Evaluation]) {
        self.inner_mut().tell(evaluations)
    }
    fn best(&self) -> (&[f64], f64) {
        self.inner().best()
    }
    fn generation(&self) -> usize {
        self.inner().generation()
    }
    fn evaluations(&self) -> usize {
        self.inner().evaluations()
    }
    fn progress(&self) -> &Progress {
        self.inner().progress()
    }
    fn converged(&self) -> bool {
        self.inner().converged()
    }
    fn population(&self) -> Option<(&[Vec<f64>], &[f64])> {
        self.inner().population()
    }
}
