//! A global search that hands over to a local one and back: SHADE until
//! its best point looks worth polishing, then Levenberg–Marquardt on the
//! per-value residuals from that point, then SHADE again with the local
//! result in its population, and so on until the executor's budget or
//! target ends the run ([`Hybrid`]).
//!
//! Why: DE spends most of its renders on the last digits, where the
//! objective is smooth and a Gauss–Newton step with a finite-difference
//! Jacobian (P+1 renders) does what many DE generations would; a local
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
//! **Local phase.** Each step asks for one batch of P+1 points: the trial
//! point and, per coordinate, the trial moved by that coordinate's
//! difference step. If the trial improves the fitness it becomes the
//! current point and its Jacobian is already known; if not, the damping
//! grows and the batch is redone from the current point's Jacobian (the P
//! differences of a rejected trial are the price of asking for one batch
//! per step, which keeps the executor's parallelism). The normal equations
//! are reweighted (IRLS) so the steps minimise the L1 deviation the fit
//! reports, and acceptance compares that same fitness. Bounds: a
//! coordinate on a face whose step points out of the cube is held fixed for
//! that step, the rest is projected into the cube; differences at the upper
//! face are taken backwards. Difference steps adapt per coordinate from the
//! change they produce (`lm::adapt_step`), since the images are 8-bit, and
//! carry over from one local run to the next.
//!
//! **Back to the global phase.** A local run ends when its last
//! [`RATE_WINDOW`] steps lowered the log fitness per render less than the
//! global phase did over its last stint (the population would do better),
//! after [`STALL_STEPS`] steps in a row without a relative gain of
//! [`GAIN_TOLERANCE`], or when the damping passes [`LAMBDA_MAX`]. Its point
//! then replaces the worst population member and SHADE goes on. The run
//! ends by the executor's budget or target; [`Search::converged`] is true
//! only when nothing can move any more: the fitness is 0, or a local run
//! gained nothing and the population has collapsed onto one point.
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
//!
//! Everything is deterministic (the only random numbers are SHADE's, drawn
//! from its seeded generator) and serialisable, floats bit-exact, so a run
//! resumed from a checkpoint in either phase continues identically.

use serde::{Deserialize, Serialize};

use super::identifiability::Identifiability;
use super::lm::{self, Column, Normal};
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
/// Local steps over which the local rate of progress is measured.
pub const RATE_WINDOW: usize = 3;
/// A step must lower the fitness by this fraction to count as progress.
pub const GAIN_TOLERANCE: f64 = 1e-5;
/// Steps in a row without progress that end a local run.
pub const STALL_STEPS: usize = 3;
/// Damping beyond which the step is too short to matter.
pub const LAMBDA_MAX: f64 = 1e8;
/// A local run from a population member other than the best starts only
/// this far (max-norm, unit cube) from every earlier start and end.
pub const START_SEPARATION: f64 = 0.05;
/// A settling run ends after a local run from the global best gaining less
/// than this fraction of its start's fitness (see the module docs).
pub const SETTLED_GAIN: f64 = 1e-3;
/// A settling run ends once this many local runs in a row from other
/// basins have not bettered the global best by [`SETTLED_GAIN`].
pub const SETTLE_TRIES: usize = 2;
/// Largest per-coordinate spread of a population collapsed onto one point.
const COLLAPSED: f64 = 1e-12;

const LAMBDA_START: f64 = 1e-3;
const LAMBDA_MIN: f64 = 1e-9;
const LAMBDA_DOWN: f64 = 1.0 / 3.0;
const LAMBDA_UP: f64 = 8.0;
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

/// One Levenberg–Marquardt run.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Local {
    /// The accepted point.
    #[serde(with = "exact::vector")]
    x: Vec<f64>,
    /// Its fitness (+inf until its batch has been told).
    #[serde(with = "exact::scalar")]
    fitness: f64,
    /// The fitness it started from.
    #[serde(with = "exact::scalar")]
    start_fitness: f64,
    /// Its normal equations (None until its batch has been told).
    normal: Option<Normal>,
    #[serde(with = "exact::scalar")]
    lambda: f64,
    /// Difference step per coordinate (unsigned).
    #[serde(with = "exact::vector")]
    steps: Vec<f64>,
    /// The batch asked for: trial first, then one neighbour per coordinate.
    #[serde(with = "exact::matrix")]
    batch: Vec<Vec<f64>>,
    stalled: usize,
    /// The accepted fitness after each step, oldest first, the last
    /// [`RATE_WINDOW`] + 1 of them.
    #[serde(with = "exact::vector")]
    history: Vec<f64>,
    /// The global phase's log fitness lowered per render, which the run
    /// must beat to go on.
    #[serde(with = "exact::scalar")]
    rate_floor: f64,
    /// Set when the run ended because the global phase was faster.
    outpaced: bool,
    /// Whether it started from the global best after a global stint that
    /// gained less than [`SETTLED_GAIN`] (the global phase is done there).
    #[serde(default)]
    global_done: bool,
}

impl Local {
    fn start(x: Vec<f64>, steps: Vec<f64>, rate_floor: f64, global_done: bool) -> Local {
        let batch = neighbourhood(&x, &steps);
        Local {
            x,
            fitness: f64::INFINITY,
            start_fitness: f64::INFINITY,
            normal: None,
            lambda: LAMBDA_START,
            steps,
            batch,
            stalled: 0,
            history: Vec::new(),
            rate_floor,
            outpaced: false,
            global_done,
        }
    }

    /// Takes the evaluations of `batch`; returns false when the run ended.
    fn tell(&mut self, evaluations: &[Evaluation]) -> bool {
        let trial = self.batch[0].clone();
        let center = &evaluations[0];
        let normal = center.residuals.as_deref().map(|r| {
            let columns: Vec<Column> = (0..self.x.len())
                .map(|j| Column {
                    residuals: evaluations[j + 1].residuals.as_deref(),
                    step: self.batch[j + 1][j] - trial[j],
                })
                .collect();
            lm::normal_equations(r, &columns)
        });
        if let Some(r) = center.residuals.as_deref() {
            for (j, step) in self.steps.iter_mut().enumerate() {
                *step = lm::adapt_step(*step, r, evaluations[j + 1].residuals.as_deref());
            }
        }
        let fitness = if center.fitness.is_finite() {
            center.fitness
        } else {
            f64::INFINITY
        };
        let first = self.normal.is_none();
        if first {
            // The starting point itself: nothing to compare with yet.
            self.fitness = fitness;
            self.start_fitness = fitness;
            self.normal = normal;
            if self.normal.is_none() {
                return false;
            }
        } else if fitness < self.fitness && normal.is_some() {
            let gain = (self.fitness - fitness) / self.fitness;
            self.stalled = if gain > GAIN_TOLERANCE {
                0
            } else {
                self.stalled + 1
            };
            self.x = trial;
            self.fitness = fitness;
            self.normal = normal;
            self.lambda = (self.lambda * LAMBDA_DOWN).max(LAMBDA_MIN);
        } else {
            self.stalled += 1;
            self.lambda *= LAMBDA_UP;
        }
        self.history.push(self.fitness);
        if self.history.len() > RATE_WINDOW + 1 {
            self.history.remove(0);
        }
        if self.fitness == 0.0 || self.stalled >= STALL_STEPS || self.lambda > LAMBDA_MAX {
            return false;
        }
        if self.slower_than_global() {
            self.outpaced = true;
            return false;
        }
        match self.next_trial() {
            Some(next) => {
                self.batch = neighbourhood(&next, &self.steps);
                true
            }
            None => false,
        }
    }

    /// Whether the last [`RATE_WINDOW`] steps lowered the log fitness per
    /// render less than the global phase did.
    fn slower_than_global(&self) -> bool {
        if self.history.len() <= RATE_WINDOW {
            return false;
        }
        let renders = (RATE_WINDOW * (self.x.len() + 1)) as f64;
        let rate = (self.history[0] / self.fitness).ln() / renders;
        rate < self.rate_floor
    }

    /// The damped step from `x`, with coordinates on a face whose step
    /// would leave the cube held fixed; None when it does not move.
    fn next_trial(&self) -> Option<Vec<f64>> {
        lm::bounded_trial(self.normal.as_ref()?, self.lambda, &self.x)
    }
}

/// `x` followed by `x` moved along each axis by its step (backwards where
/// forwards would leave the cube).
fn neighbourhood(x: &[f64], steps: &[f64]) -> Vec<Vec<f64>> {
    let mut batch = Vec::with_capacity(x.len() + 1);
    batch.push(x.to_vec());
    for (j, &h) in steps.iter().enumerate() {
        let mut moved = x.to_vec();
        moved[j] = if x[j] + h <= 1.0 { x[j] + h } else { x[j] - h };
        batch.push(moved);
    }
    batch
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
        }
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
        self.starts.len()
    }

    /// Standard errors and correlations at the best point, in unit
    /// coordinates, from its Jacobian; `None` before the local phase has
    /// evaluated a Jacobian there (or if it is singular).
    pub fn identifiability(&self) -> Option<Identifiability> {
        Identifiability::from_normal(self.at_best.as_ref()?)
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
        self.starts.push(start.clone());
        // Only a stint after a local run counts: the first one began at
        // the first generation, not where the phases last agreed.
        let global_done = from_best
            && !self.ends.is_empty()
            && fitness >= self.stint_fitness * (1.0 - SETTLED_GAIN);
        self.phase = Phase::Local(Local::start(start, self.steps.clone(), rate, global_done));
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

    fn tell_local(&mut self, mut local: Local, evaluations: &[Evaluation]) {
        self.generation += 1;
        let going = local.tell(evaluations);
        if let Some(normal) = &local.normal {
            if self.observe(&local.x, local.fitness) || local.x == self.best {
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
        let gained = local.fitness < local.start_fitness;
        self.global.inject(&local.x, local.fitness);
        let stuck = !gained && collapsed(self.global.population(), self.global.fitness());
        let settled = self.settle && local.global_done && !local.outpaced && {
            let gain = 1.0 - local.fitness / local.start_fitness;
            let spreads = basin_spreads(self.global.population(), self.global.fitness());
            (gain.is_nan() || gain < SETTLED_GAIN) && found_basin(&spreads)
        };
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
            && self.starts.iter().chain(&self.ends).all(|s| s.len() == dim)
            && self.at_best.as_ref().is_none_or(normal_ok);
        if let Phase::Local(local) = &self.phase {
            ok &= local.x.len() == dim
                && local.steps.len() == dim
                && local.batch.len() == dim + 1
                && local.batch.iter().all(|p| p.len() == dim)
                && local.normal.as_ref().is_none_or(normal_ok);
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
        match &mut self.phase {
            Phase::Global => Search::ask(&mut self.global),
            Phase::Local(local) => Request {
                points: local.batch.clone(),
                residuals: true,
            },
            // Nothing left to try; an executor that asks anyway gets the
            // best point again, which changes nothing.
            Phase::Done => Request {
                points: vec![self.best.clone()],
                residuals: false,
            },
        }
    }

    /// # Panics
    /// If `evaluations` does not match the last request's length.
    fn tell(&mut self, evaluations: &[Evaluation]) {
        let expected = match &self.phase {
            Phase::Global => self.global.population().len(),
            Phase::Local(local) => local.batch.len(),
            Phase::Done => 1,
        };
        assert_eq!(
            evaluations.len(),
            expected,
            "tell() got {} evaluations for a request of {expected}",
            evaluations.len()
        );
        self.evaluations += evaluations.len();
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
        matches!(self.phase, Phase::Done)
    }

    fn population(&self) -> Option<(&[Vec<f64>], &[f64])> {
        match self.phase {
            Phase::Global => Some((self.global.population(), self.global.fitness())),
            _ => None,
        }
    }
}
