//! A fit: the scene's free parameters searched so that its renders match
//! one photograph or a set, each candidate rendered and compared with the
//! photographs (`problem`), the generation loop written once
//! (`executor`), one search run to its stop rule (`search_run`), logs as
//! observers (`observers`), and the outcome returned in memory — fitted
//! scene, best image, final population — as well as written into the run
//! directory (`output`, `crate::rundir`). A fit of a list of photographs
//! (one given on its own is a list of one) runs through the one fit path
//! in `set/` (`set::driver`): one state, saved as checkpoint.json, one
//! check of the inputs and of a resume.
//!
//! Data flows one way: parameter vector -> scene -> renderer -> image ->
//! metric -> optimizer.

mod config;
mod executor;
pub(crate) mod identity;
mod observers;
mod output;
mod problem;
mod search_run;
pub mod set;
mod swaps;
mod target;
pub(crate) mod uncertainty;

pub use config::{FitConfig, GenerationReport};
pub use executor::{Observer, Problem};
pub use output::{Alternative, FitOutcome, FitResult, HeldOutResult, Population};
pub use problem::{counted, render_seed};
pub use set::saved::load as load_state;
pub use set::state::FitState;
pub use target::FitTarget;
pub use uncertainty::{Correlation, Uncertainty};

use crate::error::Result;
use crate::render::Renderer;
use crate::rundir::RunDir;
use crate::scene::Scene;
use std::path::Path;

impl Observer for () {
    fn generation(&mut self, _: &GenerationReport) -> Result<()> {
        Ok(())
    }
}

/// Runs a fit of `scene` to `target` with `renderer`, in the run directory
/// `dir` (opened in `config.mode`), and returns its outcome.
pub fn run(
    scene: &Scene,
    target: &FitTarget,
    renderer: &dyn Renderer,
    config: &FitConfig,
    dir: &Path,
    observer: &mut dyn Observer,
) -> Result<FitOutcome> {
    let shots = [set::Shot::one(scene, target.clone())];
    let run_dir = set::driver::open(dir, &shots, true, config)?;
    run_in(scene, target, renderer, config, Some(&run_dir), observer)
}

/// Runs a fit in memory only: no file is written, nothing can be resumed
/// (the refits of a diagnosis).
pub fn run_in_memory(
    scene: &Scene,
    target: &FitTarget,
    renderer: &dyn Renderer,
    config: &FitConfig,
    observer: &mut dyn Observer,
) -> Result<FitOutcome> {
    run_in(scene, target, renderer, config, None, observer)
}

/// Fits `scene` to one photograph, `target`, in the run directory `dir`
/// (opened in `config.mode`) or (None) in memory only: a list of one
/// through the one fit path, phase after phase.
pub fn run_in(
    scene: &Scene,
    target: &FitTarget,
    renderer: &dyn Renderer,
    config: &FitConfig,
    dir: Option<&RunDir>,
    observer: &mut dyn Observer,
) -> Result<FitOutcome> {
    set::phase::run_one(scene, target, renderer, config, dir, observer)
}
