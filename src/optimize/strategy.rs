//! The names of the search strategies, as users write them in configs and
//! on the command line (`rand1bin`, `jde`, `shade`, `hybrid`).
//!
//! Kept apart from the algorithms so that the CLI and config layers can
//! parse and print a strategy without pulling in any search state.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Which search a run uses: one of the trial-generation schemes of
/// [`crate::optimize::De`], or [`Strategy::Hybrid`], a SHADE global phase
/// handing over to a local least-squares phase ([`crate::optimize::Hybrid`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Strategy {
    /// DE/rand/1/bin with fixed F and CR (Storn & Price 1997).
    Rand1Bin,
    /// rand/1/bin with per-individual self-adapted F and CR (Brest et al. 2006).
    Jde,
    /// current-to-pbest/1/bin with archive and success-history memory
    /// (Tanabe & Fukunaga 2013).
    Shade,
    /// SHADE alternating with Levenberg–Marquardt runs on the residuals
    /// from its best point. Not a DE
    /// scheme: [`crate::optimize::Searcher::new`] builds a
    /// [`crate::optimize::Hybrid`] for it, and a [`crate::optimize::De`]
    /// given it runs its global phase, SHADE.
    Hybrid,
}

impl Strategy {
    /// Every strategy, in the order they are listed to users.
    pub const ALL: [Strategy; 4] = [
        Strategy::Rand1Bin,
        Strategy::Jde,
        Strategy::Shade,
        Strategy::Hybrid,
    ];

    /// The Differential Evolution schemes, the ones [`crate::optimize::De`]
    /// runs as themselves.
    pub const DE: [Strategy; 3] = [Strategy::Rand1Bin, Strategy::Jde, Strategy::Shade];

    /// The DE scheme a [`crate::optimize::De`] runs for this strategy: the
    /// strategy itself, or SHADE for the hybrid's global phase.
    pub fn de_scheme(self) -> Strategy {
        match self {
            Strategy::Hybrid => Strategy::Shade,
            other => other,
        }
    }

    /// The canonical lowercase name; the same string serde uses.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Rand1Bin => "rand1bin",
            Strategy::Jde => "jde",
            Strategy::Shade => "shade",
            Strategy::Hybrid => "hybrid",
        }
    }
}

impl fmt::Display for Strategy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(self.name())
    }
}

/// A strategy name that is not one of [`Strategy::ALL`].
#[derive(Clone, Debug, PartialEq, Eq, Error)]
#[error(
    "unknown search strategy `{given}`; valid names are: {}",
    valid_names()
)]
pub struct ParseStrategyError {
    /// The text that failed to parse, as given.
    pub given: String,
}

/// The names of [`Strategy::ALL`], comma-separated: the error lists them from
/// the registry, so a new strategy needs no edit here.
fn valid_names() -> String {
    let names: Vec<&str> = Strategy::ALL.iter().map(|s| s.name()).collect();
    names.join(", ")
}

impl FromStr for Strategy {
    type Err = ParseStrategyError;

    /// Accepts the canonical names, ignoring ASCII case and surrounding
    /// whitespace, because users type these on the command line.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let wanted = s.trim();
        Strategy::ALL
            .into_iter()
            .find(|strategy| strategy.name().eq_ignore_ascii_case(wanted))
            .ok_or_else(|| ParseStrategyError {
                given: s.to_string(),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_error_lists_every_valid_name() {
        let message = "nope".parse::<Strategy>().unwrap_err().to_string();
        assert!(message.contains("`nope`"), "{message}");
        for strategy in Strategy::ALL {
            assert!(message.contains(strategy.name()), "{message}");
        }
    }
}
