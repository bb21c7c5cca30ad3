//! The interface every search strategy offers the fit executor: ask for a
//! batch of points in the unit cube, be told how each one scored. A global
//! strategy needs only each point's fitness; a local one (a Gauss–Newton
//! step from finite differences) also needs its residual vector, and says
//! so in its request, so the executor computes residuals only when asked.
//! `searcher.rs` holds any strategy as one value.

use super::{De, Progress};

/// What a search wants evaluated next.
#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    /// Points in `[0,1]^dim`.
    pub points: Vec<Vec<f64>>,
    /// Whether each point's residual vector is needed, not just its fitness.
    pub residuals: bool,
    /// The view the residuals are wanted at: target and render each
    /// blurred by a Gaussian of this many pixels before they are
    /// subtracted (0: as rendered). The fitness is always the sharp one.
    /// The search names a scale, never an image: the metric applies it
    /// (`metric::blur`), so the search still knows nothing of images.
    pub blur: f64,
}

/// How one point scored. A failed render has an infinite fitness and no
/// residuals.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Evaluation {
    pub fitness: f64,
    /// Per-value residuals (render − target, over the mask, at the blur
    /// asked for), when asked for.
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
            blur: 0.0,
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
