//! The steps of one photograph given on its own: its phases, one search
//! each over its own parameters with earlier phases' best values in
//! place, and the outcome of the last (or of the one that met the target
//! deviation).

use super::driver::drive;
use super::run::{Plan, Run, Steps};
use super::shots::Shot;
use super::state::FitState;
use super::SetConfig;
use crate::error::{Error, Result};
use crate::fit::problem::ShotsProblem;
use crate::fit::search_run::{Logs, SearchRun};
use crate::fit::{output, uncertainty, FitConfig, FitOutcome, FitResult, FitTarget, Observer};
use crate::metric::deviation;
use crate::optimize::{Search, Searcher, Start, StopReason, StopRule};
use crate::rundir::RunDir;
use crate::scene::{ParamSpace, Scene};

/// One photograph's plan: its phases, in order.
pub struct Phases;

impl Plan for Phases {
    type Step = usize;
    type Outcome = FitOutcome;

    fn steps(&self, run: &Run) -> Result<Vec<usize>> {
        let phases = run.space.phases().len();
        budgets(&run.config.fit, phases)?;
        Ok((0..phases).collect())
    }

    fn step(
        &self,
        run: &Run,
        state: &mut FitState,
        index: usize,
        _: &[usize],
        observer: &mut dyn Observer,
        io: &mut Steps,
    ) -> Result<Option<FitOutcome>> {
        step(run, state, index, observer, io)
    }

    fn finish(&self, _: &Run, _: &FitState) -> Result<FitOutcome> {
        // The last phase returns the outcome.
        Err(Error::Run(
            "one photograph's fit ran past its last phase".into(),
        ))
    }
}

/// Fits `scene` to one photograph, `target`, in a run directory (opened
/// by `driver::open`) or (None) in memory only.
pub fn run_one(
    scene: &Scene,
    target: &FitTarget,
    renderer: &dyn crate::render::Renderer,
    config: &FitConfig,
    dir: Option<&RunDir>,
    observer: &mut dyn Observer,
) -> Result<FitOutcome> {
    let shots = [Shot::one(scene, target.clone())];
    let config = SetConfig::one(config.clone());
    drive(
        &Phases,
        scene,
        (&shots, &[]),
        renderer,
        &config,
        dir,
        true,
        observer,
    )
}

/// Runs phase `index` of the photograph's fit; its outcome when it was
/// the last, or met the target deviation.
fn step(
    run: &Run,
    state: &mut FitState,
    index: usize,
    observer: &mut dyn Observer,
    steps: &mut Steps,
) -> Result<Option<FitOutcome>> {
    let config = &run.config.fit;
    let phases = run.space.phases();
    let budgets = budgets(config, phases.len())?;
    let phase = phases[index];
    let sub = run.space.phase(phase);
    let base = state
        .base
        .clone()
        .ok_or_else(|| Error::Run("one photograph's fit has no base scene in its state".into()))?;
    let session = run.renderer.session(&base, &sub, config.jobs)?;
    // Only once the renderer has started does an overwriting run remove
    // the earlier run's files.
    (steps.clear)()?;
    if steps.logs.is_none() {
        *steps.logs = Some(Logs::open(run.dir, config)?);
    }
    let mut search = match state.within.search.take() {
        Some(s) => s,
        None => new_search(config, &sub, &base, index),
    };
    let target = &run.shots[0].target;
    let mut problem = ShotsProblem::new(
        session,
        sub.clone(),
        vec![base.clone()],
        vec![target],
        config.de.seed,
    );
    let search_run = SearchRun {
        rule: StopRule {
            max_generations: budgets[index],
            target: config.target_deviation.map(|d| 3.0 * d),
            stagnation: config.stagnation,
        },
        offsets: crate::fit::executor::Offsets {
            generations: state.generations,
            evaluations: state.evaluations,
            seconds: state.seconds,
            total_generations: budgets.iter().sum(),
            phase,
        },
        config,
        dir: run.dir,
    };
    let logs = steps.logs.as_mut().expect("opened above");
    let mut save = |s: &Searcher, _: f64| -> Result<()> {
        state.within.search = Some(s.clone());
        (steps.save)(state)
    };
    let reason = search_run.run(&mut problem, &mut search, logs, observer, &mut save)?;
    if index + 1 == phases.len() || reason == StopReason::Target {
        let failed = logs.failed();
        let outcome = finish(run, state, search, problem, reason, failed)?;
        (steps.save)(state)?;
        if let Some(d) = run.dir {
            output::write_one(d, &outcome)?;
        }
        return Ok(Some(outcome));
    }
    state.base = Some(sub.scene_at(&base, search.best().0));
    state.generations += search.generation();
    state.evaluations += search.evaluations();
    state.within = Default::default();
    state.blocks_done += 1;
    (steps.save)(state)?;
    Ok(None)
}

/// The outcome of the last phase; its search stays in the state (the
/// final population, and a larger budget resumes it).
fn finish(
    run: &Run,
    state: &mut FitState,
    search: Searcher,
    problem: ShotsProblem,
    reason: StopReason,
    failed_renders: usize,
) -> Result<FitOutcome> {
    let (config, target) = (&run.config.fit, &run.shots[0].target);
    let sub = problem.space.clone();
    let base = state.base.clone().unwrap_or_else(|| run.scene.clone());
    let scene = sub.scene_at(&base, search.best().0);
    let image = match problem
        .into_best_images()
        .and_then(|v| v.into_iter().next())
    {
        Some(img) => img,
        None => crate::render::render_one(run.renderer, &scene, 0)?,
    };
    let result = FitResult {
        renderer: run.renderer.name(),
        strategy: config.de.strategy.to_string(),
        seed: config.de.seed,
        params: run.space.json_values(&scene),
        deviation: deviation(&target.image, &image, target.mask.as_ref()),
        deviation_precise: target
            .levels
            .as_ref()
            .map(|l| crate::metric::deviation_levels(l, &image, target.mask.as_ref())),
        evaluations: state.evaluations + search.evaluations(),
        generations: state.generations + search.generation(),
        wall_seconds: state.seconds,
        stop_reason: reason.to_string(),
        target: target.path.as_ref().map(|p| p.display().to_string()),
        target_encoding: target.encoding,
        failed_renders,
        identifiability: search
            .identifiability()
            .map(|id| uncertainty::of(&sub, &id)),
        shots: None,
        alternatives: output::alternatives(&sub, &base, search.best().0, &search.alternatives()),
        held_out: Vec::new(),
    };
    result.check_finite()?;
    state.within.search = Some(search);
    let population = state.population();
    Ok(FitOutcome {
        result,
        scene,
        image,
        population,
    })
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
    search.set_swaps(crate::fit::swaps::light_swaps(sub, base));
    if config.settle {
        search.settle();
    }
    search
}

/// Generations for each phase; every phase gets at least one.
pub fn budgets(config: &FitConfig, phases: usize) -> Result<Vec<usize>> {
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
