//! Photographs held out of a set's fit (`"hold_out": true` in the shots
//! file, or `--hold-out NAME,…`): they take no part in fitting the shared
//! model (nor, in a diagnosis, in choosing effects). Afterwards each is
//! predicted from the model alone — its own per-shot unknowns fitted with
//! everything shared frozen, its known values (`set`) as given — and the
//! prediction's deviation reported. A model that merely memorises its
//! photographs fits them well and predicts these badly: this is the
//! measure to trust (docs/usage.md).

use super::phase;
use super::setup::{block_config, block_seed};
use super::shots::Shot;
use crate::error::{Error, Result};
use crate::fit::executor::Halt;
use crate::fit::output::HeldOutResult;
use crate::fit::search_run::halt_error;
use crate::fit::FitConfig;
use crate::metric::{deviation, Deviation};
use crate::optimize::{DeConfig, Strategy};
use crate::raster::Image;
use crate::render::Renderer;
use crate::rundir::RunDir;
use crate::scene::limits::quote;
use crate::scene::load::with_overrides;
use crate::scene::{Override, ParamSpace, Scene};
use serde::Serialize;

/// The stream of the run's seed the predictions draw from, apart from
/// every block's (`block_seed` counts blocks from 0).
const PREDICTION_STREAM: usize = 1 << 20;

/// Marks the shots `names` (given by `option`) held out; an unknown name
/// is refused naming it.
pub fn mark(shots: &mut [Shot], names: &[String], option: &str) -> Result<()> {
    for name in names {
        let Some(s) = shots.iter_mut().find(|s| &s.name == name) else {
            let known: Vec<&str> = shots.iter().map(|s| s.name.as_str()).take(8).collect();
            let more = if shots.len() > 8 { ", …" } else { "" };
            return Err(Error::Usage(format!(
                "{option}: no shot named {} in the shots file (its shots: {}{more})",
                quote(name),
                known.join(", ")
            )));
        };
        s.entry.hold_out = true;
    }
    Ok(())
}

/// The shots to fit and those held out, in their order; refused when
/// every one is held out (there would be no model to predict from).
pub fn split(shots: &[Shot]) -> Result<(Vec<Shot>, Vec<Shot>)> {
    let (held, fitted): (Vec<Shot>, Vec<Shot>) =
        shots.iter().cloned().partition(|s| s.entry.hold_out);
    if fitted.is_empty() {
        return Err(Error::Usage(format!(
            "every photograph of the set is held out ({} of {}); expected at least one to fit",
            held.len(),
            shots.len()
        )));
    }
    Ok((fitted, held))
}

/// One held-out photograph predicted: result.json's entry and the render.
#[derive(Clone, Debug)]
pub struct Prediction {
    pub result: HeldOutResult,
    pub image: Image,
}

/// Predicts each of `held_out` from `model` (a set's shared model, its
/// per-shot fields as the scene gives them): the shot's `set` values put
/// in, its own free parameters fitted with every shared value frozen
/// (`config`'s search, as a per-shot block's), then rendered and scored.
/// `dir` only names the run in the message of an interrupted run.
pub fn predict(
    model: &Scene,
    held_out: &[Shot],
    renderer: &dyn Renderer,
    config: &FitConfig,
    dir: Option<&RunDir>,
) -> Result<Vec<Prediction>> {
    let space = ParamSpace::from_scene(model);
    let mut out = Vec::with_capacity(held_out.len());
    for (i, shot) in held_out.iter().enumerate() {
        let interrupted = || {
            let flag = config.interrupt.as_ref();
            flag.is_some_and(|f| f.load(std::sync::atomic::Ordering::SeqCst))
        };
        match predict_one(model, &space, shot, i, renderer, config) {
            Err(_) if interrupted() => return Err(halt_error(Halt::Interrupted, dir)),
            r => out.push(r?),
        }
    }
    Ok(out)
}

/// Held-out photograph `i` predicted from `model` (see [`predict`]).
fn predict_one(
    model: &Scene,
    space: &ParamSpace,
    shot: &Shot,
    i: usize,
    renderer: &dyn Renderer,
    config: &FitConfig,
) -> Result<Prediction> {
    let overrides: Vec<Override> = shot
        .entry
        .set
        .iter()
        .map(|(k, v)| Override {
            path: k.clone(),
            value: v.clone(),
        })
        .collect();
    let base = with_overrides(model, &overrides, "(held out)", &shot.name)?;
    let own = shot.own_space(space);
    let t = &shot.target;
    let scene = if own.is_empty() {
        base
    } else {
        let mut fit_scene = base;
        fit_scene
            .free
            .retain(|f| own.specs.iter().any(|s| s.name == f.param));
        let seed = block_seed(config.de.seed, PREDICTION_STREAM, i);
        // Over the whole box, as a fresh fit's first per-shot block: the
        // scene's per-shot values are a guess, not this photograph's.
        let cfg = block_config(config, own.dim(), seed);
        phase::run_one(&fit_scene, t, renderer, &cfg, None, &mut ())?.scene
    };
    let image = crate::render::render_one(renderer, &scene, 0)?;
    Ok(Prediction {
        result: HeldOutResult {
            name: shot.name.clone(),
            params: own.json_values(&scene),
            deviation_fit: deviation(&t.image, &image, t.mask.as_ref()),
        },
        image,
    })
}

/// A held-out photograph in diagnosis.json: its prediction from the
/// fit's model and from the diagnosis's improved one.
#[derive(Clone, Debug, Serialize)]
pub struct Compared {
    pub name: String,
    /// Its own values as the improved model predicts them.
    pub params: serde_json::Map<String, serde_json::Value>,
    pub deviation_fit: Deviation,
    pub deviation_after: Deviation,
}

/// The search of a prediction outside a fit (a diagnosis): the hybrid
/// strategy with its default budget, from `seed`, `jobs` renders at once.
pub fn search(seed: u64, jobs: usize) -> FitConfig {
    FitConfig {
        de: DeConfig {
            seed,
            strategy: Strategy::Hybrid,
            ..DeConfig::default()
        },
        jobs,
        snapshot_every: usize::MAX / 2,
        ..FitConfig::default()
    }
}

/// Each of `held_out` predicted from the improved model (`models.1`) and,
/// unless the fit already did (`known`, result.json's `held_out`), from
/// the fit's model (`models.0`), with the same search (`config`): the
/// entries, and the predictions after. A prediction the fit made is taken
/// as it reported it, so that diagnosis.json's `deviation_fit` is the
/// figure of result.json.
pub fn compare(
    (fitted, after): (&Scene, &Scene),
    held_out: &[Shot],
    known: &[HeldOutResult],
    renderer: &dyn Renderer,
    config: FitConfig,
) -> Result<(Vec<Compared>, Vec<Image>)> {
    let found = |s: &Shot| known.iter().find(|k| k.name == s.name);
    let new: Vec<Shot> = held_out
        .iter()
        .filter(|s| found(s).is_none())
        .cloned()
        .collect();
    let mut before = predict(fitted, &new, renderer, &config, None)?.into_iter();
    let now = predict(after, held_out, renderer, &config, None)?;
    let mut out = (Vec::new(), Vec::new());
    for (shot, a) in held_out.iter().zip(now) {
        let deviation_fit = match found(shot) {
            Some(k) => k.deviation_fit,
            None => before
                .next()
                .map(|b| b.result.deviation_fit)
                .ok_or_else(|| {
                    Error::Run(format!("held-out shot {} has no prediction", shot.name))
                })?,
        };
        out.0.push(Compared {
            name: a.result.name,
            params: a.result.params,
            deviation_fit,
            deviation_after: a.result.deviation_fit,
        });
        out.1.push(a.image);
    }
    Ok(out)
}
