//! A global search that hands over to a local one and back: SHADE until
//! its best point looks worth polishing, then Levenberg–Marquardt on the
//! per-value residuals from that point, then SHADE again with the local
//! result in its population, and so on until the executor's budget or
//! target ends the run ([`Hybrid`]).
//!
//! Why: DE spends most of its renders on the last digits, where the
//! objective is smooth and a Gauss–Newton step with a finite-difference
//! Jacobian (2P+1 renders) does what many DE generations would; a local
//! method alone, though, sticks in whatever basin it starts in, and on
//! 8-bit images it stalls once the remaining differences are a few levels
//! on a few values, where the population still finds its way down.
//!
//! **Handover.** A local run is tried from the global best every
//! [`TRIAL_EVERY`] SHADE generations, or earlier once the better half of
//! the population sits in one basin (per-coordinate spread in the unit
//! cube: the largest below [`HANDOVER_SPREAD`], or three quarters of them,
//! [`HANDOVER_QUANTILE`], below [`HANDOVER_SPREAD_MOST`]), provided the
//! global best has improved on the best point a local run stalled at (else
//! the run would start where it stalled). If it has not, the periodic
//! trial starts instead from the best member farther than
//! [`START_SEPARATION`] from every earlier start and end: another basin,
//! which SHADE alone would take thousands of renders to bring below the
//! stalled one. A trial that fails costs a few batches of P+1 renders;
//! waiting for the spread alone meant waiting for the last coordinate the
//! image barely sees, thousands of renders.
//!
//! **Local phase** ([`Local`], `local.rs`). A trial is asked for alone
//! and its Jacobian (second-order differences: 2P+1 renders) only once it
//! is accepted, so a rejected trial costs one render. The normal equations
//! are reweighted (IRLS) so the steps minimise the L1 deviation the fit
//! reports, and acceptance compares that same fitness. Bounds by an
//! active set (`lm::bounded_trial`). Difference steps adapt per coordinate
//! from the change they produce (`lm::adapt_step`), since the images are
//! 8-bit, and carry over from one local run to the next. A periodic
//! coordinate (a hue, [`Hybrid::set_periods`]) steps round its circle
//! instead of stopping at a face (`lm::wrap`). When a run finds its
//! sharp difference columns noise, even one (edges that move in sample
//! steps), it descends blurred residuals first (`pyramid.rs`). Each run
//! decides at its own first sharp Jacobian: a landscape rough where the
//! population started may be smooth where a later run starts, and a
//! coarse descent there only spends renders (with every later run
//! starting coarse, glossy_effects reached 0.01 % in 2 of 10 seeds).
//!
//! **Back to the global phase.** A local run ends when its last few steps
//! lowered the log fitness per render less than the global phase did over
//! its last stint (the population would do better), or when it stalls
//! (see `local.rs`). Its point then replaces the worst population member
//! and SHADE goes on. The run ends by the executor's budget or target;
//! [`Search::converged`] is true only when nothing can move any more: the
//! fitness is 0, or a local run gained nothing and the population has
//! collapsed onto one point.
//!
//! **Restarts: a second opinion.** A population that has finished — its
//! fitness is 0, it has collapsed, or both phases agree it is done (a
//! local run from its best gained less than [`SETTLED_GAIN`] after a
//! stint that also did not, the better half in one basin) — may have
//! finished in the wrong basin: on a sharp landscape (a highlight of a few
//! pixels, a thin shadow) the first population can close on a basin
//! before any member has seen the true one, and a run that goes on from
//! there only polishes it. So a fresh population is drawn over the whole
//! cube (its own seed, derived from the run's), up to [`MAX_RESTARTS`]
//! times, until two populations have ended alike the best fitness
//! (`basins::alike`): the budget goes to evidence, not to a stall counter.
//! The best point, the places seen ([`Basins`]) and the difference steps
//! are kept; a population that then settles in a worse place gets the
//! best point injected, so the run goes on from there as before. A run
//! that reaches the executor's target ends first: on a smooth landscape
//! the restarts cost nothing. Two populations that end alike in distinct
//! places are what result.json's `alternatives` report.
//!
//! **Settling** ([`Hybrid::settle`], for refits that need an answer, not
//! a budget spent): the run also ends once both phases agree they are done
//! — a local run from the global best gained less than [`SETTLED_GAIN`],
//! after a global stint that also gained less than that, with the better
//! half of the population in one basin — or once the global best has
//! stood through [`SETTLE_TRIES`] local runs from other basins (or no
//! other basin is left to try). A local run stalling alone is not enough:
//! on 8-bit images it stalls in narrow valleys (a light's falloff against
//! its intensity and position) that the population still descends. And a
//! settling run hands over the first time only when the population has
//! found its basin, never periodically: a local run from an early best,
//! handed back, becomes the p-best every SHADE trial moves towards, so the
//! population follows it into its basin; a refit from scratch exists to
//! find another basin (with the periodic trial, a diagnosis's refits of a
//! light's falloff stopped at half the SAD drop SHADE alone reached).
//! A settling run draws no fresh population.
//!
//! Everything is deterministic (the only random numbers are SHADE's, drawn
//! from its seeded generator) and serialisable, floats bit-exact, so a run
//! resumed from a checkpoint in either phase continues identically.

use serde::{Deserialize, Serialize};

use super::basins::{alike, Basins};
use super::identifiability::Identifiability;
use super::lm::Normal;
use super::local::Local;
use super::swaps::Swaps;
use super::{exact, De, DeConfig, Evaluation, Progress, Request, Search, Strategy};

/// Hand over when the largest per-coordinate spread is below
/// [`HANDOVER_SPREAD`], or when this quantile of them is below
/// [`HANDOVER_SPREAD_MOST`].
pub const HANDOVER_QUANTILE: f64 = 0.75;
/// See [`HANDOVER_QUANTILE`].
pub const HANDOVER_SPREAD_MOST: f64 = 0.03;
/// Largest per-coordinate standard deviation in the unit cube (uniform is
/// 0.29) at which the local phase starts.
pub const HANDOVER_SPREAD: f64 = 0.1;
/// SHADE generations after which a local run is tried even if the spread
/// test has not handed over.
pub const TRIAL_EVERY: usize = 10;
/// A local run from a population member other than the best starts only
/// this far (max-norm, unit cube) from every earlier start and end.
pub const START_SEPARATION: f64 = 0.05;
/// A settling run ends after a local run from the global best gaining less
/// than this fraction of its start's fitness (see the module docs).
pub const SETTLED_GAIN: f64 = 1e-3;
/// A settling run ends once this many local runs in a row from other
/// basins have not bettered the global best by [`SETTLED_GAIN`].
pub const SETTLE_TRIES: usize = 2;
/// Fresh populations drawn at most, one after another, to confirm where
/// the first one ended (see the module docs).
pub const MAX_RESTARTS: usize = 3;
/// A restart's seed: the run's seed plus this times the restart's number,
/// so that each population is independent and every run repeatable.
const RESTART_SEED_STEP: u64 = 0x9E37_79B9_7F4A_7C15;
/// Largest per-coordinate spread of a population collapsed onto one point.
const COLLAPSED: f64 = 1e-12;

const STEP_START: f64 = 0.01;

/// SHADE handing over to Levenberg–Marquardt and back; see the module docs.
///
/// Deserialising checks the shapes the search indexes by, so a damaged
/// checkpoint is an error, never a later panic.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(remote = "Self")]
pub struct Hybrid {
    #[serde(with = "exact::config")]
    config: DeConfig,
    dim: usize,
    /// The global phase; paused while a local run goes.
    global: De,
    phase: Phase,
    generation: usize,
    evaluations: usize,
    progress: Progress,
    #[serde(with = "exact::vector")]
    best: Vec<f64>,
    #[serde(with = "exact::scalar")]
    best_fitness: f64,
    /// Where the last local run ended (+inf before the first).
    #[serde(with = "exact::scalar")]
    local_end: f64,
    /// Whether it ended only because the global phase was faster (so it
    /// may go on from there if the global phase then is not).
    outpaced: bool,
    /// When the current global stint began: SHADE's generation, this
    /// search's evaluations, and the global best.
    stint_generation: usize,
    stint_evaluations: usize,
    #[serde(with = "exact::scalar")]
    stint_fitness: f64,
    /// Difference steps, kept from one local run to the next.
    #[serde(with = "exact::vector")]
    steps: Vec<f64>,
    /// Where local runs started, and where they ended.
    #[serde(with = "exact::matrix")]
    starts: Vec<Vec<f64>>,
    #[serde(with = "exact::matrix")]
    ends: Vec<Vec<f64>>,
    /// The normal equations at the best point, once the local phase has
    /// evaluated it.
    at_best: Option<Normal>,
    /// Whether the run ends once settled (see the module docs).
    #[serde(default)]
    settle: bool,
    /// Local runs from other basins since one bettered the global best.
    #[serde(default)]
    fresh_tries: usize,
    /// Each coordinate's period in unit coordinates, 0 if none (a hue;
    /// see [`Hybrid::set_periods`]); empty: none is periodic.
    #[serde(with = "exact::vector", default)]
    periods: Vec<f64>,
    /// Distinct places that fit alike the best (result.json's
    /// `alternatives`).
    #[serde(default)]
    basins: Basins,
    /// The fitness each population ended at, one per population drawn so
    /// far that has finished (see the module docs).
    #[serde(with = "exact::vector", default)]
    population_ends: Vec<f64>,
    /// Local runs of earlier populations.
    #[serde(default)]
    earlier_local_runs: usize,
    /// Declared interchangeable coordinates and the swapped points
    /// awaiting a render (`swaps.rs`).
    #[serde(default)]
    swaps: Swaps,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
// A search holds one phase, so the variants' size difference costs nothing.
#[allow(clippy::large_enum_variant)]
enum Phase {
    Global,
    Local(Local),
    Done,
}

/// The per-coordinate standard deviations of the better half of
/// `population`, smallest first (empty when fewer than two individuals
/// have been evaluated successfully).
pub fn basin_spreads(population: &[Vec<f64>], fitness: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..population.len())
        .filter(|&i| fitness[i].is_finite())
        .collect();
    order.sort_by(|&a, &b| fitness[a].total_cmp(&fitness[b]).then(a.cmp(&b)));
    order.truncate(population.len().div_ceil(2));
    if order.len() < 2 || population.is_empty() {
        return Vec::new();
    }
    let dim = population[0].len();
    let n = order.len() as f64;
    let mut spreads: Vec<f64> = (0..dim)
        .map(|j| {
            let mean = order.iter().map(|&i| population[i][j]).sum::<f64>() / n;
            let var = order
                .iter()
                .map(|&i| (population[i][j] - mean).powi(2))
                .sum::<f64>()
                / n;
            var.sqrt()
        })
        .collect();
    spreads.sort_by(f64::total_cmp);
    spreads
}

/// Whether the population has found its basin (see the module docs).
fn found_basin(spreads: &[f64]) -> bool {
    let Some(&largest) = spreads.last() else {
        return false;
    };
    let at = ((HANDOVER_QUANTILE * spreads.len() as f64).ceil() as usize).clamp(1, spreads.len());
    largest < HANDOVER_SPREAD || spreads[at - 1] < HANDOVER_SPREAD_MOST
}

/// Whether every coordinate of the finite-fitness population has (nearly)
/// one value: differential mutation can then no longer move it.
fn collapsed(population: &[Vec<f64>], fitness: &[f64]) -> bool {
    let Some(first) = population.iter().zip(fitness).find(|(_, f)| f.is_finite()) else {
        return true;
    };
    population
        .iter()
        .zip(fitness)
        .filter(|(_, f)| f.is_finite())
        .all(|(x, _)| {
            x.iter()
                .zip(first.0)
                .all(|(a, b)| (a - b).abs() <= COLLAPSED)
        })
}

impl Hybrid {
    /// A hybrid search whose global phase is `global` (a SHADE [`De`]);
    /// `config` is the run's config (strategy [`Strategy::Hybrid`]).
    pub fn new(global: De, config: &DeConfig) -> Hybrid {
        let dim = global.dim();
        let best = global.best().0.to_vec();
        let mut config = config.sanitized();
        config.strategy = Strategy::Hybrid;
        Hybrid {
            config,
            dim,
            global,
            phase: Phase::Global,
            generation: 0,
            evaluations: 0,
            progress: Progress::default(),
            best,
            best_fitness: f64::INFINITY,
            local_end: f64::INFINITY,
            outpaced: false,
            stint_generation: 0,
            stint_evaluations: 0,
            stint_fitness: f64::INFINITY,
            steps: vec![STEP_START; dim],
            starts: Vec::new(),
            ends: Vec::new(),
            at_best: None,
            settle: false,
            fresh_tries: 0,
            periods: Vec::new(),
            basins: Basins::default(),
            population_ends: Vec::new(),
            earlier_local_runs: 0,
            swaps: Swaps::default(),
        }
    }

    /// Declares periodic coordinates: `periods[j]` is coordinate j's
    /// period in unit coordinates (0: not periodic), as for a hue searched
    /// over an interval that overlaps itself. The local phase then steps
    /// round the circle instead of stopping at a face (`lm::wrap`). A
    /// vector of the wrong length is ignored.
    pub fn set_periods(&mut self, periods: Vec<f64>) {
        if periods.len() == self.dim {
            self.periods = periods;
        }
    }

    /// Declares coordinate permutations that may render the same image
    /// (see `swaps.rs`): where a local run ends alike the best, its
    /// swapped points are rendered too and may be reported as
    /// alternatives.
    pub fn set_swaps(&mut self, perms: Vec<Vec<usize>>) {
        self.swaps.declare(self.dim, perms);
    }

    /// Ends the run once it has settled (see the module docs) rather than
    /// only by the executor's budget or target.
    pub fn settle(&mut self) {
        self.settle = true;
    }

    /// The config in use.
    pub fn config(&self) -> &DeConfig {
        &self.config
    }

    /// Whether a local run has started (the search may be back in its
    /// global phase since).
    pub fn is_local(&self) -> bool {
        !self.starts.is_empty()
    }

    /// Local runs started so far.
    pub fn local_runs(&self) -> usize {
        self.earlier_local_runs + self.starts.len()
    }

    /// Populations drawn after the first (see the module docs).
    pub fn restarts(&self) -> usize {
        self.population_ends
            .len()
            .saturating_sub(1)
            .min(MAX_RESTARTS)
    }

    /// Whether a finished population (ended at `fitness`) calls for a
    /// fresh one: fewer than two populations have ended alike the best,
    /// and the restarts are not used up.
    fn restart_due(&mut self, fitness: f64) -> bool {
        self.population_ends.push(fitness);
        let agreeing = self
            .population_ends
            .iter()
            .filter(|&&f| alike(self.best_fitness, f))
            .count();
        agreeing < 2 && self.population_ends.len() <= MAX_RESTARTS
    }

    /// Draws a fresh population over the whole cube; the best point, the
    /// places seen and the difference steps stay.
    fn restart(&mut self) {
        let mut config = self.config.clone();
        config.strategy = Strategy::Shade;
        let n = self.population_ends.len() as u64;
        config.seed = config.seed.wrapping_add(n.wrapping_mul(RESTART_SEED_STEP));
        self.global = De::new(self.dim, config);
        self.earlier_local_runs += self.starts.len();
        self.starts.clear();
        self.ends.clear();
        self.local_end = f64::INFINITY;
        self.outpaced = false;
        self.stint_fitness = f64::INFINITY;
        self.fresh_tries = 0;
        self.phase = Phase::Global;
    }

    /// Standard errors and correlations at the best point, in unit
    /// coordinates, from its Jacobian; `None` before the local phase has
    /// evaluated a Jacobian there (or if it is singular).
    pub fn identifiability(&self) -> Option<Identifiability> {
        Identifiability::from_normal(self.at_best.as_ref()?)
    }

    /// Other places seen that fit alike the best, in unit coordinates,
    /// best first, with their fitness (see `basins.rs`).
    pub fn alternatives(&self) -> Vec<(Vec<f64>, f64)> {
        self.basins.alternatives(&self.best, self.best_fitness)
    }

    fn observe(&mut self, point: &[f64], fitness: f64) -> bool {
        if fitness < self.best_fitness {
            self.best_fitness = fitness;
            self.best = point.to_vec();
            return true;
        }
        false
    }

    fn tell_global(&mut self, evaluations: &[Evaluation]) {
        let before = self.global.generation();
        Search::tell(&mut self.global, evaluations);
        // The initial population is generation 0, as in SHADE alone.
        if self.global.generation() > before {
            self.generation += 1;
        }
        let (point, fitness) = self.global.best();
        let point = point.to_vec();
        self.observe(&point, fitness);
        if !self.stint_fitness.is_finite() {
            // The first generation with a success starts the stint.
            self.stint_generation = self.global.generation();
            self.stint_evaluations = self.evaluations;
            self.stint_fitness = fitness;
        }
        let due = found_basin(&basin_spreads(
            self.global.population(),
            self.global.fitness(),
        ));
        // A settling run's first local run waits for the population's own
        // basin (see the module docs).
        let patient = self.settle && self.starts.is_empty();
        let periodic = !patient && self.global.generation() >= self.stint_generation + TRIAL_EVERY;
        if !(fitness.is_finite() && (due || periodic)) {
            return;
        }
        let from_best = fitness < self.local_end || self.outpaced;
        let start = if from_best {
            point
        } else if periodic {
            // The best point is where a local run stalled: try the best
            // member of another basin, if the population still has one.
            let fresh = self.fresh_point();
            if self.settle && (fresh.is_none() || self.fresh_tries >= SETTLE_TRIES) {
                self.phase = Phase::Done;
                return;
            }
            match fresh {
                Some(other) => {
                    self.fresh_tries += 1;
                    other
                }
                None => return,
            }
        } else {
            return;
        };
        let renders = (self.evaluations - self.stint_evaluations).max(1) as f64;
        let rate = if fitness > 0.0 && self.stint_fitness.is_finite() {
            (self.stint_fitness / fitness).ln() / renders
        } else {
            0.0
        };
        // Only a stint after a local run counts: the first one began at
        // the first generation, not where the phases last agreed.
        let global_done = from_best
            && !self.ends.is_empty()
            && fitness >= self.stint_fitness * (1.0 - SETTLED_GAIN);
        self.phase = Phase::Local(Local::start(
            &start,
            self.steps.clone(),
            rate,
            global_done,
            &self.periods,
        ));
        self.starts.push(start);
    }

    /// The best population member farther than [`START_SEPARATION`]
    /// (max-norm) from every local run's start and end.
    fn fresh_point(&self) -> Option<Vec<f64>> {
        let population = self.global.population();
        let fitness = self.global.fitness();
        let mut order: Vec<usize> = (0..population.len())
            .filter(|&i| fitness[i].is_finite())
            .collect();
        order.sort_by(|&a, &b| fitness[a].total_cmp(&fitness[b]).then(a.cmp(&b)));
        let far = |candidate: &[f64], seen: &[f64]| {
            seen.iter()
                .zip(candidate)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
                > START_SEPARATION
        };
        order
            .into_iter()
            .map(|i| &population[i])
            .find(|c| self.starts.iter().chain(&self.ends).all(|s| far(c, s)))
            .cloned()
    }

    /// The swapped points rendered: each is a place seen (and the best,
    /// if better); the phase goes on where it was.
    fn tell_swaps(&mut self, evaluations: &[Evaluation]) {
        for (point, e) in self.swaps.take().iter().zip(evaluations) {
            self.observe(point, e.fitness);
            self.basins.offer(point, e.fitness, self.best_fitness);
        }
        self.progress.observe(self.generation, self.best_fitness);
    }

    fn tell_local(&mut self, mut local: Local, evaluations: &[Evaluation]) {
        self.generation += 1;
        // A trial better than the best counts at once: the target may be
        // reached before its Jacobian is rendered.
        let trial = local.trial(evaluations).map(|(p, f)| (p.to_vec(), f));
        if let Some((point, fitness)) = &trial {
            self.observe(point, *fitness);
        }
        let going = local.tell(evaluations);
        // The normal equations belong to the run's point only after a
        // Jacobian batch, and say how well the fit is determined only
        // when sharp.
        let sharp = local.blur == 0.0;
        if let (Some(normal), None) = (&local.normal, &trial) {
            if (self.observe(&local.x, local.fitness) || local.x == self.best) && sharp {
                self.at_best = Some(normal.clone());
            }
        }
        if going {
            self.phase = Phase::Local(local);
            return;
        }
        self.steps = local.steps.clone();
        if local.fitness < self.local_end * (1.0 - SETTLED_GAIN) {
            self.fresh_tries = 0;
        }
        // The best end so far is where the next run would stall again.
        self.outpaced = local.outpaced && local.fitness <= self.local_end;
        self.local_end = self.local_end.min(local.fitness);
        self.ends.push(local.x.clone());
        self.basins
            .offer(&local.x, local.fitness, self.best_fitness);
        if alike(self.best_fitness, local.fitness) {
            self.swaps.queue_from(&local.x);
        }
        let gained = local.fitness < local.start_fitness;
        self.global.inject(&local.x, local.fitness);
        let stuck = !gained && collapsed(self.global.population(), self.global.fitness());
        let agreed = local.global_done && !local.outpaced && {
            let gain = 1.0 - local.fitness / local.start_fitness;
            let spreads = basin_spreads(self.global.population(), self.global.fitness());
            (gain.is_nan() || gain < SETTLED_GAIN) && found_basin(&spreads)
        };
        let settled = self.settle && agreed;
        let finished = local.fitness == 0.0 || stuck || agreed;
        // A settling refit keeps its one population (see the module docs).
        if finished && !self.settle && self.restart_due(local.fitness) {
            self.restart();
            return;
        }
        if agreed && !self.settle && !alike(self.best_fitness, local.fitness) {
            // This population settled in a worse place: show it the best.
            self.global.inject(&self.best.clone(), self.best_fitness);
        }
        self.phase = if local.fitness == 0.0 || stuck || settled {
            Phase::Done
        } else {
            self.stint_generation = self.global.generation();
            self.stint_evaluations = self.evaluations;
            self.stint_fitness = self.global.best().1;
            Phase::Global
        };
    }
}

impl Serialize for Hybrid {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        Hybrid::serialize(self, serializer)
    }
}

impl<'de> Deserialize<'de> for Hybrid {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let hybrid = Hybrid::deserialize(deserializer)?;
        hybrid.check().map_err(serde::de::Error::custom)?;
        Ok(hybrid)
    }
}

impl Hybrid {
    fn check(&self) -> Result<(), String> {
        let dim = self.dim;
        let square = |m: &[Vec<f64>]| m.len() == dim && m.iter().all(|row| row.len() == dim);
        let normal_ok = |n: &Normal| square(&n.a) && square(&n.jtj) && n.g.len() == dim;
        let mut ok = self.global.dim() == dim
            && self.best.len() == dim
            && self.steps.len() == dim
            && (self.periods.is_empty() || self.periods.len() == dim)
            && self.starts.iter().chain(&self.ends).all(|s| s.len() == dim)
            && self.basins.fits(dim)
            && self.swaps.fits(dim)
            && self.at_best.as_ref().is_none_or(normal_ok);
        if let Phase::Local(local) = &self.phase {
            ok &= local.fits(dim) && local.normal.as_ref().is_none_or(normal_ok);
        }
        if ok {
            Ok(())
        } else {
            Err(format!("hybrid search state does not fit dimension {dim}"))
        }
    }
}

impl Search for Hybrid {
    fn ask(&mut self) -> Request {
        if let Some(points) = self.swaps.pending() {
            return Request {
                points: points.to_vec(),
                residuals: false,
                blur: 0.0,
            };
        }
        match &mut self.phase {
            Phase::Global => Search::ask(&mut self.global),
            Phase::Local(local) => Request {
                points: local.batch().to_vec(),
                residuals: true,
                blur: local.blur,
            },
            // Nothing left to try; an executor that asks anyway gets the
            // best point again, which changes nothing.
            Phase::Done => Request {
                points: vec![self.best.clone()],
                residuals: false,
                blur: 0.0,
            },
        }
    }

    /// # Panics
    /// If `evaluations` does not match the last request's length.
    fn tell(&mut self, evaluations: &[Evaluation]) {
        // The swapped ends, while pending, are what `ask` requested.
        let expected = if let Some(points) = self.swaps.pending() {
            points.len()
        } else {
            match &self.phase {
                Phase::Global => self.global.population().len(),
                Phase::Local(local) => local.batch().len(),
                Phase::Done => 1,
            }
        };
        assert_eq!(
            evaluations.len(),
            expected,
            "tell() got {} evaluations for a request of {expected}",
            evaluations.len()
        );
        self.evaluations += evaluations.len();
        if self.swaps.pending().is_some() {
            self.tell_swaps(evaluations);
            return;
        }
        match std::mem::replace(&mut self.phase, Phase::Done) {
            Phase::Global => {
                self.phase = Phase::Global;
                self.tell_global(evaluations);
            }
            Phase::Local(local) => self.tell_local(local, evaluations),
            Phase::Done => self.generation += 1,
        }
        self.progress.observe(self.generation, self.best_fitness);
    }

    fn best(&self) -> (&[f64], f64) {
        (&self.best, self.best_fitness)
    }

    fn generation(&self) -> usize {
        self.generation
    }

    fn evaluations(&self) -> usize {
        self.evaluations
    }

    fn progress(&self) -> &Progress {
        &self.progress
    }

    fn converged(&self) -> bool {
        matches!(self.phase, Phase::Done) && self.swaps.pending().is_none()
    }

    fn population(&self) -> Option<(&[Vec<f64>], &[f64])> {
        match self.phase {
            Phase::Global => Some((self.global.population(), self.global.fitness())),
            _ => None,
        }
    }
}
