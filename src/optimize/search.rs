//! The interface every search strategy offers the fit executor: ask for a
//! batch of points in the unit cube, be told how each one scored. A global
//! strategy needs only each point's fitness; a local one (a Gauss–Newton
//! step from finite differences) also needs its residual vector, and says
//! so in its request, so the executor computes residuals only when asked.
//!
//! [`Searcher`] holds any strategy as one serialisable value, so that a
//! checkpoint stores whichever one a run uses.

use super::{De, DeConfig, Hybrid, Identifiability, Progress, Strategy};
use serde::{Deserialize, Serialize};

/// What a search wants evaluated next.
#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    /// Points in `[0,1]^dim`.
    pub points: Vec<Vec<f64>>,
    /// Whether each point's residual vector is needed, not just its fitness.
    pub residuals: bool,
}

/// How one point scored. A failed render has an infinite fitness and no
/// residuals.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Evaluation {
    pub fitness: f64,
    /// Per-value residuals (render − target, over the mask), when asked for.
    pub residuals: Option<Vec<f32>>,
}

impl Evaluation {
    /// A point whose evaluation failed.
    pub fn failed() -> Evaluation {
        Evaluation {
            fitness: f64::INFINITY,
            residuals: None,
        }
    }
}

/// An ask/tell minimiser over the unit cube.
pub trait Search {
    /// The next batch to evaluate. Called once per generation; a request is
    /// answered by exactly one [`Search::tell`].
    fn ask(&mut self) -> Request;
    /// The evaluations of the last request's points, in order.
    fn tell(&mut self, evaluations: &[Evaluation]);
    /// The best point so far and its fitness.
    fn best(&self) -> (&[f64], f64);
    /// Requests answered so far.
    fn generation(&self) -> usize;
    /// Points evaluated so far.
    fn evaluations(&self) -> usize;
    /// When the best fitness last improved (for the stagnation rule).
    fn progress(&self) -> &Progress;
    /// True when the search has nothing left to try (the hybrid's fitness
    /// is 0, or its population collapsed and a local run gained nothing);
    /// the executor then stops as if the budget were used up.
    fn converged(&self) -> bool {
        false
    }
    /// The current population and its fitness, for a global strategy (the
    /// report's trade-off section); `None` for a local one.
    fn population(&self) -> Option<(&[Vec<f64>], &[f64])> {
        None
    }
}

impl Search for De {
    fn ask(&mut self) -> Request {
        Request {
            points: De::ask(self),
            residuals: false,
        }
    }

    fn tell(&mut self, evaluations: &[Evaluation]) {
        let fitness: Vec<f64> = evaluations.iter().map(|e| e.fitness).collect();
        De::tell(self, &fitness);
    }

    fn best(&self) -> (&[f64], f64) {
        De::best(self)
    }

    fn generation(&self) -> usize {
        De::generation(self)
    }

    fn evaluations(&self) -> usize {
        De::evaluations(self)
    }

    fn progress(&self) -> &Progress {
        De::progress(self)
    }

    fn population(&self) -> Option<(&[Vec<f64>], &[f64])> {
        Some((De::population(self), De::fitness(self)))
    }
}

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
