//! One Levenberg–Marquardt run of the hybrid search ([`Local`]): from a
//! starting point, damped Gauss–Newton steps on the per-value residuals
//! with a second-order difference Jacobian, until the run stalls or the
//! global phase would gain more per render.
//!
//! **Two kinds of batch.** A Jacobian batch is a point and its 2P
//! neighbours, two per coordinate moved by that coordinate's difference
//! step (`lm::second_order` says why two); a trial batch is the one point the damped step proposes. The
//! Jacobian of a trial is asked for only once the trial has been accepted
//! (with the trial rendered again as the batch's centre, so that the
//! differences share its sampler seed and no residual vector has to be
//! kept between batches): a rejected trial costs one render, not 2P+1. On
//! a ridge, where the model is good along some directions and poor along
//! others, about half of the trials are rejected.
//!
//! **Damping.** Marquardt's scaling (`λ diag A`), with λ lowered after an
//! accepted step by how well the model predicted its gain (Nielsen's rule:
//! the ratio ρ of the actual to the predicted decrease) and, after a
//! rejected one, raised until the trial is at most half as far from the
//! point as the rejected one: on a nearly singular system the damping that
//! shortens a step spans many orders of magnitude, and a fixed factor from
//! a small λ gives back the same trial, paid for with another render.
//!
//! **Coarse to fine** (`pyramid.rs`). When a column of a sharp Jacobian
//! is noise, the run goes on at [`pyramid::BLUR_START`] pixels of blur:
//! its Jacobians, trials and acceptance all use the residuals of blurred
//! images (the sharp fitness is still what the hybrid keeps as the best).
//! What would end a run at a blurred level instead halves the blur and
//! asks for a Jacobian at the same point, down to the sharp level, where
//! the run ends as below. The difference steps are held while blurred:
//! the rule that steers them (`lm::adapt_step`) counts 8-bit levels.
//!
//! **End.** After [`STALL_STEPS`] steps in a row without a relative gain
//! of [`GAIN_TOLERANCE`] (rejected trials count), when the damping passes
//! [`LAMBDA_MAX`], or when the last [`RATE_WINDOW`] steps lowered the log
//! fitness per render less than the global phase did before the run.

use serde::{Deserialize, Serialize};

use super::lm::{self, Column, Normal};
use super::{exact, pyramid, Evaluation};

/// Local steps over which the local rate of progress is measured.
pub const RATE_WINDOW: usize = 3;
/// A step must lower the fitness by this fraction to count as progress.
pub const GAIN_TOLERANCE: f64 = 1e-5;
/// Steps in a row without progress that end a local run.
pub const STALL_STEPS: usize = 3;
/// Damping beyond which the step is too short to matter.
pub const LAMBDA_MAX: f64 = 1e8;

const LAMBDA_START: f64 = 1e-3;
const LAMBDA_MIN: f64 = 1e-9;
/// Nielsen's bounds on the change of λ after an accepted step.
const LAMBDA_DOWN: f64 = 1.0 / 3.0;
const LAMBDA_UP: f64 = 2.0;
/// How much shorter each trial after a rejected one is.
const SHORTEN: f64 = 0.5;

/// What the batch asked for is.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
enum Probe {
    /// A point (the start, or an accepted trial) and its P neighbours.
    Jacobian,
    /// One trial point.
    Trial,
}

/// One Levenberg–Marquardt run.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Local {
    /// The accepted point.
    #[serde(with = "exact::vector")]
    pub x: Vec<f64>,
    /// Its fitness (+inf until its batch has been told).
    #[serde(with = "exact::scalar")]
    pub fitness: f64,
    /// The fitness it started from.
    #[serde(with = "exact::scalar")]
    pub start_fitness: f64,
    /// Its normal equations (None until its batch has been told).
    pub normal: Option<Normal>,
    #[serde(with = "exact::scalar")]
    lambda: f64,
    /// Difference step per coordinate (unsigned).
    #[serde(with = "exact::vector")]
    pub steps: Vec<f64>,
    /// The batch asked for (see [`Probe`]).
    #[serde(with = "exact::matrix")]
    batch: Vec<Vec<f64>>,
    probe: Probe,
    /// The relative gain the model predicted for the trial asked for.
    #[serde(with = "exact::scalar")]
    predicted: f64,
    stalled: usize,
    /// Renders spent by this run.
    renders: usize,
    /// The accepted fitness and the renders spent after each step, oldest
    /// first, the last [`RATE_WINDOW`] + 1 of them.
    history: Vec<(u64, usize)>,
    /// The global phase's log fitness lowered per render, which the run
    /// must beat to go on.
    #[serde(with = "exact::scalar")]
    rate_floor: f64,
    /// Set when the run ended because the global phase was faster.
    pub outpaced: bool,
    /// Whether it started from the global best after a global stint that
    /// gained less than the hybrid's settled gain (the global phase is done
    /// there).
    pub global_done: bool,
    /// Each coordinate's period in unit coordinates, 0 if none (see
    /// `lm::wrap`; empty: none is periodic).
    #[serde(with = "exact::vector", default)]
    periods: Vec<f64>,
    /// The blur of the residuals the run minimises now, in pixels (0:
    /// sharp; see the module docs).
    #[serde(with = "exact::scalar", default)]
    pub blur: f64,
    /// The blurred merit of the accepted point while `blur` > 0
    /// (`pyramid::merit`); at the sharp level the fitness is the merit.
    #[serde(with = "exact::scalar", default = "unknown")]
    blurred_merit: f64,
    /// Set once the run found a sharp column to be noise (it then went
    /// coarse, and does not again).
    #[serde(default)]
    pub rough: bool,
}

/// A merit not yet measured.
fn unknown() -> f64 {
    f64::INFINITY
}

impl Local {
    /// A run from `x`, sharp: it goes coarse only on its own evidence
    /// (see the module docs).
    pub fn start(
        x: &[f64],
        steps: Vec<f64>,
        rate_floor: f64,
        global_done: bool,
        periods: &[f64],
    ) -> Local {
        // The same image, farther from the faces (see `lm::wrap`).
        let x = lm::wrap(x, periods);
        let batch = neighbourhood(&x, &steps);
        Local {
            x,
            fitness: f64::INFINITY,
            start_fitness: f64::INFINITY,
            normal: None,
            lambda: LAMBDA_START,
            steps,
            batch,
            probe: Probe::Jacobian,
            predicted: 0.0,
            stalled: 0,
            renders: 0,
            history: Vec::new(),
            rate_floor,
            outpaced: false,
            global_done,
            periods: periods.to_vec(),
            blur: 0.0,
            blurred_merit: f64::INFINITY,
            rough: false,
        }
    }

    /// What the run minimises at its level, for one evaluation: the
    /// fitness when sharp, the blurred residuals' merit otherwise.
    fn merit_of(&self, evaluation: &Evaluation) -> f64 {
        if self.blur > 0.0 {
            pyramid::merit(evaluation.residuals.as_deref())
        } else {
            evaluation.fitness
        }
    }

    /// The accepted point's merit at the run's level.
    fn merit(&self) -> f64 {
        if self.blur > 0.0 {
            self.blurred_merit
        } else {
            self.fitness
        }
    }

    /// The points to evaluate next.
    pub fn batch(&self) -> &[Vec<f64>] {
        &self.batch
    }

    /// Whether the batch's shapes fit dimension `dim`.
    pub fn fits(&self, dim: usize) -> bool {
        let expected = match self.probe {
            Probe::Jacobian => 2 * dim + 1,
            Probe::Trial => 1,
        };
        self.x.len() == dim
            && self.steps.len() == dim
            && (self.periods.is_empty() || self.periods.len() == dim)
            && self.batch.len() == expected
            && self.batch.iter().all(|p| p.len() == dim)
    }

    /// The trial asked for, with its fitness, when the batch is a trial
    /// (the hybrid sees a trial's fitness before its Jacobian is asked).
    pub fn trial<'a>(&'a self, evaluations: &[Evaluation]) -> Option<(&'a [f64], f64)> {
        (self.probe == Probe::Trial).then(|| (&self.batch[0][..], evaluations[0].fitness))
    }

    /// Takes the evaluations of the batch; returns false when the run ended.
    pub fn tell(&mut self, evaluations: &[Evaluation]) -> bool {
        self.renders += evaluations.len();
        match self.probe {
            Probe::Jacobian => {
                if !self.tell_jacobian(evaluations) {
                    return false;
                }
                if self.coarsen(evaluations) {
                    return true;
                }
                self.next_trial()
            }
            Probe::Trial => self.tell_trial(&evaluations[0]),
        }
    }

    /// The centre's fitness and normal equations; the difference steps
    /// adapted to the changes they made.
    fn tell_jacobian(&mut self, evaluations: &[Evaluation]) -> bool {
        let centre = &evaluations[0];
        let Some(r) = centre.residuals.as_deref() else {
            return false;
        };
        let p = self.x.len();
        let differences: Vec<(Option<Vec<f32>>, f64)> = (0..p)
            .map(|j| {
                let at = |k: usize| {
                    let offset = self.batch[k][j] - self.batch[0][j];
                    (evaluations[k].residuals.as_deref(), offset)
                };
                column(r, at(1 + j), at(1 + p + j))
            })
            .collect();
        let columns: Vec<Column> = differences
            .iter()
            .map(|(residuals, step)| Column {
                residuals: residuals.as_deref(),
                step: *step,
            })
            .collect();
        let normal = lm::normal_equations(r, &columns);
        if self.blur == 0.0 {
            for (j, step) in self.steps.iter_mut().enumerate() {
                *step = lm::adapt_step(*step, r, evaluations[j + 1].residuals.as_deref());
            }
        }
        self.blurred_merit = pyramid::merit(Some(r));
        let fitness = if centre.fitness.is_finite() {
            centre.fitness
        } else {
            f64::INFINITY
        };
        if self.normal.is_none() {
            // The starting point itself: nothing to compare with yet.
            self.start_fitness = fitness;
        }
        self.x = self.batch[0].clone();
        self.fitness = fitness;
        self.normal = Some(normal);
        self.record();
        fitness.is_finite()
    }

    /// Accepts or rejects the trial; an accepted one's Jacobian is asked
    /// for next.
    fn tell_trial(&mut self, evaluation: &Evaluation) -> bool {
        if evaluation.fitness == 0.0 && self.fitness > 0.0 {
            // Nothing is left to gain: no Jacobian is worth its renders.
            self.x = self.batch[0].clone();
            self.fitness = 0.0;
            return false;
        }
        let (merit, current) = (self.merit_of(evaluation), self.merit());
        if merit < current {
            let gain = (current - merit) / current;
            self.stalled = if gain > GAIN_TOLERANCE {
                0
            } else {
                self.stalled + 1
            };
            // Nielsen's rule: keep the damping where the model predicted
            // the gain poorly, lower it where it predicted well.
            let rho = gain / self.predicted;
            let factor = if rho.is_finite() {
                (1.0 - (2.0 * rho - 1.0).powi(3)).clamp(LAMBDA_DOWN, LAMBDA_UP)
            } else {
                LAMBDA_DOWN
            };
            self.lambda = (self.lambda * factor).max(LAMBDA_MIN);
            self.probe = Probe::Jacobian;
            self.batch = neighbourhood(&self.batch[0], &self.steps);
            return true;
        }
        self.stalled += 1;
        self.record();
        let rejected = distance(&self.batch[0], &self.x, &self.periods);
        if let Some(normal) = &self.normal {
            // Raise the damping until the trial is clearly shorter.
            while self.lambda <= LAMBDA_MAX {
                self.lambda *= LAMBDA_UP;
                match lm::bounded_trial(normal, self.lambda, &self.x, &self.periods) {
                    Some(t) if distance(&t, &self.x, &self.periods) > SHORTEN * rejected => {
                        continue
                    }
                    _ => break,
                }
            }
        }
        self.next_trial()
    }

    /// Appends the accepted merit after a step to the history.
    fn record(&mut self) {
        self.history.push((self.merit().to_bits(), self.renders));
        if self.history.len() > RATE_WINDOW + 1 {
            self.history.remove(0);
        }
    }

    /// The next trial, unless the run has ended (see the module docs); a
    /// blurred level that would end goes on at the next level instead.
    fn next_trial(&mut self) -> bool {
        if self.fitness == 0.0 {
            return false;
        }
        match self.propose() {
            Some(trial) => {
                self.batch = vec![trial];
                self.probe = Probe::Trial;
                true
            }
            None if self.blur > 0.0 => {
                self.set_level(pyramid::next_level(self.blur));
                true
            }
            None => false,
        }
    }

    /// The damped step's trial at this level, or None when the level has
    /// ended (see the module docs).
    fn propose(&mut self) -> Option<Vec<f64>> {
        if self.merit() == 0.0 || self.stalled >= STALL_STEPS || self.lambda > LAMBDA_MAX {
            return None;
        }
        if self.slower_than_global() {
            // Only the sharp level's pace is the run's.
            self.outpaced = self.blur == 0.0;
            return None;
        }
        let normal = self.normal.as_ref()?;
        let trial = lm::bounded_trial(normal, self.lambda, &self.x, &self.periods)?;
        self.predicted = lm::predicted_gain(normal, &self.x, &trial, &self.periods);
        Some(trial)
    }

    /// Goes on at blur `blur` from the accepted point: a fresh Jacobian
    /// there, the damping and the stall count as at a start.
    fn set_level(&mut self, blur: f64) {
        self.blur = blur;
        self.blurred_merit = f64::INFINITY;
        self.stalled = 0;
        self.lambda = LAMBDA_START;
        self.history.clear();
        self.batch = neighbourhood(&self.x, &self.steps);
        self.probe = Probe::Jacobian;
    }

    /// After a sharp Jacobian: when one of its resolved columns is noise
    /// (`pyramid::rough`) and the run has not been coarse yet, it goes to
    /// the coarsest level; returns whether it did.
    fn coarsen(&mut self, evaluations: &[Evaluation]) -> bool {
        if self.blur > 0.0 || self.rough {
            return false;
        }
        let Some(r) = evaluations[0].residuals.as_deref() else {
            return false;
        };
        let p = self.x.len();
        let agreements: Vec<f64> = (0..p)
            .filter_map(|j| {
                let a = evaluations[1 + j].residuals.as_deref()?;
                let b = evaluations[1 + p + j].residuals.as_deref()?;
                let s = self.batch[1 + j][j] - self.batch[0][j];
                let t = self.batch[1 + p + j][j] - self.batch[0][j];
                if !lm::resolved(s.abs(), r, Some(a)) {
                    return None;
                }
                pyramid::agreement(r, (a, s), (b, t))
            })
            .collect();
        if !pyramid::rough(&agreements) {
            return false;
        }
        self.rough = true;
        self.set_level(pyramid::BLUR_START);
        true
    }

    /// Whether the last [`RATE_WINDOW`] steps lowered the log fitness per
    /// render less than the global phase did.
    fn slower_than_global(&self) -> bool {
        if self.history.len() <= RATE_WINDOW {
            return false;
        }
        let (then, renders_then) = self.history[0];
        let (now, renders_now) = self.history[self.history.len() - 1];
        let renders = (renders_now - renders_then).max(1) as f64;
        let rate = (f64::from_bits(then) / f64::from_bits(now)).ln() / renders;
        rate < self.rate_floor
    }
}

/// Euclidean distance in the unit cube, a periodic coordinate's the
/// shortest way round.
fn distance(a: &[f64], b: &[f64], periods: &[f64]) -> f64 {
    lm::offset(a, b, periods)
        .iter()
        .map(|d| d * d)
        .sum::<f64>()
        .sqrt()
}

/// One column's difference from the neighbours' residuals and offsets:
/// second-order when both rendered, forward from the one that did
/// otherwise (None: a zero column).
fn column(
    r: &[f32],
    (a, first): (Option<&[f32]>, f64),
    (b, second): (Option<&[f32]>, f64),
) -> (Option<Vec<f32>>, f64) {
    let (a, b) = (
        a.filter(|d| d.len() == r.len()),
        b.filter(|d| d.len() == r.len()),
    );
    let distinct = second != 0.0 && second != first;
    match (a, b) {
        (Some(a), Some(b)) if distinct => (Some(lm::second_order(r, a, first, b, second)), first),
        (Some(a), _) => (Some(a.to_vec()), first),
        (None, Some(b)) => (Some(b.to_vec()), second),
        (None, None) => (None, first),
    }
}

/// `x`, then `x` moved along each axis by its step `h`, then by a second
/// offset: `x ± h` inside the cube, `x + h, x + 2h` at the lower face and
/// `x − h, x − 2h` at the upper one (see [`lm::second_order`]).
fn neighbourhood(x: &[f64], steps: &[f64]) -> Vec<Vec<f64>> {
    let mut first = Vec::with_capacity(x.len());
    let mut second = Vec::with_capacity(x.len());
    for (j, &h) in steps.iter().enumerate() {
        let (a, b) = if x[j] - h < 0.0 {
            (x[j] + h, x[j] + 2.0 * h)
        } else if x[j] + h > 1.0 {
            (x[j] - h, x[j] - 2.0 * h)
        } else {
            (x[j] + h, x[j] - h)
        };
        let mut moved = x.to_vec();
        moved[j] = a;
        first.push(moved.clone());
        moved[j] = b.clamp(0.0, 1.0);
        second.push(moved);
    }
    let mut batch = vec![x.to_vec()];
    batch.extend(first);
    batch.extend(second);
    batch
}
