//! A fit of a set of photographs of one scene (`fit --shots`): the shared
//! parameters (material, camera, …) and every photograph's own
//! (`"per_shot": true`, e.g. its light) found by block coordinate descent.
//!
//! One search over all coordinates at once does not scale: 24 photographs
//! with 4 own coordinates each make ~100 coordinates, where DE needs a
//! budget that grows with the dimension, and most pairs of coordinates do
//! not interact (one photograph's light does not change another's image).
//! So the blocks alternate:
//! 1. each photograph's own parameters, the shared ones held (independent
//!    small fits, one per photograph);
//! 2. the shared parameters, every photograph's own held: one search whose
//!    candidate is drawn once per photograph and scored over all of them
//!    (`problem`);
//!
//! and again 1, 2, … until a round improves the deviation over the whole
//! set by less than 1 %, or the round budget is spent; then, with
//! `--joint`, one joint block moves every coordinate at once by
//! Levenberg–Marquardt (`joint`), which follows the valleys where shared
//! and per-shot values trade.
//! Later blocks start around the current values. The state is saved after
//! every photograph of a per-shot block and every generation of a shared
//! block (`state`), so `--resume` continues where the run stopped, to the
//! result an uninterrupted run gives.

pub(crate) mod driver;
pub mod held_out;
mod joint;
mod outcome;
pub(crate) mod phase;
pub mod renders;
mod resume;
mod run;
pub(crate) mod saved;
mod setup;
pub mod shots;
pub(crate) mod state;

pub use super::output::ShotResult;
pub use crate::fit::counted;
pub use outcome::{SetOutcome, ShotOutcome};
pub use setup::SetConfig;

use super::executor::{Halt, Offsets};
use super::search_run::{halt_error, Logs, SearchRun};
use super::Observer;
use crate::error::Result;
use crate::fit::problem::ShotsProblem;
use crate::metric::Deviation;
use crate::optimize::{Search, Searcher, Start, StopRule};
use crate::render::Renderer;
use crate::rundir::RunDir;
use crate::scene::{ParamSpace, Scene};
use driver::drive;
use run::{Plan, Run, Steps};
use setup::{block_config, block_seed, varying};
pub use shots::Shot;
use state::{FitState, Within};

/// Relative improvement of a round below which the blocks stop.
const ROUND_TOLERANCE: f64 = 0.01;
/// Unit-cube spread of a later block's start around the current values.
const LATER_RADIUS: f64 = 0.1;

/// Each shared coordinate's start spread in a shared block: a fresh fit's
/// first block searches the whole box (the current values one member of
/// its population: the scene's values are a guess), a warm refit's first
/// block spreads its new parameters as `config.spread` says, and every
/// other block starts around the current values.
fn start_radii(shared: &ParamSpace, first: bool, config: &SetConfig) -> Vec<f64> {
    let mut radii = Vec::with_capacity(shared.dim());
    for spec in &shared.specs {
        let radius = match (first, config.warm) {
            (true, false) => 1.0,
            (true, true) => config
                .spread
                .iter()
                .find(|(name, _)| *name == spec.name)
                .map_or(LATER_RADIUS, |s| s.1),
            (false, _) => LATER_RADIUS,
        };
        radii.extend(std::iter::repeat_n(radius, spec.dim()));
    }
    radii
}

/// Runs a set fit of `shots`, in a run directory (opened by
/// `driver::open`) or (None) in memory only: the one fit path (`driver`)
/// with the set's blocks. The shots marked `hold_out` are left out of the
/// fit and predicted after it (`held_out`); refused when every one is.
pub fn run_in(
    scene: &Scene,
    shots: &[Shot],
    renderer: &dyn Renderer,
    config: &SetConfig,
    dir: Option<&RunDir>,
    observer: &mut dyn Observer,
) -> Result<SetOutcome> {
    let (fitted, held) = held_out::split(shots)?;
    let shots = (fitted.as_slice(), held.as_slice());
    drive(
        &Blocks, scene, shots, renderer, config, dir, false, observer,
    )
}

/// A step of the alternation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Block {
    Own,
    Shared,
    /// Every coordinate at once, by Levenberg–Marquardt (`joint`).
    Joint,
}

/// A set's plan: its blocks.
pub struct Blocks;

impl Plan for Blocks {
    type Step = Block;
    type Outcome = SetOutcome;

    fn steps(&self, run: &Run) -> Result<Vec<Block>> {
        Ok(plan(&run.space, run.shots, run.config))
    }

    /// Runs a block and records it: the set's deviation after it, the
    /// next block (straight to the joint block, if there is one, once a
    /// round has converged).
    fn step(
        &self,
        run: &Run,
        state: &mut FitState,
        block: Block,
        plan: &[Block],
        observer: &mut dyn Observer,
        io: &mut Steps,
    ) -> Result<Option<SetOutcome>> {
        let (shots, renderer, config, space, dir) =
            (run.shots, run.renderer, run.config, &run.space, run.dir);
        let total = match block {
            Block::Own => own_block(state, shots, renderer, config, space, dir, io)?,
            Block::Shared => {
                shared_block(state, shots, renderer, config, space, observer, dir, io)?
            }
            Block::Joint => joint::run(state, shots, renderer, config, space, io.clear)?,
        };
        state.within = Within::default();
        state.history.push(total);
        state.blocks_done += 1;
        if block == Block::Own && converged(&state.history) {
            state.blocks_done = plan.len() - usize::from(plan.last() == Some(&Block::Joint));
        }
        (io.save)(state)?;
        Ok(None)
    }

    fn finish(&self, run: &Run, state: &FitState) -> Result<SetOutcome> {
        outcome::finish(state, run)
    }
}

/// The blocks in order: own, shared, own, shared, own, … (`rounds` shared
/// blocks), then the joint block; a set with only one kind of parameter
/// has only that block.
fn plan(space: &ParamSpace, shots: &[Shot], config: &SetConfig) -> Vec<Block> {
    let (rounds, warm, joint) = (config.rounds, config.warm, config.joint);
    let has_own = shots.iter().any(|s| !s.own_space(space).is_empty());
    let has_shared = !space.shared().is_empty();
    match (has_own, has_shared) {
        (true, true) => {
            let mut v = if warm { vec![] } else { vec![Block::Own] };
            for _ in 0..rounds.max(1) {
                v.extend([Block::Shared, Block::Own]);
            }
            if joint {
                v.push(Block::Joint);
            }
            v
        }
        (true, false) => vec![Block::Own],
        _ => vec![Block::Shared],
    }
}

/// True when the last round (shared then own block) improved the set's
/// deviation by less than `ROUND_TOLERANCE` of it.
fn converged(history: &[f64]) -> bool {
    let n = history.len();
    n >= 3 && history[n - 3] - history[n - 1] < ROUND_TOLERANCE * history[n - 3]
}

/// Fits each photograph's own parameters with the shared ones held,
/// saving after each photograph (a resumed block skips those done); the
/// set's deviation after it.
fn own_block(
    state: &mut FitState,
    shots: &[Shot],
    renderer: &dyn Renderer,
    config: &SetConfig,
    space: &ParamSpace,
    dir: Option<&RunDir>,
    steps: &mut Steps,
) -> Result<f64> {
    let done = state.within.own_parts.len();
    for (i, shot) in shots.iter().enumerate().skip(done) {
        let interrupted = || {
            let flag = config.fit.interrupt.as_ref();
            flag.is_some_and(|f| f.load(std::sync::atomic::Ordering::SeqCst))
        };
        // A photograph's fit runs in memory: its own "nothing was saved"
        // is not the set's, whose state resumes the run.
        let d = match own_fit(state, i, shot, renderer, config, space) {
            Err(_) if interrupted() => return Err(halt_error(Halt::Interrupted, dir)),
            r => r?,
        };
        (steps.clear)()?;
        state.within.push_part(d);
        (steps.save)(state)?;
    }
    let parts: Vec<(Deviation, usize)> = state
        .within
        .parts()
        .into_iter()
        .zip(shots)
        .map(|(d, s)| (d, crate::fit::counted(&s.target)))
        .collect();
    Ok(Deviation::pooled(&parts).average)
}

/// Photograph `i`'s own parameters fitted with the shared ones held, from
/// the seed of this block and photograph; its deviation after.
fn own_fit(
    state: &mut FitState,
    i: usize,
    shot: &Shot,
    renderer: &dyn Renderer,
    config: &SetConfig,
    space: &ParamSpace,
) -> Result<Deviation> {
    let own = shot.own_space(space);
    let base = state.shot_scene(i, &shot.scene, &space.shared(), &own);
    let t = &shot.target;
    if own.is_empty() {
        let img = crate::render::render_one(renderer, &base, 0)?;
        return Ok(crate::metric::deviation(&t.image, &img, t.mask.as_ref()));
    }
    let mut fit_scene = base;
    fit_scene
        .free
        .retain(|f| own.specs.iter().any(|s| s.name == f.param));
    let seed = block_seed(config.fit.de.seed, state.blocks_done, i);
    let mut cfg = block_config(&config.fit, own.dim(), seed);
    cfg.start_radius = (state.blocks_done > 0 || config.warm).then_some(LATER_RADIUS);
    let out = phase::run_one(&fit_scene, t, renderer, &cfg, None, &mut ())?;
    state.own[i] = own.unit_of(&out.scene);
    state.evaluations += out.result.evaluations;
    state.generations += out.result.generations;
    state.failed_renders += out.result.failed_renders;
    Ok(out.result.deviation)
}

/// Fits the shared parameters over every photograph at once, each with its
/// own values held; the set's deviation after it.
#[allow(clippy::too_many_arguments)]
fn shared_block(
    state: &mut FitState,
    shots: &[Shot],
    renderer: &dyn Renderer,
    config: &SetConfig,
    space: &ParamSpace,
    observer: &mut dyn Observer,
    dir: Option<&RunDir>,
    steps: &mut Steps,
) -> Result<f64> {
    let shared = space.shared();
    let bases: Vec<Scene> = shots
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let own = s.own_space(space);
            own.scene_at(&s.scene, &state.own[i])
        })
        .collect();
    let session = renderer.session(&bases[0], &varying(space, shots), config.fit.jobs)?;
    (steps.clear)()?;
    let targets = shots.iter().map(|s| &*s.target).collect();
    let seed = block_seed(config.fit.de.seed, state.blocks_done, 0);
    let mut problem = ShotsProblem::new(session, shared.clone(), bases, targets, seed);
    let cfg = block_config(&config.fit, shared.dim(), seed);
    // A fresh fit's first shared block searches the whole box (the current
    // values one member of its population): the scene's values are a guess.
    let radii = start_radii(&shared, state.shared_blocks == 0, config);
    let start = Start::AroundEach {
        center: &state.shared,
        radii: &radii,
    };
    // A resumed block continues from its saved search.
    let mut search = state.within.search.take().unwrap_or_else(|| {
        let mut s = Searcher::new(shared.dim(), &cfg.de, start);
        s.set_periods(phase::periods(&shared));
        s
    });
    let run = SearchRun {
        rule: StopRule {
            max_generations: cfg.generations,
            target: cfg.target_deviation.map(|d| 3.0 * d),
            stagnation: cfg.stagnation,
        },
        offsets: Offsets {
            generations: state.generations,
            evaluations: state.evaluations,
            seconds: state.seconds,
            total_generations: state.generations + config.fit.generations,
            phase: 1,
        },
        config: &config.fit,
        dir,
    };
    if steps.logs.is_none() {
        *steps.logs = Some(Logs::open(dir, &config.fit)?);
    }
    let logs = steps.logs.as_mut().expect("opened above");
    let mut save = |s: &Searcher, _: f64| -> Result<()> {
        state.within.search = Some(s.clone());
        (steps.save)(state)
    };
    run.run(&mut problem, &mut search, logs, observer, &mut save)?;
    let n = shots.len();
    state.failed_renders += problem.failed_renders();
    state.shared = search.best().0.to_vec();
    state.evaluations += search.evaluations() * n;
    state.generations += search.generation();
    state.shared_blocks += 1;
    let average = search.best().1 / 3.0;
    state.last_shared = Some(search);
    Ok(average)
}
