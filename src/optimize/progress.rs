//! Tracking of when the best fitness last improved, for the stagnation
//! stop rule.
//!
//! It lives inside [`crate::optimize::De`] (not beside it) so it is saved in
//! checkpoints: a resumed run must stop at the same generation as one that
//! never stopped.

use serde::{Deserialize, Serialize};

use super::exact;

/// A best fitness must drop by more than this fraction of its previous
/// reference value to count as an improvement.
pub const IMPROVEMENT_TOLERANCE: f64 = 1e-9;

/// The best fitness at the last real improvement, and when it happened.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Progress {
    #[serde(with = "exact::scalar")]
    reference_best: f64,
    last_improvement_generation: usize,
}

impl Default for Progress {
    fn default() -> Self {
        Progress {
            reference_best: f64::INFINITY,
            last_improvement_generation: 0,
        }
    }
}

impl Progress {
    /// Records the best fitness after `generation`.
    ///
    /// Compared with the reference kept from the last improvement, not with
    /// the previous generation: many tiny gains then still add up to one
    /// that counts, so a slow but steady run is not called stagnant.
    pub fn observe(&mut self, generation: usize, best: f64) {
        let improved = if self.reference_best.is_finite() {
            best < self.reference_best - IMPROVEMENT_TOLERANCE * self.reference_best.abs()
        } else {
            // Everything failed so far: the first success is progress.
            best.is_finite()
        };
        if improved {
            self.reference_best = best;
            self.last_improvement_generation = generation;
        }
    }

    /// The generation of the last improvement (0 for the initial population).
    pub fn last_improvement_generation(&self) -> usize {
        self.last_improvement_generation
    }

    /// The best fitness as of the last improvement (+inf before any success).
    pub fn reference_best(&self) -> f64 {
        self.reference_best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_steps_add_up_to_an_improvement() {
        let mut p = Progress::default();
        p.observe(0, 1.0);
        assert_eq!(p.last_improvement_generation(), 0);
        // Each step is below the tolerance...
        p.observe(1, 1.0 - 0.6e-9);
        assert_eq!(p.last_improvement_generation(), 0);
        // ...but together they pass it.
        p.observe(2, 1.0 - 1.2e-9);
        assert_eq!(p.last_improvement_generation(), 2);
    }

    #[test]
    fn first_success_after_failures_counts() {
        let mut p = Progress::default();
        p.observe(0, f64::INFINITY);
        p.observe(3, 5.0);
        assert_eq!(p.last_improvement_generation(), 3);
        assert_eq!(p.reference_best(), 5.0);
    }
}
