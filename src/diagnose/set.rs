//! `diagnose` of a set fit (`fit --shots`): the same rounds as for one
//! photograph, with the evidence pooled over every photograph (each one's
//! R² weighted by its pixels) and every refit a set fit (the shared
//! parameters over all photographs, each photograph's own after them), so
//! that an effect is accepted on the set: an effect shared by every
//! photograph is weak evidence in one and strong across twenty.
//!
//! A candidate's refit here is warm: it starts from the best of the
//! effect's starts over the set (each also with its level matched, every
//! free light intensity scaled, per-shot ones included) and every block of
//! the set fit searches around the current values. The accepted candidate
//! is then refitted from scratch too (every shared value from the centre
//! of its box), and the better of the two kept: a warm refit keeps what
//! the model had bent to absorb the effect it lacked.

pub use super::diagnosis::{SetDiagnosis, ShotAfter};
pub use super::inputs::SetInputs;

use super::backward::{prune, Removal, Step};
use super::diagnosis::Imitation;
use super::effects::{self, Effect};
use super::residual::Residual;
use super::selection::{choose, overdispersion, samples, weigh};
use super::set_refit::{initial, SetModel, SetRefits};
use super::{Candidate, DiagnoseConfig, Diagnosis, UNEXPLAINED};
use crate::error::{Error, Result};
use crate::metric::Deviation;
use crate::render::from_spec_with;
use crate::scene::ParamSpace;
use std::path::Path;
use std::time::Instant;

/// Pooled evidence: each photograph's R² weighted by its pixels.
fn evidence(residuals: &[Residual], effect: &dyn Effect) -> f64 {
    let total: usize = residuals.iter().map(|r| r.pixels.len()).sum();
    residuals
        .iter()
        .map(|r| r.evidence(effect) * r.pixels.len() as f64)
        .sum::<f64>()
        / total.max(1) as f64
}

/// Runs the diagnosis of a set, writing its files into `out`.
pub fn run(inputs: &SetInputs, out: &Path, config: &DiagnoseConfig) -> Result<SetDiagnosis> {
    let started = Instant::now();
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    let renderer = from_spec_with(&config.renderer, &config.render_options)?;
    let (scene, held) = super::held::split(&inputs.scene, config.refit_geometry);
    let model0 = initial(renderer.as_ref(), inputs, scene, config.jobs)?;
    let before = model0.deviations(inputs);
    let residuals_before = model0.residuals(inputs);
    let mut fits = SetRefits {
        renderer: renderer.as_ref(),
        inputs,
        config,
        jobs: config.jobs,
        renders: inputs.shots.len(),
        out,
    };
    let null = fits.run(&model0.scene, &model0.own)?;
    let mut model = model0.clone().better(null);
    let refined = pooled(&model.deviations(inputs), inputs);
    let n: f64 = inputs
        .shots
        .iter()
        .map(|s| samples(&s.target.image, s.target.mask.as_ref()))
        .sum();
    let Rounds {
        candidates,
        mut accepted,
        removed,
        imitations,
    } = rounds(&mut fits, &mut model, n)?;
    if !accepted.is_empty() {
        // The last refit stopped where block descent slows: along a valley
        // where shared and per-shot values trade. A warm refit from there
        // goes on down it.
        let polished = fits.run(&model.scene, &model.own)?;
        model = model.better(polished);
    }
    let residuals_after = model.residuals(inputs);
    let structured = residuals_after.iter().filter(|r| r.structured()).count();
    let unexplained = 2 * structured > residuals_after.len();
    if unexplained {
        accepted.push(UNEXPLAINED.into());
    }
    let after = model.deviations(inputs);
    model.scene = super::held::restore(&model.scene, &held);
    let space = ParamSpace::from_scene(&model.scene);
    let diagnosis = Diagnosis {
        deviation_before: pooled(&before, inputs),
        deviation_after: pooled(&after, inputs),
        candidates,
        accepted,
        params_after: space.shared().json_values(&model.scene),
        deviation_refined: refined,
        unexplained,
        renders: fits.renders,
        wall_seconds: started.elapsed().as_secs_f64(),
        held: super::held::paths(&held),
        removed,
        imitations,
    };
    let (held_out, held_out_images) = predictions(inputs, &model, renderer.as_ref(), config)?;
    let d = SetDiagnosis {
        diagnosis,
        shots_after: shots_after(inputs, &model, &before, &after),
        held_out,
        held_out_images,
    };
    super::albedo::prune(out, &model.scene);
    super::report::write_set(
        out,
        &d,
        &model,
        inputs,
        (&residuals_before, &residuals_after),
    )?;
    Ok(d)
}

/// Each held-out photograph predicted by the fit's model and by `model`.
fn predictions(
    inputs: &SetInputs,
    model: &SetModel,
    renderer: &dyn crate::render::Renderer,
    c: &DiagnoseConfig,
) -> Result<(
    Vec<crate::fit::set::held_out::Compared>,
    Vec<crate::raster::Image>,
)> {
    use crate::fit::set::held_out::{compare, search};
    let models = (&inputs.scene, &model.scene);
    compare(models, &inputs.held_out, renderer, search(c.seed, c.jobs))
}

/// Every photograph's own values after, and its deviations.
fn shots_after(
    inputs: &SetInputs,
    model: &SetModel,
    before: &[Deviation],
    after: &[Deviation],
) -> Vec<ShotAfter> {
    inputs
        .shots
        .iter()
        .enumerate()
        .map(|(i, s)| ShotAfter {
            name: s.name.clone(),
            params: model.own[i].clone(),
            deviation_before: before[i],
            deviation_after: after[i],
        })
        .collect()
}

/// What the rounds of a set found.
struct Rounds {
    candidates: Vec<Candidate>,
    accepted: Vec<String>,
    removed: Vec<Removal>,
    imitations: Vec<Imitation>,
}

/// The rounds: every effect not yet accepted tried on the set, the
/// criterion choosing; `model` becomes the accepted one, and after each
/// acceptance the backward step (`backward.rs`) may take an earlier one
/// out. The candidates of every round, the effects accepted and those
/// removed.
fn rounds(fits: &mut SetRefits, model: &mut SetModel, n: f64) -> Result<Rounds> {
    let base = model.scene.clone();
    let mut candidates = Vec::new();
    let mut steps: Vec<Step> = Vec::new();
    let mut removed = Vec::new();
    let mut imitations = Vec::new();
    for round in 1..=fits.config.max_rounds {
        let accepted: Vec<String> = steps.iter().map(|s| s.effect.name().to_string()).collect();
        let (found, chosen, named) = round_of(fits, model, &accepted, n, round)?;
        candidates.extend(found);
        imitations.extend(named);
        let Some(step) = chosen else {
            break;
        };
        steps.push(step);
        let c = overdispersion_of(model, fits.inputs);
        removed.extend(prune(
            fits,
            &base,
            &mut steps,
            model,
            n,
            c,
            fits.config,
            round,
        )?);
    }
    let accepted = steps.iter().map(|s| s.effect.name().to_string()).collect();
    Ok(Rounds {
        candidates,
        accepted,
        removed,
        imitations,
    })
}

/// The overdispersion of `model`'s residuals over every photograph.
fn overdispersion_of(model: &SetModel, inputs: &SetInputs) -> f64 {
    let pairs = model.images.iter().zip(&inputs.shots);
    overdispersion(pairs.map(|(img, s)| (&s.target.image, img, s.target.mask.as_ref())))
}

/// One round: every effect not in `accepted` tried on the set; its
/// candidates, and the accepted effect's step (`model` then its model).
fn round_of(
    fits: &mut SetRefits,
    model: &mut SetModel,
    accepted: &[String],
    n: f64,
    round: usize,
) -> Result<(Vec<Candidate>, Option<Step>, Vec<Imitation>)> {
    let inputs = fits.inputs;
    let residuals = model.residuals(inputs);
    let k0 = model.dim(inputs);
    let open: Vec<&dyn Effect> = effects::ALL
        .iter()
        .copied()
        .filter(|e| !accepted.iter().any(|a| a == e.name()))
        .collect();
    // The searched effects' refits side by side (`lanes.rs`).
    let searched: Vec<&dyn Effect> = open.iter().copied().filter(|e| !e.closed_form()).collect();
    let best = refit_effects(fits, model, &searched)?;
    let mut refitted = best.into_iter();
    let mut tried: Vec<(Candidate, (SetModel, Step))> = Vec::new();
    for effect in open {
        let (fitted, k, form) = if effect.closed_form() {
            let solved = match effect.applies(&model.scene) {
                true => super::albedo::set_model(fits, model, round)?,
                false => None,
            };
            let Some((fitted, values)) = solved else {
                continue;
            };
            let k = fitted.dim(inputs) + values;
            (fitted, k, 0)
        } else {
            let Some((fitted, form)) = refitted.next().expect("one result per searched effect")
            else {
                continue;
            };
            let k = fitted.dim(inputs);
            (fitted, k, form)
        };
        let candidate = Candidate {
            effect: effect.name().to_string(),
            evidence: evidence(&residuals, effect),
            deviation_after: Some(pooled(&fitted.deviations(inputs), inputs)),
            round,
            delta_bic: None,
            overdispersion: None,
            gain: Some(1.0 - fitted.sad / model.sad.max(1e-9)),
            added_params: k.saturating_sub(k0),
            accepted: false,
            refit: "warm (set)".into(),
        };
        tried.push((candidate, (fitted, Step { effect, form })));
    }
    tried.sort_by(|a, b| b.0.evidence.total_cmp(&a.0.evidence));
    let (mut found, models): (Vec<Candidate>, Vec<(SetModel, Step)>) = tried.into_iter().unzip();
    let (models, forms): (Vec<SetModel>, Vec<Step>) = models.into_iter().unzip();
    weigh_round(&mut found, &models, model.sad, n, inputs);
    let chosen = choose(&found, fits.config);
    let named = chosen.map_or_else(Vec::new, |i| {
        imitations_of(&found, i, &models, model, inputs)
    });
    if let Some(i) = chosen {
        found[i].accepted = true;
        let warm = models.into_iter().nth(i).expect("chosen from these");
        let scratch = fits.scratch(&warm.scene, &warm.own)?;
        if scratch.sad < warm.sad {
            found[i].refit = "warm (set), then from scratch (set)".into();
            found[i].deviation_after = Some(pooled(&scratch.deviations(inputs), inputs));
            *model = scratch;
        } else {
            *model = warm;
        }
    }
    Ok((found, chosen.map(|i| forms[i]), named))
}

/// The effects of a round whose refits changed the renders as the
/// chosen one's did (`imitations.rs`), over every photograph.
fn imitations_of(
    found: &[Candidate],
    chosen: usize,
    models: &[SetModel],
    model: &SetModel,
    inputs: &SetInputs,
) -> Vec<Imitation> {
    super::imitations::named(found, chosen, |j| {
        let views = (0..inputs.shots.len()).map(|s| {
            let mask = inputs.shots[s].target.mask.as_ref();
            let (a, b) = (&models[chosen].images[s], &models[j].images[s]);
            (&model.images[s], a, b, mask)
        });
        super::imitations::correlation(views)
    })
}

/// The round's criterion changes from a model with SAD `sad0`, the
/// overdispersion measured over every photograph.
fn weigh_round(
    found: &mut [Candidate],
    models: &[SetModel],
    sad0: f64,
    n: f64,
    inputs: &SetInputs,
) {
    let sads: Vec<f64> = models.iter().map(|m| m.sad).collect();
    weigh(found, &sads, sad0, n, |i| {
        let pairs = models[i].images.iter().zip(&inputs.shots);
        overdispersion(pairs.map(|(img, s)| (&s.target.image, img, s.target.mask.as_ref())))
    });
}

/// Every form of every effect in `searched` added to `model` and refitted
/// over the set, side by side (`lanes.rs`); each effect's best form (None:
/// it does not apply).
fn refit_effects(
    fits: &mut SetRefits,
    model: &SetModel,
    searched: &[&'static dyn Effect],
) -> Result<Vec<Option<(SetModel, usize)>>> {
    let forms: Vec<(usize, usize, effects::Extension)> = searched
        .iter()
        .enumerate()
        .flat_map(|(i, &e)| {
            effects::forms(e, &model.scene)
                .into_iter()
                .enumerate()
                .map(move |(form, x)| (i, form, x))
        })
        .collect();
    let done = super::lanes::side_by_side(fits, &forms, |f, (i, _, ext)| {
        let (start, own) = f.best_start(ext, &model.own)?;
        // The effect's own parameters spread as its refit for one
        // photograph spreads them: they hold a neutral guess, not a fit.
        let radius = searched[*i].trades().radius;
        let spread = ext
            .added
            .iter()
            .map(|a| (a.param.clone(), radius))
            .collect();
        f.run_spread(&start, &own, spread)
    });
    let mut best: Vec<Option<(SetModel, usize)>> = searched.iter().map(|_| None).collect();
    for ((i, form, _), fitted) in forms.iter().zip(done) {
        let fitted = fitted?;
        best[*i] = Some(match best[*i].take() {
            Some(b) if b.0.sad <= fitted.sad => b,
            _ => (fitted, *form),
        });
    }
    Ok(best)
}

/// The deviation over every photograph.
fn pooled(devs: &[Deviation], inputs: &SetInputs) -> Deviation {
    let parts: Vec<(Deviation, usize)> = devs
        .iter()
        .zip(&inputs.shots)
        .map(|(d, s)| (*d, crate::fit::set::counted(&s.target)))
        .collect();
    Deviation::pooled(&parts)
}
