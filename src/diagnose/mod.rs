//! `scenefit diagnose`: trace the residual of a finished fit to the effect
//! the model lacks, add it, refit, and report the error before and after
//! (docs/diagnose.md).
//!
//! Each round scores every applicable effect (`effects/`) by how much of
//! the residual its feature maps explain (`residual.rs`), then confirms
//! each by refits with the effect added (`refit.rs`): a warm one (from the
//! best of the effect's starts, `starts.rs`, its own parameters and those
//! it trades with searched, then everything refined around the result) and
//! one from scratch (every parameter over its bounds), the better
//! counting. An effect is accepted when its refit lowers the Bayesian
//! information criterion by more than a margin and the sum of absolute
//! differences by at least `min_gain` (`selection.rs`), against the
//! unchanged model refitted the same two ways, so that neither further
//! convergence nor a better basin is credited to an effect. An accepted
//! model is polished (every parameter refined) before the next round.
//! Rounds repeat until nothing is accepted; `unexplained` is reported when
//! smooth structure remains in the residual. Inputs come from a fit
//! directory (`inputs.rs`); the files written are named in `rundir`.

mod albedo;
mod backward;
mod config;
mod diagnosis;
pub mod effects;
pub mod features;
mod held;
mod imitations;
mod inputs;
mod lanes;
pub mod photo;
mod refit;
pub mod report;
pub mod residual;
mod selection;
pub mod set;
mod set_refit;
mod starts;

pub use config::DiagnoseConfig;
pub use diagnosis::{Candidate, Diagnosis, UNEXPLAINED};
pub use inputs::Inputs;

use crate::error::{Error, Result};
use crate::metric::deviation;
use crate::render::{from_spec_with, render_one};
use crate::scene::{ParamSpace, Scene};
use effects::Effect;
use refit::{Model, Refine, Refits, Search};
use residual::Residual;
use selection::samples;
use std::path::Path;
use std::time::Instant;

/// Runs the diagnosis, writing its files into `out`.
pub fn run(inputs: &Inputs, out: &Path, config: &DiagnoseConfig) -> Result<Diagnosis> {
    let started = Instant::now();
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    let renderer = from_spec_with(&config.renderer, &config.render_options)?;
    let (target, mask) = (&inputs.target, inputs.mask.as_ref());
    let (scene, held) = held::split(&inputs.scene, config.refit_geometry);
    let image0 = render_one(renderer.as_ref(), &scene, 0)?;
    let before = deviation(target, &image0, mask);
    let residual_before = Residual::new(target, &image0, mask);
    let mut fits = Refits::new(renderer.as_ref(), inputs, config);
    let mut model = fits.unchanged(Model::new(scene, image0, inputs))?;
    let refined = deviation(target, &model.image, mask);

    let base = model.scene.clone();
    let mut candidates = Vec::new();
    let mut removed = Vec::new();
    let mut imitations = Vec::new();
    let mut steps: Vec<backward::Step> = Vec::new();
    for round in 1..=config.max_rounds {
        let names: Vec<String> = steps.iter().map(|s| s.effect.name().to_string()).collect();
        let found = run_round(&mut fits, &model, &names, round, out)?;
        candidates.extend(found.candidates);
        imitations.extend(found.imitations);
        let Some((step, next)) = found.accepted else {
            break;
        };
        model = next;
        if config.polish_generations > 0 {
            let polished = fits.run(&model.scene, None, Refine::polish(config))?;
            model = model.better(polished);
        }
        steps.push(step);
        let c = selection::overdispersion([(target, &model.image, mask)]);
        let n = samples(target, mask);
        removed.extend(backward::prune(
            &mut fits, &base, &mut steps, &mut model, n, c, config, round,
        )?);
    }
    let mut accepted: Vec<String> = steps.iter().map(|s| s.effect.name().to_string()).collect();

    let residual_after = Residual::new(target, &model.image, mask);
    let unexplained = residual_after.structured();
    if unexplained {
        accepted.push(UNEXPLAINED.into());
    }
    let improved = held::restore(&model.scene, &held);
    let diagnosis = Diagnosis {
        deviation_before: before,
        deviation_after: deviation(target, &model.image, mask),
        candidates,
        accepted,
        params_after: ParamSpace::from_scene(&improved).json_values(&improved),
        deviation_refined: refined,
        unexplained,
        // The refits, and the first render of the fitted model.
        renders: fits.renders + 1,
        wall_seconds: started.elapsed().as_secs_f64(),
        held: held::paths(&held),
        removed,
        imitations,
    };
    albedo::prune(out, &model.scene);
    let residuals = (&residual_before, &residual_after);
    report::write(out, &diagnosis, &improved, &model.image, residuals)?;
    Ok(diagnosis)
}

/// What a round found: its candidates, ranked by evidence (for the
/// report), and the accepted effect's name and model, if any.
struct Round {
    candidates: Vec<Candidate>,
    accepted: Option<(backward::Step, Model)>,
    imitations: Vec<diagnosis::Imitation>,
}

/// One round: every applicable effect not yet accepted, extended, refitted
/// and scored; the criterion chooses.
fn run_round(
    fits: &mut Refits,
    model: &Model,
    accepted: &[String],
    round: usize,
    out: &Path,
) -> Result<Round> {
    let inputs = fits.inputs;
    let residual = Residual::new(&inputs.target, &model.image, inputs.mask.as_ref());
    let open: Vec<&dyn Effect> = effects::ALL
        .iter()
        .copied()
        .filter(|e| !e.set_only() && !accepted.iter().any(|a| a == e.name()))
        .collect();
    let searched: Vec<&dyn Effect> = open.iter().copied().filter(|e| !e.closed_form()).collect();
    let mut refitted = try_effects(fits, model, &searched, round)?.into_iter();
    let mut tried: Vec<(Candidate, (Model, backward::Step))> = Vec::new();
    for effect in open {
        let found = if !effect.closed_form() {
            refitted.next().flatten()
        } else if effect.applies(&model.scene) {
            albedo::candidate(effect.name(), fits, model, round, out)?.map(|(c, m)| (c, m, 0))
        } else {
            None
        };
        if let Some((c, m, form)) = found {
            let evidence = residual.evidence(effect);
            let step = backward::Step { effect, form };
            tried.push((Candidate { evidence, ..c }, (m, step)));
        }
    }
    tried.sort_by(|a, b| b.0.evidence.total_cmp(&a.0.evidence));
    let (mut candidates, models): (Vec<Candidate>, Vec<(Model, backward::Step)>) =
        tried.into_iter().unzip();
    let mask = inputs.mask.as_ref();
    let n = samples(&inputs.target, mask);
    let sads: Vec<f64> = models.iter().map(|m| m.0.sad).collect();
    selection::weigh(&mut candidates, &sads, model.sad, n, |i| {
        selection::overdispersion([(&inputs.target, &models[i].0.image, mask)])
    });
    let chosen = selection::choose(&candidates, fits.config);
    let imitations = chosen.map_or_else(Vec::new, |i| {
        imitations::named(&candidates, i, |j| {
            let (a, b) = (&models[i].0.image, &models[j].0.image);
            imitations::correlation([(&model.image, a, b, mask)])
        })
    });
    let accepted = chosen.and_then(|i| {
        candidates[i].accepted = true;
        models.into_iter().nth(i).map(|(m, step)| (step, m))
    });
    Ok(Round {
        candidates,
        accepted,
        imitations,
    })
}

/// An effect added to the model, ready for its refits.
struct Trial {
    effect: &'static dyn Effect,
    /// The extended scene's best start.
    start: Scene,
    /// The entries its own search moves.
    search: Vec<crate::scene::FreeParam>,
    radius: f64,
    /// Free values added.
    added: usize,
    /// Which of the effect's forms.
    form: usize,
}

/// Each effect added to `model` and refitted warm (from its best start)
/// and, when configured, from scratch, in each of its forms; the best
/// refit counts. None for an effect that does not apply. Every refit of
/// the round runs side by side with the others (`lanes.rs`); candidates'
/// evidence is left at 0. Each with the index of its form.
fn try_effects(
    fits: &mut Refits,
    model: &Model,
    effects: &[&'static dyn Effect],
    round: usize,
) -> Result<Vec<Option<(Candidate, Model, usize)>>> {
    let prepared: Vec<Vec<Trial>> =
        lanes::side_by_side(fits, effects, |f, &e| prepare(f, model, e))
            .into_iter()
            .collect::<Result<_>>()?;
    // Every form of every effect, with the index of its effect.
    let trials: Vec<(usize, Trial)> = prepared
        .into_iter()
        .enumerate()
        .flat_map(|(e, forms)| forms.into_iter().map(move |t| (e, t)))
        .collect();
    let config = fits.config;
    let scratch = config.restart_generations > 0;
    // (trial, from scratch), the refits from scratch first: they are the
    // longest, and lanes take tasks in order.
    let mut refits: Vec<(usize, bool)> = Vec::new();
    for from_scratch in [true, false] {
        if from_scratch && !scratch {
            continue;
        }
        refits.extend((0..trials.len()).map(|i| (i, from_scratch)));
    }
    let done = lanes::side_by_side(fits, &refits, |f, &(i, from_scratch)| {
        let t = &trials[i].1;
        if from_scratch {
            f.run(&t.start, None, Refine::restart(config))
        } else {
            let search = Search {
                params: t.search.clone(),
                radius: t.radius,
            };
            let close = Refine::close(config, config.refine_generations);
            f.run(&t.start, Some(search), close)
        }
    });
    let mut results: Vec<[Option<Model>; 2]> = trials.iter().map(|_| [None, None]).collect();
    for (&(i, from_scratch), m) in refits.iter().zip(done) {
        results[i][from_scratch as usize] = Some(m?);
    }
    // The best refit of each effect over its forms, the neutral form's
    // warm refit first: a tie keeps the earlier.
    let mut best: Vec<Option<(Model, &'static str, &Trial)>> =
        effects.iter().map(|_| None).collect();
    for ((e, t), refitted) in trials.iter().zip(results) {
        for (m, refit) in refitted.into_iter().zip(["warm", "from scratch"]) {
            let Some(m) = m else { continue };
            let slot = &mut best[*e];
            if slot.as_ref().is_none_or(|b| m.sad < b.0.sad) {
                *slot = Some((m, refit, t));
            }
        }
    }
    Ok(best
        .into_iter()
        .map(|b| {
            b.map(|(fitted, refit, t)| {
                let c = Candidate::scored(
                    t.effect.name(),
                    round,
                    fits.inputs,
                    model,
                    &fitted,
                    t.added,
                    refit,
                );
                (c, fitted, t.form)
            })
        })
        .collect())
}

/// `effect` added to `model` in each of its forms, each at its best start
/// (renders counted in `fits`); empty when it does not apply.
fn prepare(fits: &mut Refits, model: &Model, effect: &'static dyn Effect) -> Result<Vec<Trial>> {
    let k0 = ParamSpace::from_scene(&model.scene).dim();
    let mut trials = Vec::new();
    for (form, ext) in effects::forms(effect, &model.scene).into_iter().enumerate() {
        let added = ParamSpace::from_scene(&ext.scene).dim() - k0;
        let (start, count) = starts::best_start(fits.renderer(), &ext, fits.inputs)?;
        fits.renders += count;
        let trades = effect.trades();
        trials.push(Trial {
            effect,
            search: trades.search(&start, &ext.added),
            radius: trades.radius,
            start,
            added,
            form,
        });
    }
    Ok(trials)
}
