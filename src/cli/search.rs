//! The search options (population, generations, F, CR, strategy, seed,
//! jobs, stop rules), defined once for every command that runs a search:
//! `fit` reads them as `--population`, …, and each pipeline stage as
//! `--stage1-population`, `--stage2-population`, …
//!
//! clap needs a distinct id per flattened copy, so the options are built
//! here by one function from a [`Kind`] (the flag prefix, the help prefix
//! and the defaults) rather than derived once per copy.

use crate::error::{Error, Result};
use crate::fit::FitConfig;
use crate::optimize::{DeConfig, Strategy};
use clap::{Arg, ArgAction, ArgMatches, Args, Command, FromArgMatches};
use std::marker::PhantomData;
use std::ops::Deref;

/// The values of one set of search options.
#[derive(Debug, Clone, PartialEq)]
pub struct SearchArgs {
    pub population: usize,
    pub generations: usize,
    pub f: f64,
    pub cr: f64,
    pub strategy: Strategy,
    pub seed: u64,
    /// Renders at once; `None`: the renderer's choice.
    pub jobs: Option<usize>,
    pub target_deviation: Option<f64>,
    pub stagnation: Option<usize>,
    pub phase_generations: Option<Vec<usize>>,
}

/// Which copy of the options: its flag prefix, help prefix and defaults.
pub trait Kind {
    /// Put before every flag name, e.g. "stage1-".
    const PREFIX: &'static str;
    /// Put before every help line, e.g. "Stage 1: ".
    const HELP: &'static str;
    const POPULATION: usize;
    const GENERATIONS: usize;
    const STRATEGY: &'static str;
    /// Whether `--target-deviation` and `--phase-generations` exist here.
    const ALL_STOPS: bool;
}

/// `fit`'s options: the paper's budget with the hybrid search, which
/// reaches a given deviation in a fraction of DE's renders
/// (docs/benchmarks.md); `--strategy rand1bin` is the paper's search.
#[derive(Debug, Clone)]
pub struct Fit;
impl Kind for Fit {
    const PREFIX: &'static str = "";
    const HELP: &'static str = "";
    const POPULATION: usize = 80;
    const GENERATIONS: usize = 500;
    const STRATEGY: &'static str = "hybrid";
    const ALL_STOPS: bool = true;
}

/// `demo`'s options: the paper's budget with SHADE, which reaches the
/// accuracy asked of the demo within that budget.
#[derive(Debug, Clone)]
pub struct Demo;
impl Kind for Demo {
    const PREFIX: &'static str = "";
    const HELP: &'static str = "";
    const POPULATION: usize = 80;
    const GENERATIONS: usize = 500;
    const STRATEGY: &'static str = "shade";
    const ALL_STOPS: bool = true;
}

/// The pipeline's stage 1: the paper's budget over the full bounds, with
/// the hybrid search as `fit`.
#[derive(Debug, Clone)]
pub struct Stage1;
impl Kind for Stage1 {
    const PREFIX: &'static str = "stage1-";
    const HELP: &'static str = "Stage 1: ";
    const POPULATION: usize = 80;
    const GENERATIONS: usize = 500;
    const STRATEGY: &'static str = "hybrid";
    const ALL_STOPS: bool = false;
}

/// The pipeline's stage 2: a smaller budget, as it only refines.
#[derive(Debug, Clone)]
pub struct Stage2;
impl Kind for Stage2 {
    const PREFIX: &'static str = "stage2-";
    const HELP: &'static str = "Stage 2: ";
    const POPULATION: usize = 24;
    const GENERATIONS: usize = 30;
    const STRATEGY: &'static str = "rand1bin";
    const ALL_STOPS: bool = false;
}

/// One copy of the search options, flattened into a command with
/// `#[command(flatten)]`; dereferences to its values.
#[derive(Debug, Clone)]
pub struct Search<K> {
    values: SearchArgs,
    kind: PhantomData<K>,
}

impl<K> Deref for Search<K> {
    type Target = SearchArgs;
    fn deref(&self) -> &SearchArgs {
        &self.values
    }
}

/// The option names, without prefix, in the order `--help` lists them.
const POPULATION: &str = "population";
const GENERATIONS: &str = "generations";
const F: &str = "f";
const CR: &str = "cr";
const STRATEGY: &str = "strategy";
const SEED: &str = "seed";
const JOBS: &str = "jobs";
const TARGET_DEVIATION: &str = "target-deviation";
const STAGNATION: &str = "stagnation";
const PHASE_GENERATIONS: &str = "phase-generations";

fn id<K: Kind>(name: &str) -> String {
    format!("{}{name}", K::PREFIX)
}

/// An option with its prefixed id and flag and its prefixed help.
fn arg<K: Kind>(name: &str, help: &str) -> Arg {
    Arg::new(id::<K>(name))
        .long(id::<K>(name))
        .value_name(name.to_uppercase().replace('-', "_"))
        .help(format!("{}{help}", K::HELP))
        // A negative number reaches the value parser, whose message names
        // the option, instead of being taken for an unknown flag.
        .allow_hyphen_values(true)
}

/// The one definition of the search options.
fn args<K: Kind>() -> Vec<Arg> {
    let mut v = vec![
        arg::<K>(POPULATION, "individuals per generation")
            .value_parser(super::numbers::positive_count)
            .default_value(K::POPULATION.to_string()),
        arg::<K>(GENERATIONS, "generations over all phases")
            .value_parser(super::numbers::positive_count)
            .default_value(K::GENERATIONS.to_string()),
        arg::<K>(F, "differential weight F (rand1bin)")
            .value_parser(super::numbers::number)
            .default_value("0.6"),
        arg::<K>(CR, "crossover rate CR (rand1bin)")
            .value_parser(super::numbers::number)
            .default_value("0.7"),
        arg::<K>(
            STRATEGY,
            "the strategy: rand1bin (the paper), jde, shade or hybrid",
        )
        .value_parser(|s: &str| s.parse::<Strategy>())
        .default_value(K::STRATEGY),
        arg::<K>(
            SEED,
            "seed of the search: the same seed gives the same result whatever --jobs is",
        )
        .value_parser(super::numbers::seed)
        .default_value("1"),
        arg::<K>(JOBS, "renders at once (default: the renderer's choice)")
            .value_parser(super::numbers::positive_count),
        arg::<K>(
            STAGNATION,
            "stop a phase after this many generations without improvement",
        )
        .value_parser(super::numbers::whole)
        .value_name("GENERATIONS"),
    ];
    if K::ALL_STOPS {
        v.push(
            arg::<K>(
                TARGET_DEVIATION,
                "stop once the average deviation (%) is at or below this",
            )
            .value_parser(super::numbers::number)
            .value_name("PERCENT"),
        );
        v.push(
            arg::<K>(
                PHASE_GENERATIONS,
                "generations per phase, e.g. 200,300 (default: an even split)",
            )
            .value_parser(super::numbers::positive_count)
            .value_name("GENERATIONS")
            .value_delimiter(',')
            .action(ArgAction::Append),
        );
    }
    v
}

/// Capitalises a help line that has no prefix ("individuals…" for `fit`).
fn capitalised(a: Arg) -> Arg {
    let Some(help) = a.get_help().map(|h| h.to_string()) else {
        return a;
    };
    let mut c = help.chars();
    match c.next() {
        Some(first) => a.help(first.to_uppercase().chain(c).collect::<String>()),
        None => a,
    }
}

impl<K: Kind> Args for Search<K> {
    fn augment_args(cmd: Command) -> Command {
        args::<K>()
            .into_iter()
            .fold(cmd, |cmd, a| cmd.arg(capitalised(a)))
    }
    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

impl<K: Kind> FromArgMatches for Search<K> {
    fn from_arg_matches(m: &ArgMatches) -> std::result::Result<Self, clap::Error> {
        let one = |name: &str| id::<K>(name);
        let values = SearchArgs {
            population: required(m, &one(POPULATION))?,
            generations: required(m, &one(GENERATIONS))?,
            f: required(m, &one(F))?,
            cr: required(m, &one(CR))?,
            strategy: required(m, &one(STRATEGY))?,
            seed: required(m, &one(SEED))?,
            jobs: m.get_one::<usize>(&one(JOBS)).copied(),
            stagnation: m.get_one::<usize>(&one(STAGNATION)).copied(),
            // Asking clap for an option it was not given panics: only ask
            // where the options exist.
            target_deviation: K::ALL_STOPS
                .then(|| m.get_one::<f64>(&one(TARGET_DEVIATION)).copied())
                .flatten(),
            phase_generations: K::ALL_STOPS
                .then(|| {
                    m.get_many::<usize>(&one(PHASE_GENERATIONS))
                        .map(|v| v.copied().collect())
                })
                .flatten(),
        };
        Ok(Search {
            values,
            kind: PhantomData,
        })
    }
    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> std::result::Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

/// A value that has a default, so is always there.
fn required<T: Clone + Send + Sync + 'static>(
    m: &ArgMatches,
    id: &str,
) -> std::result::Result<T, clap::Error> {
    m.get_one::<T>(id).cloned().ok_or_else(|| {
        clap::Error::raw(
            clap::error::ErrorKind::MissingRequiredArgument,
            format!("--{id}: no value"),
        )
    })
}

impl SearchArgs {
    /// The fit configuration, the options checked; `default_jobs` stands
    /// in for an absent `--jobs`.
    pub fn config(&self, default_jobs: usize) -> Result<FitConfig> {
        if self.jobs == Some(0) {
            return Err(Error::Usage("--jobs: expected 1 or more".into()));
        }
        if self.generations == 0 {
            return Err(Error::Usage(
                "--generations: expected 1 or more (a fit of no generation has no result)".into(),
            ));
        }
        if self
            .phase_generations
            .as_ref()
            .is_some_and(|v| v.contains(&0))
        {
            return Err(Error::Usage(
                "--phase-generations: expected 1 or more generations for every phase".into(),
            ));
        }
        if let Some(d) = self.target_deviation {
            if d.is_nan() || d < 0.0 {
                return Err(Error::Usage(format!(
                    "--target-deviation: expected a percentage >= 0, got {d}"
                )));
            }
        }
        let de = DeConfig {
            population: self.population,
            f: self.f,
            cr: self.cr,
            strategy: self.strategy,
            seed: self.seed,
        };
        de.validate().map_err(|e| Error::Usage(format!("{e}")))?;
        Ok(FitConfig {
            de,
            generations: self.generations,
            phase_generations: self.phase_generations.clone(),
            target_deviation: self.target_deviation,
            stagnation: self.stagnation,
            jobs: self.jobs.unwrap_or(default_jobs),
            ..FitConfig::default()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser, Debug)]
    struct Both {
        #[command(flatten)]
        fit: Search<Fit>,
        #[command(flatten)]
        s1: Search<Stage1>,
        #[command(flatten)]
        s2: Search<Stage2>,
    }

    #[test]
    fn each_copy_reads_its_own_prefixed_flags_and_defaults() {
        let b = Both::try_parse_from([
            "x",
            "--population",
            "10",
            "--stage1-population",
            "11",
            "--stage2-strategy",
            "jde",
            "--phase-generations",
            "2,3",
            "--stage1-jobs",
            "3",
        ])
        .unwrap();
        assert_eq!(b.fit.population, 10);
        assert_eq!(b.fit.phase_generations, Some(vec![2, 3]));
        assert_eq!(b.s1.population, 11);
        assert_eq!(b.s1.jobs, Some(3));
        assert_eq!(b.s1.generations, 500);
        assert_eq!(b.s2.population, 24);
        assert_eq!(b.s2.generations, 30);
        assert_eq!(b.s2.strategy, Strategy::Jde);
        assert_eq!(b.fit.strategy, Strategy::Hybrid);
        assert_eq!(b.s1.strategy, Strategy::Hybrid);
        assert_eq!(b.fit.jobs, None);
    }

    #[test]
    fn stages_have_no_fit_only_stop_rules() {
        assert!(Both::try_parse_from(["x", "--stage1-target-deviation", "1"]).is_err());
        assert!(Both::try_parse_from(["x", "--stage2-phase-generations", "1"]).is_err());
    }

    #[test]
    fn a_bad_strategy_is_refused() {
        assert!(Both::try_parse_from(["x", "--stage2-strategy", "nope"]).is_err());
    }
}
