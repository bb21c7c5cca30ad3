//! When to end a run: a generation budget, a target fitness, or
//! stagnation of the best fitness.
//!
//! The rule itself is stateless; what stagnation needs to remember lives
//! in the search's [`crate::optimize::Progress`], so a run resumed from a
//! checkpoint stops exactly when the uninterrupted run would have.

use std::fmt;

use serde::{Deserialize, Serialize};

use super::Search;

/// Limits of a run. The first one met ends it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StopRule {
    /// Stop after this many generations (the initial population is
    /// generation 0).
    pub max_generations: usize,
    /// Stop once the best fitness is at or below this value.
    pub target: Option<f64>,
    /// Stop after this many generations without a relative improvement of
    /// the best fitness greater than
    /// [`IMPROVEMENT_TOLERANCE`](crate::optimize::IMPROVEMENT_TOLERANCE).
    pub stagnation: Option<usize>,
}

/// Why [`StopRule::check`] ended a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StopReason {
    Generations,
    Target,
    Stagnation,
    /// The search has nothing left to try ([`Search::converged`]): said
    /// apart from the budget, so a run that ended early does not read as
    /// one cut short.
    Converged,
}

impl fmt::Display for StopReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(match self {
            StopReason::Generations => "generation budget used up",
            StopReason::Target => "target fitness reached",
            StopReason::Stagnation => "best fitness stagnated",
            StopReason::Converged => "converged: nothing left to move",
        })
    }
}

impl StopRule {
    /// Whether `search` should stop now, and why.
    ///
    /// Checked in the order target, stagnation, generations, so a run that
    /// meets its target on its last allowed generation reports success.
    /// Nothing stops a run whose initial population is not yet evaluated,
    /// except a budget of zero generations.
    pub fn check<S: Search + ?Sized>(&self, de: &S) -> Option<StopReason> {
        let started = de.evaluations() > 0;
        if let Some(target) = self.target {
            if started && de.best().1 <= target {
                return Some(StopReason::Target);
            }
        }
        if let Some(patience) = self.stagnation {
            let since = de
                .generation()
                .saturating_sub(de.progress().last_improvement_generation());
            if started && since >= patience {
                return Some(StopReason::Stagnation);
            }
        }
        if de.generation() >= self.max_generations {
            return Some(StopReason::Generations);
        }
        if started && de.converged() {
            return Some(StopReason::Converged);
        }
        None
    }
}
