//! The one fit path, for one photograph or a set: a fit is a plan of
//! steps run in order over one state (`state::FitState`, saved as
//! checkpoint.json), each step a search run by `search_run` over the one
//! problem (`problem`) or a set's per-shot or joint block. One photograph
//! given on its own (`fit --target`) is a list of one whose plan is its
//! phases (`phase`); a shots file's photographs (`fit --shots`) are
//! fitted by alternating blocks (`set`). The inputs are checked, the run
//! directory opened and a resume checked here, once for both.

use super::resume;
use super::run::{Plan, Run, Steps};
use super::shots::Shot;
use super::state::FitState;
use super::SetConfig;
use crate::error::{Error, Result};
use crate::fit::identity::RunIdentity;
use crate::fit::{FitConfig, Observer};
use crate::render::Renderer;
use crate::rundir::{Kind, Mode, RunDir};
use crate::scene::{ParamSpace, Scene};
use std::path::Path;
use std::time::Instant;

/// Opens the run directory `dir` for a fit of `shots` (in `config.mode`),
/// refusing a run that would overwrite one of its inputs.
pub fn open(dir: &Path, shots: &[Shot], alone: bool, config: &FitConfig) -> Result<RunDir> {
    let kind = if alone { Kind::Fit } else { Kind::Set };
    let run_dir = RunDir::open_as(dir, config.mode, kind)?;
    for s in shots {
        if alone {
            if let Some(p) = &s.target.path {
                run_dir.refuse_overwritten_input(p, "the target")?;
            }
            continue;
        }
        run_dir.refuse_overwritten_input(&s.entry.target, &format!("shot {}'s target", s.name))?;
        if let Some(m) = &s.entry.mask {
            run_dir.refuse_overwritten_input(m, &format!("shot {}'s mask", s.name))?;
        }
    }
    for (what, p) in &config.inputs {
        run_dir.refuse_overwritten_input(p, what)?;
    }
    Ok(run_dir)
}

/// Runs a fit of `scene` to `shots` by `plan`, in a run directory or
/// (None) in memory only; `alone` as in [`Run`]; `held_out` are
/// predicted at the end, not fitted.
#[allow(clippy::too_many_arguments)]
pub fn drive<P: Plan>(
    plan: &P,
    scene: &Scene,
    (shots, held_out): (&[Shot], &[Shot]),
    renderer: &dyn Renderer,
    config: &SetConfig,
    dir: Option<&RunDir>,
    alone: bool,
    observer: &mut dyn Observer,
) -> Result<P::Outcome> {
    let space = check_inputs(scene, shots, alone, &config.fit)?;
    check_sizes(scene, held_out, alone)?;
    let run = Run {
        scene,
        shots,
        renderer,
        config,
        dir,
        alone,
        space,
        held_out,
    };
    let steps = plan.steps(&run)?;
    let mut state = initial_state(&run)?;
    let (started, before) = (Instant::now(), state.seconds);
    let mut cleared = config.fit.mode != Mode::Overwrite;
    let mut logs = None;
    let mut save = |state: &mut FitState| -> Result<()> {
        state.seconds = before + started.elapsed().as_secs_f64();
        dir.map_or(Ok(()), |d| state.save(d))
    };
    // A fresh set is resumable from its start (an overwriting one once
    // the earlier run's files are gone: its first save); a search saves
    // before its first generation.
    if config.fit.mode == Mode::Fresh && !alone {
        save(&mut state)?;
    }
    while let Some(&step) = steps.get(state.blocks_done) {
        let mut clear = || -> Result<()> {
            if !cleared {
                if let Some(d) = dir {
                    d.clear()?;
                }
                cleared = true;
            }
            Ok(())
        };
        let mut io = Steps {
            clear: &mut clear,
            save: &mut save,
            logs: &mut logs,
        };
        if let Some(o) = plan.step(&run, &mut state, step, &steps, observer, &mut io)? {
            return Ok(o);
        }
    }
    plan.finish(&run, &state)
}

/// Checks what a fit needs before anything starts; the scene's free space.
fn check_inputs(
    scene: &Scene,
    shots: &[Shot],
    alone: bool,
    config: &FitConfig,
) -> Result<ParamSpace> {
    let space = ParamSpace::from_scene(scene);
    if space.is_empty() {
        return Err(Error::Usage(
            "the scene has no \"free\" parameters to fit".into(),
        ));
    }
    check_sizes(scene, shots, alone)?;
    config
        .de
        .validate()
        .map_err(|e| Error::Usage(e.to_string()))?;
    Ok(space)
}

/// Refuses a photograph whose size is not the scene's.
fn check_sizes(scene: &Scene, shots: &[Shot], alone: bool) -> Result<()> {
    for s in shots {
        let (w, h) = s.target.image.dimensions();
        if (w, h) != (scene.image.width, scene.image.height) {
            // One photograph needs no name.
            let name = match alone {
                true => String::new(),
                false => format!("shot {}: ", s.name),
            };
            return Err(Error::Usage(format!(
                "{name}the target is {w}x{h} but the scene renders {}x{}",
                scene.image.width, scene.image.height
            )));
        }
    }
    Ok(())
}

/// A fresh run's first state, or a resumed run's state checked against
/// this run's inputs.
fn initial_state(run: &Run) -> Result<FitState> {
    let config = &run.config.fit;
    let identities = run
        .shots
        .iter()
        .map(|s| RunIdentity::of(&s.scene, &s.target, &run.renderer.name(), config))
        .collect();
    let mut fresh = FitState::new(identities, if run.alone { 0 } else { run.config.rounds });
    fresh.held_out = run.held_out.iter().map(|s| s.name.clone()).collect();
    if run.alone {
        fresh.base = Some(run.scene.clone());
    } else {
        fresh.shared = run.space.shared().unit_of(run.scene);
        fresh.own = run
            .shots
            .iter()
            .map(|s| s.own_space(&run.space).unit_of(&s.scene))
            .collect();
    }
    match (run.dir, config.mode) {
        (Some(d), Mode::Resume) => {
            let s = super::saved::load(d)?;
            resume::check(&s, &resume::file_of(d), run, &fresh)?;
            Ok(s)
        }
        _ => Ok(fresh),
    }
}
