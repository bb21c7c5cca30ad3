//! The generation loop, written once: ask the search for a batch, have the
//! problem evaluate it, tell the search, save the checkpoint, then let the
//! observers see the generation, each at its own cadence. Stop rules, the
//! interrupt flag and the all-failed rule are checked here and nowhere
//! else (in the spirit of argmin's Executor).

use super::GenerationReport;
use crate::error::{Error, Result};
use crate::optimize::{Evaluation, Search, Searcher, StopReason, StopRule};
use crate::raster::Image;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// What the loop evaluates: a batch of unit-cube points, in order.
pub trait Problem {
    /// Evaluates `points`; residual vectors only when `residuals` is
    /// `Some(blur)`, of target and render blurred alike by a Gaussian of
    /// `blur` pixels (0: as rendered; see `metric::blur`). `generation`
    /// (counted over the whole run) seeds sampling renderers.
    fn evaluate(
        &mut self,
        points: &[Vec<f64>],
        residuals: Option<f64>,
        generation: usize,
    ) -> Vec<Evaluation>;
    /// Why each of the last batch's failed evaluations failed.
    fn failures(&self) -> &[String];
    /// The best image seen so far, if the problem keeps one.
    fn best_image(&self) -> Option<&Image>;
    /// The parameters of a unit-cube point, for reports.
    fn params(&self, point: &[f64]) -> serde_json::Map<String, serde_json::Value>;
    /// The deviation of the best image, for reports.
    fn best_deviation(&self) -> crate::metric::Deviation;
}

/// Receives every generation's news (or every `cadence`-th).
pub trait Observer {
    fn generation(&mut self, report: &GenerationReport) -> Result<()>;
    /// Report every this many generations (1: every one).
    fn cadence(&self) -> usize {
        1
    }
}

/// Counters carried over from earlier phases and earlier sessions of the run.
#[derive(Clone, Copy, Debug, Default)]
pub struct Offsets {
    pub generations: usize,
    pub evaluations: usize,
    pub seconds: f64,
    pub total_generations: usize,
    pub phase: u32,
}

/// Why the loop ended without a result.
pub enum Halt {
    /// The interrupt flag was set; the last checkpoint resumes the run.
    Interrupted,
    /// Every evaluation of a generation failed; why each did.
    AllFailed {
        generation: usize,
        failures: Vec<String>,
    },
    Error(Error),
}

impl From<Error> for Halt {
    fn from(e: Error) -> Halt {
        Halt::Error(e)
    }
}

/// Runs one search to its stop rule.
pub struct Executor<'a> {
    pub rule: StopRule,
    pub interrupt: Option<Arc<AtomicBool>>,
    pub observers: Vec<&'a mut dyn Observer>,
}

impl Executor<'_> {
    /// Runs `search` on `problem` until the rule stops it; `save` is called
    /// after every generation with the search and the seconds spent so far
    /// in this call, before any observer sees the generation, so that a run
    /// killed in between redoes no generation and logs nothing twice.
    pub fn run(
        &mut self,
        problem: &mut dyn Problem,
        search: &mut Searcher,
        offsets: Offsets,
        save: &mut dyn FnMut(&Searcher, f64) -> Result<()>,
    ) -> std::result::Result<StopReason, Halt> {
        let mut seconds = 0.0;
        // A phase that has not started yet is saved as it is, so that a
        // first generation that fails entirely or is interrupted leaves a
        // checkpoint to resume from.
        if search.evaluations() == 0 {
            save(search, 0.0)?;
        }
        loop {
            if let Some(reason) = self.rule.check(search) {
                return Ok(reason);
            }
            if self.interrupted() {
                return Err(Halt::Interrupted);
            }
            let started = Instant::now();
            let request = search.ask();
            let generation = offsets.generations + search.generation();
            let view = request.residuals.then_some(request.blur);
            let evaluations = problem.evaluate(&request.points, view, generation);
            // A batch cut short by an interrupt is not told: the search
            // stays as the checkpoint has it, and a resume redoes it.
            if self.interrupted() {
                return Err(Halt::Interrupted);
            }
            if evaluations.iter().all(|e| !e.fitness.is_finite()) {
                return Err(Halt::AllFailed {
                    generation,
                    failures: problem.failures().to_vec(),
                });
            }
            search.tell(&evaluations);
            seconds += started.elapsed().as_secs_f64();
            save(search, seconds)?;
            self.report(problem, search, &offsets, seconds)?;
        }
    }

    fn interrupted(&self) -> bool {
        self.interrupt
            .as_ref()
            .is_some_and(|f| f.load(Ordering::SeqCst))
    }

    fn report(
        &mut self,
        problem: &dyn Problem,
        search: &Searcher,
        offsets: &Offsets,
        seconds: f64,
    ) -> Result<()> {
        let generation = offsets.generations + search.generation();
        let evaluations = offsets.evaluations + search.evaluations();
        let elapsed = offsets.seconds + seconds;
        let report = GenerationReport {
            generation,
            total_generations: offsets.total_generations,
            evaluations,
            best: problem.best_deviation(),
            // Averaged over the run: one generation's rate jumps about.
            renders_per_second: evaluations as f64 / elapsed.max(1e-9),
            elapsed,
            phase: offsets.phase,
            failures: problem.failures(),
            params: problem.params(search.best().0),
            best_image: problem.best_image(),
        };
        for o in self.observers.iter_mut() {
            if generation.is_multiple_of(o.cadence().max(1)) {
                o.generation(&report)?;
            }
        }
        Ok(())
    }
}
