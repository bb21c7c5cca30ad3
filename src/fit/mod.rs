//! A fit: the scene's free parameters searched phase after phase, each
//! candidate rendered and compared with the target (`problem`), the loop
//! written once (`executor`), a checkpoint every generation
//! (`checkpoint`, `identity`), logs as observers (`observers`), and the
//! outcome returned in memory — fitted scene, best image, final population
//! — as well as written into the run directory (`output`, `crate::rundir`).
//!
//! Data flows one way: parameter vector -> scene -> renderer -> image ->
//! metric -> optimizer.

mod checkpoint;
mod config;
mod executor;
pub(crate) mod identity;
mod observers;
mod output;
mod problem;
mod search_run;
pub mod set;
mod target;
pub(crate) mod uncertainty;

pub use checkpoint::Checkpoint;
pub use config::{FitConfig, GenerationReport};
pub use executor::{Observer, Problem};
pub use output::{Alternative, FitOutcome, FitResult, Population};
pub use problem::{counted, render_seed};
pub use target::FitTarget;
pub use uncertainty::{Correlation, Uncertainty};

use crate::error::{Error, Result};
use crate::metric::deviation;
use crate::optimize::{Search, Searcher, Start, StopReason, StopRule};
use crate::render::Renderer;
use crate::rundir::{Mode, RunDir};
use crate::scene::{ParamSpace, Scene};
use executor::Offsets;
use identity::RunIdentity;
use problem::ShotsProblem;
use search_run::{Logs, SearchRun};
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
    let run_dir = RunDir::open(dir, config.mode)?;
    if let Some(p) = &target.path {
        run_dir.refuse_overwritten_input(p, "the target")?;
    }
    for (what, p) in &config.inputs {
        run_dir.refuse_overwritten_input(p, what)?;
    }
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

/// The phase loop: one search per phase, each over its own parameters with
/// earlier phases' best values in place.
pub fn run_in(
    scene: &Scene,
    target: &FitTarget,
    renderer: &dyn Renderer,
    config: &FitConfig,
    dir: Option<&RunDir>,
    observer: &mut dyn Observer,
) -> Result<FitOutcome> {
    let space = check_inputs(scene, target, config)?;
    let phases = space.phases();
    let budgets = phase_budgets(config, phases.len())?;
    let identity = RunIdentity::of(scene, target, &renderer.name(), config);
    let mut state = initial_state(dir, config, scene, identity)?;
    let mut logs: Option<Logs> = None;
    loop {
        let phase = phases[state.phase_index];
        let sub = space.phase(phase);
        let session = renderer.session(&state.base, &sub, config.jobs)?;
        if logs.is_none() {
            // Only once the renderer has started does an overwriting run
            // remove the earlier run's files.
            if let (Some(d), Mode::Overwrite) = (dir, config.mode) {
                d.clear()?;
            }
            logs = Some(Logs::open(dir, config)?);
        }
        let mut search = match state.search.take() {
            Some(s) => s,
            None => new_search(config, &sub, &state.base, state.phase_index),
        };
        let mut problem = ShotsProblem::new(
            session,
            sub.clone(),
            vec![state.base.clone()],
            vec![target],
            config.de.seed,
        );
        if search.evaluations() > 0 {
            let (best, f) = search.best();
            problem.adopt_best(best, f);
        }
        let rule = StopRule {
            max_generations: budgets[state.phase_index],
            target: config.target_deviation.map(|d| 3.0 * d),
            stagnation: config.stagnation,
        };
        let offsets = Offsets {
            generations: state.generation_offset,
            evaluations: state.evaluations_before,
            seconds: state.elapsed_before,
            total_generations: budgets.iter().sum(),
            phase,
        };
        let logs_now = logs.as_mut().expect("opened above");
        let run = SearchRun {
            rule,
            offsets,
            config,
            dir,
        };
        let mut save = |s: &Searcher, seconds: f64| -> Result<()> {
            state.elapsed_before = offsets.seconds + seconds;
            dir.map_or(Ok(()), |d| state.save_with(d, s))
        };
        let reason = run.run(&mut problem, &mut search, logs_now, observer, &mut save)?;
        if state.phase_index + 1 == phases.len() || reason == StopReason::Target {
            let failed = logs_now.failed();
            return finish(
                state, search, problem, &space, reason, failed, renderer, config, target, dir,
            );
        }
        state.base = sub.scene_at(&state.base, search.best().0);
        state.generation_offset += search.generation();
        state.evaluations_before += search.evaluations();
        state.phase_index += 1;
        if let Some(d) = dir {
            state.save(d)?;
        }
    }
}

/// The outcome of the last phase, written into the run directory.
#[allow(clippy::too_many_arguments)]
fn finish(
    mut state: Checkpoint,
    search: Searcher,
    problem: ShotsProblem,
    space: &ParamSpace,
    reason: StopReason,
    failed_renders: usize,
    renderer: &dyn Renderer,
    config: &FitConfig,
    target: &FitTarget,
    dir: Option<&RunDir>,
) -> Result<FitOutcome> {
    let sub = problem.space.clone();
    let scene = sub.scene_at(&state.base, search.best().0);
    let image = match problem
        .into_best_images()
        .and_then(|v| v.into_iter().next())
    {
        Some(img) => img,
        None => crate::render::render_one(renderer, &scene, 0)?,
    };
    let result = FitResult {
        renderer: renderer.name(),
        strategy: config.de.strategy.to_string(),
        seed: config.de.seed,
        params: space.json_values(&scene),
        deviation: deviation(&target.image, &image, target.mask.as_ref()),
        deviation_precise: target
            .levels
            .as_ref()
            .map(|l| crate::metric::deviation_levels(l, &image, target.mask.as_ref())),
        evaluations: state.evaluations_before + search.evaluations(),
        generations: state.generation_offset + search.generation(),
        wall_seconds: state.elapsed_before,
        stop_reason: reason.to_string(),
        target: target.path.as_ref().map(|p| p.display().to_string()),
        target_encoding: target.encoding,
        failed_renders,
        identifiability: search
            .identifiability()
            .map(|id| uncertainty::of(&sub, &id)),
        shots: None,
        alternatives: output::alternatives(
            &sub,
            &state.base,
            search.best().0,
            &search.alternatives(),
        ),
    };
    result.check_finite()?;
    state.search = Some(search);
    let outcome = FitOutcome {
        result,
        scene,
        image,
        population: state.population(),
    };
    if let Some(d) = dir {
        state.save(d)?;
        output::finish(d, &outcome)?;
    }
    Ok(outcome)
}

/// Checks what a fit needs before anything starts; the scene's free space.
fn check_inputs(scene: &Scene, target: &FitTarget, config: &FitConfig) -> Result<ParamSpace> {
    let space = ParamSpace::from_scene(scene);
    if space.is_empty() {
        return Err(Error::Usage(
            "the scene has no \"free\" parameters to fit".into(),
        ));
    }
    if (scene.image.width, scene.image.height) != target.image.dimensions() {
        return Err(Error::Usage(format!(
            "the target is {}x{} but the scene renders {}x{}",
            target.image.width(),
            target.image.height(),
            scene.image.width,
            scene.image.height
        )));
    }
    config
        .de
        .validate()
        .map_err(|e| Error::Usage(e.to_string()))?;
    Ok(space)
}

/// A fresh run's first state, or a resumed run's checkpoint checked
/// against this run's inputs.
fn initial_state(
    dir: Option<&RunDir>,
    config: &FitConfig,
    scene: &Scene,
    identity: RunIdentity,
) -> Result<Checkpoint> {
    match (dir, config.mode) {
        (Some(d), Mode::Resume) => {
            let c = Checkpoint::load(d)?;
            c.check_identity(d, &identity)?;
            c.check_image(d, scene)?;
            Ok(c)
        }
        _ => Ok(Checkpoint::start(scene.clone(), identity)),
    }
}

/// A phase's search, from its own stream of the run's seed.
fn new_search(config: &FitConfig, sub: &ParamSpace, base: &Scene, phase_index: usize) -> Searcher {
    let mut de = config.de.clone();
    de.seed = phase_seed(config.de.seed, phase_index);
    let center = sub.unit_of(base);
    let start = match config.start_radius {
        Some(radius) => Start::Around {
            center: &center,
            radius,
        },
        None => Start::Uniform,
    };
    let mut search = Searcher::new(sub.dim(), &de, start);
    search.set_periods(periods(sub));
    if config.settle {
        search.settle();
    }
    search
}

/// Each unit coordinate's period in unit coordinates, 0 if none: a hue
/// whose bounds span the whole circle is searched over an interval that
/// overlaps itself (`ParamSpace::from_scene`), so moving it by one turn
/// gives the same colour.
pub(crate) fn periods(space: &ParamSpace) -> Vec<f64> {
    space
        .specs
        .iter()
        .flat_map(|s| {
            (0..s.dim()).map(move |c| {
                let span = s.max[c] - s.min[c];
                let circle = s.hsv && c == 0 && s.min[0] <= 0.0 && s.max[0] >= 1.0 && span > 1.0;
                if circle {
                    1.0 / span
                } else {
                    0.0
                }
            })
        })
        .collect()
}

/// Generations for each phase; every phase gets at least one.
fn phase_budgets(config: &FitConfig, phases: usize) -> Result<Vec<usize>> {
    let v = match &config.phase_generations {
        Some(v) if v.len() == phases => v.clone(),
        Some(v) => {
            return Err(Error::Usage(format!(
                "phase generations: the scene has {phases} phase(s), got {} numbers",
                v.len()
            )))
        }
        None => {
            let each = config.generations / phases;
            let mut v = vec![each; phases];
            v[phases - 1] += config.generations - each * phases;
            v
        }
    };
    if v.contains(&0) {
        return Err(Error::Usage(format!(
            "a budget of {} generation(s) over {phases} phase(s) leaves a phase with none; expected at least 1 generation per phase",
            v.iter().sum::<usize>()
        )));
    }
    Ok(v)
}

/// Each phase draws from its own stream of the run's seed.
fn phase_seed(seed: u64, phase_index: usize) -> u64 {
    seed.wrapping_add((phase_index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15))
}
