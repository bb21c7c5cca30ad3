//! Derivative-free global optimisation in the unit cube `[0,1]^dim`.
//!
//! This module owns the search engine that fits scene parameters: an
//! ask/tell Differential Evolution ([`De`]) with three strategies, the rules
//! that end a run ([`StopRule`]), serialisable state for checkpoints, and the
//! classic test functions used to check it ([`functions`]).
//!
//! The optimiser never sees real parameter bounds: the caller maps unit
//! coordinates to scene values. That keeps every strategy's bound handling
//! identical and lets a refinement stage restart around an earlier fit with
//! [`De::around`].
//!
//! Strategies:
//! - [`Strategy::Rand1Bin`]: DE/rand/1/bin, R. Storn and K. Price,
//!   "Differential Evolution – A Simple and Efficient Heuristic for Global
//!   Optimization over Continuous Spaces", J. Global Optimization 11, 1997.
//! - [`Strategy::Jde`]: self-adaptive F and CR, J. Brest, S. Greiner,
//!   B. Bošković, M. Mernik and V. Žumer, "Self-Adapting Control Parameters
//!   in Differential Evolution", IEEE Trans. Evol. Comput. 10(6), 2006.
//! - [`Strategy::Shade`]: success-history adaptation, R. Tanabe and
//!   A. Fukunaga, "Success-History Based Parameter Adaptation for
//!   Differential Evolution", IEEE CEC 2013.
//! - [`Strategy::Hybrid`] ([`Hybrid`]): SHADE alternating with
//!   Levenberg–Marquardt runs (K. Levenberg 1944, D. Marquardt 1963) from
//!   its best point on the per-value residuals, reweighted to minimise the
//!   L1 deviation, each run's result handed back to the population, with
//!   standard errors from the Jacobian at the best point
//!   ([`Identifiability`]). The executor builds any of them through
//!   [`Searcher::new`].

pub mod basins;
mod config;
mod de;
pub(crate) mod exact;
pub mod functions;
mod hybrid;
mod identifiability;
mod init;
mod invariants;
mod jde;
pub mod lm;
mod local;
mod operators;
mod progress;
mod pyramid;
mod rand1bin;
mod sampling;
mod search;
mod searcher;
mod shade;
mod stop;
mod strategy;
mod swaps;

pub use config::{ConfigError, DeConfig, MIN_POPULATION};
pub use de::{De, TellError};
pub use functions::TestFunction;
pub use hybrid::{basin_spreads, Hybrid};
pub use identifiability::Identifiability;
pub use progress::{Progress, IMPROVEMENT_TOLERANCE};
pub use search::{Evaluation, Request, Search};
pub use searcher::{Searcher, Start};
pub use stop::{StopReason, StopRule};
pub use strategy::{ParseStrategyError, Strategy};
