//! What a set fit returns and writes: result.json (the shared parameters,
//! the deviation over every photograph, `shots` with each one's own
//! parameters and deviation, and `held_out`, each held-out photograph's
//! prediction), fitted_scene.json (the shared model), one best image per
//! photograph (a held-out one's: its prediction), and shots.json (the
//! photographs with absolute paths, held-out ones marked, for
//! `diagnose`).

use super::held_out::{predict, Prediction};
use super::run::Run;
use super::state::FitState;
use super::{varying, SetConfig, ShotResult};
use crate::error::{Error, Result};
use crate::fit::counted;
use crate::fit::output::Written;
use crate::fit::set::shots::{Shot, ShotsFile, FORMAT};
use crate::fit::{render_seed, FitResult};
use crate::metric::{deviation, deviation_levels, Deviation};
use crate::raster::Image;
use crate::render::Renderer;
use crate::rundir::{shot_best_name, RunDir};
use crate::scene::{ParamSpace, Scene};

/// One photograph's fit, in memory.
#[derive(Clone, Debug)]
pub struct ShotOutcome {
    pub result: ShotResult,
    /// The scene that draws it: shared and own values in place.
    pub scene: Scene,
    pub image: Image,
}

/// A set fit's outcome.
#[derive(Clone, Debug)]
pub struct SetOutcome {
    /// `params` the shared parameters, `deviation` over every photograph,
    /// `shots` each one's own.
    pub result: FitResult,
    /// The shared model (per-shot fields as the scene gives them).
    pub scene: Scene,
    pub shots: Vec<ShotOutcome>,
    /// Each photograph held out of the fit, predicted from its model.
    pub held_out: Vec<Prediction>,
}

/// Renders every photograph at the final values, predicts each held-out
/// one, and writes the outputs.
pub fn finish(state: &FitState, run: &Run) -> Result<SetOutcome> {
    let (scene, shots, renderer, config) = (run.scene, run.shots, run.renderer, run.config);
    let (space, dir) = (&run.space, run.dir);
    let shared = space.shared();
    let scenes: Vec<Scene> = shots
        .iter()
        .enumerate()
        .map(|(i, s)| state.shot_scene(i, &s.scene, &shared, &s.own_space(space)))
        .collect();
    let outs = render_final(scenes, shots, renderer, config, space, state)?;
    let parts: Vec<(Deviation, usize)> = outs
        .iter()
        .zip(shots)
        .map(|(o, s)| (o.result.deviation, counted(&s.target)))
        .collect();
    let result = FitResult {
        renderer: renderer.name(),
        strategy: config.fit.de.strategy.to_string(),
        seed: config.fit.de.seed,
        params: shared.json_values(&outs[0].scene),
        deviation: Deviation::pooled(&parts),
        deviation_precise: precise(&outs, shots),
        evaluations: state.evaluations,
        generations: state.generations,
        wall_seconds: state.seconds,
        stop_reason: format!(
            "{} blocks ({} shared)",
            state.blocks_done.min(state.history.len()),
            state.shared_blocks
        ),
        target: None,
        target_encoding: None,
        failed_renders: state.failed_renders,
        identifiability: identifiability(state, &shared, config),
        shots: Some(outs.iter().map(|o| o.result.clone()).collect()),
        alternatives: Vec::new(),
        held_out: Vec::new(),
    };
    result.check_finite()?;
    let model = shared.scene_at(scene, &state.shared);
    let held_out = predict(&model, run.held_out, renderer, &config.fit, dir)?;
    let mut outcome = SetOutcome {
        result,
        scene: model,
        shots: outs,
        held_out,
    };
    outcome.result.held_out = outcome.held_out.iter().map(|p| p.result.clone()).collect();
    if let Some(d) = dir {
        write(d, &outcome, shots, run.held_out)?;
    }
    Ok(outcome)
}

/// The standard errors of the shared parameters from the last shared
/// block's local search (`--strategy hybrid`), each photograph's own
/// values held at theirs then. None after a joint block, which moves the
/// shared values on from where that Jacobian was taken.
fn identifiability(
    state: &FitState,
    shared: &ParamSpace,
    config: &SetConfig,
) -> Option<crate::fit::Uncertainty> {
    if config.joint {
        return None;
    }
    let id = state.last_shared.as_ref()?.identifiability()?;
    Some(crate::fit::uncertainty::of(shared, &id))
}

/// Every photograph rendered once at its final values, and scored.
fn render_final(
    scenes: Vec<Scene>,
    shots: &[Shot],
    renderer: &dyn Renderer,
    config: &SetConfig,
    space: &ParamSpace,
    state: &FitState,
) -> Result<Vec<ShotOutcome>> {
    let images = super::renders::render_shots(
        renderer,
        &scenes,
        shots,
        &varying(space, shots),
        config.fit.jobs,
        render_seed(config.fit.de.seed, state.generations),
    )?;
    let mut outs = Vec::with_capacity(shots.len());
    for ((shot, scene), img) in shots.iter().zip(scenes).zip(images) {
        let image = img.map_err(|why| {
            Error::Run(format!(
                "{}: the final render of shot {} {why}",
                renderer.name(),
                shot.name
            ))
        })?;
        let t = &shot.target;
        let own = shot.own_space(space);
        outs.push(ShotOutcome {
            result: ShotResult {
                name: shot.name.clone(),
                params: own.json_values(&scene),
                deviation: deviation(&t.image, &image, t.mask.as_ref()),
            },
            scene,
            image,
        });
    }
    Ok(outs)
}

/// The deviation from the photographs' unrounded levels, over the set,
/// when any photograph is finer than 8-bit sRGB.
fn precise(outs: &[ShotOutcome], shots: &[Shot]) -> Option<Deviation> {
    if shots.iter().all(|s| s.target.levels.is_none()) {
        return None;
    }
    let parts: Vec<(Deviation, usize)> = outs
        .iter()
        .zip(shots)
        .map(|(o, s)| {
            let t = &s.target;
            let d = match &t.levels {
                Some(l) => deviation_levels(l, &o.image, t.mask.as_ref()),
                None => o.result.deviation,
            };
            (d, counted(t))
        })
        .collect();
    Some(Deviation::pooled(&parts))
}

/// The set's files, through the one writer (`fit::output`): the held-out
/// photographs listed after the fitted ones, marked.
fn write(dir: &RunDir, outcome: &SetOutcome, shots: &[Shot], held_out: &[Shot]) -> Result<()> {
    let file = ShotsFile {
        format: FORMAT.into(),
        shots: shots
            .iter()
            .chain(held_out)
            .map(|s| {
                let mut e = s.entry.clone();
                e.target = absolute(&e.target);
                e.mask = e.mask.as_deref().map(absolute);
                e
            })
            .collect(),
    };
    let fitted = outcome.shots.iter().map(|o| (&o.result.name, &o.image));
    let predicted = outcome.held_out.iter().map(|p| (&p.result.name, &p.image));
    let images = fitted
        .chain(predicted)
        .map(|(name, image)| (shot_best_name(name), image))
        .collect();
    let written = Written {
        images,
        shots: Some(&file),
        scene: &outcome.scene,
        result: &outcome.result,
    };
    crate::fit::output::write(dir, &written)
}

fn absolute(p: &std::path::Path) -> std::path::PathBuf {
    std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf())
}
