//! One search of a fit run to its stop rule — a phase of one photograph's
//! fit, or a shared block of a set — with the run's observers
//! (progress.txt and snapshots, failures.log, the caller's), the state
//! saved after every generation, and a halt turned into the one line the
//! user sees.

use super::executor::{Executor, Halt, Offsets};
use super::observers::{Failures, Progress};
use super::problem::ShotsProblem;
use super::{FitConfig, Observer};
use crate::error::{Error, Result};
use crate::optimize::{Search, Searcher, StopReason, StopRule};
use crate::rundir::RunDir;

/// The observers that write into the run directory (none in memory).
pub struct Logs {
    progress: Option<Progress>,
    failures: Option<Failures>,
}

impl Logs {
    /// Opened once the run is ready to write: an overwriting run has
    /// removed the earlier run's files by then. A resumed run appends.
    pub fn open(dir: Option<&RunDir>, config: &FitConfig) -> Result<Logs> {
        let Some(dir) = dir else {
            return Ok(Logs {
                progress: None,
                failures: None,
            });
        };
        let fresh = config.mode != crate::rundir::Mode::Resume;
        Ok(Logs {
            progress: Some(Progress::new(dir, config.snapshot_every, fresh)?),
            failures: Some(Failures::new(dir)),
        })
    }

    /// Failed renders logged so far by this process.
    pub fn failed(&self) -> usize {
        self.failures.as_ref().map_or(0, |f| f.count)
    }
}

/// What a search runs under: its stop rule, the counters of what ran
/// before it, the run's options and directory.
pub struct SearchRun<'a> {
    pub rule: StopRule,
    pub offsets: Offsets,
    pub config: &'a FitConfig,
    pub dir: Option<&'a RunDir>,
}

impl SearchRun<'_> {
    /// Runs `search` (a new one, or a resumed one whose best point is
    /// rendered first) on `problem` to the stop rule; `save` is called after
    /// every generation, before any observer sees it (`Executor::run`).
    pub fn run(
        &self,
        problem: &mut ShotsProblem,
        search: &mut Searcher,
        logs: &mut Logs,
        observer: &mut dyn Observer,
        save: &mut dyn FnMut(&Searcher, f64) -> Result<()>,
    ) -> Result<StopReason> {
        // A resumed search's best images, which the problem reports and
        // the outcome keeps, are those of its best point.
        if search.evaluations() > 0 {
            let (best, f) = search.best();
            problem.adopt_best(best, f);
        }
        let mut observers: Vec<&mut dyn Observer> = Vec::new();
        if let Some(f) = logs.failures.as_mut() {
            observers.push(f);
        }
        if let Some(p) = logs.progress.as_mut() {
            observers.push(p);
        }
        observers.push(observer);
        let mut executor = Executor {
            rule: self.rule.clone(),
            interrupt: self.config.interrupt.clone(),
            observers,
        };
        let halt = match executor.run(problem, search, self.offsets, save) {
            Ok(reason) => return Ok(reason),
            Err(h) => h,
        };
        if let (Halt::AllFailed { failures, .. }, Some(log)) = (&halt, logs.failures.as_mut()) {
            log.record(failures)?;
        }
        Err(halt_error(halt, self.dir))
    }
}

/// A search that stopped without a result, as the error the user sees.
pub fn halt_error(halt: Halt, dir: Option<&RunDir>) -> Error {
    let place = match dir {
        Some(d) => format!(
            "the checkpoint in {} resumes the run (--resume)",
            d.path().display()
        ),
        None => "nothing was saved".into(),
    };
    match halt {
        Halt::Error(e) => e,
        Halt::Interrupted => Error::Run(format!("interrupted; {place}")),
        Halt::AllFailed {
            generation,
            failures,
        } => Error::Run(format!(
            "every render of generation {generation} failed; {place}. First failure: {}",
            failures.first().map(String::as_str).unwrap_or("?")
        )),
    }
}
