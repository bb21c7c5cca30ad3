//! What every step of a fit reads and calls, whatever the plan: the
//! run's inputs (`Run`), the plan itself (`Plan`: one photograph's phases
//! or a set's blocks) and the run directory's services a step calls
//! (`Steps`). A leaf of the fit path, so that the driver, the resume
//! checks and each plan can share it.

use super::shots::Shot;
use super::state::FitState;
use super::SetConfig;
use crate::error::Result;
use crate::fit::search_run::Logs;
use crate::fit::Observer;
use crate::render::Renderer;
use crate::rundir::RunDir;
use crate::scene::{ParamSpace, Scene};

/// A fit's inputs, as every step reads them.
pub struct Run<'a> {
    pub scene: &'a Scene,
    pub shots: &'a [Shot],
    pub renderer: &'a dyn Renderer,
    pub config: &'a SetConfig,
    pub dir: Option<&'a RunDir>,
    /// One photograph given on its own: fitted phase after phase, and
    /// written as one photograph's run (best.png); else a set's blocks.
    pub alone: bool,
    /// The scene's free parameters.
    pub space: ParamSpace,
    /// A set's photographs held out of the fit, predicted at its end
    /// (`held_out`).
    pub held_out: &'a [Shot],
}

/// How a fit proceeds: its steps in order, each run over the one state,
/// and its outcome. One photograph's phases (`phase::Phases`) and a set's
/// blocks (`set::Blocks`) are the two plans.
pub trait Plan {
    type Step: Copy;
    type Outcome;
    /// The steps in order (or why the options allow none).
    fn steps(&self, run: &Run) -> Result<Vec<Self::Step>>;
    /// Runs `step` and records it in `state` (`state.blocks_done` moves
    /// on, the state saved); the fit's outcome when the fit ends with it.
    fn step(
        &self,
        run: &Run,
        state: &mut FitState,
        step: Self::Step,
        plan: &[Self::Step],
        observer: &mut dyn Observer,
        io: &mut Steps,
    ) -> Result<Option<Self::Outcome>>;
    /// The outcome once every step has run.
    fn finish(&self, run: &Run, state: &FitState) -> Result<Self::Outcome>;
}

/// What a step calls besides its search: `clear` once it is ready to
/// write (an overwriting run removes the earlier run's files then), `save`
/// after each step it has finished (the state written, when there is a
/// run directory).
pub struct Steps<'a> {
    pub clear: &'a mut dyn FnMut() -> Result<()>,
    pub save: &'a mut dyn FnMut(&mut FitState) -> Result<()>,
    /// progress.txt and failures.log, opened by the first search.
    pub logs: &'a mut Option<Logs>,
}
