//! The rounds of a diagnosis, for one photograph and a set alike: every
//! effect not yet accepted is added to the model in each of its forms,
//! started at its best start and refitted (`schedule.rs` says how), its
//! evidence pooled over the photographs (each one's R² weighted by its
//! pixels: an effect shared by every photograph is weak evidence in one
//! and strong across twenty); the criterion chooses (`selection.rs`), the
//! accepted model is settled, and the backward step (`backward.rs`) may
//! take an earlier effect out.

use super::backward::{prune, Removal, Step};
use super::diagnosis::Imitation;
use super::effects::{self, Effect};
use super::inputs::SetInputs;
use super::lanes::side_by_side;
use super::model::{weighted_mean, Model};
use super::refits::Refits;
use super::residual::Residual;
use super::schedule::Refit;
use super::selection::{choose, overdispersion_of, weigh};
use super::trials::Trial;
use super::Candidate;
use super::DiagnoseConfig;
use crate::error::Result;
use crate::scene::Scene;

/// What the rounds found: the candidates of every round, the effects
/// accepted, those removed again, and the imitations named.
pub(super) struct Rounds {
    pub candidates: Vec<Candidate>,
    pub accepted: Vec<String>,
    pub removed: Vec<Removal>,
    pub imitations: Vec<Imitation>,
}

/// The rounds, over `n` channel values: `model` becomes the accepted
/// one; they end when a round accepts nothing.
pub(super) fn rounds(fits: &mut Refits, model: &mut Model, n: f64) -> Result<Rounds> {
    let base = model.scene.clone();
    let mut candidates = Vec::new();
    let mut steps: Vec<Step> = Vec::new();
    let mut removed = Vec::new();
    let mut imitations = Vec::new();
    for round in 1..=fits.config.max_rounds {
        let accepted: Vec<String> = steps.iter().map(|s| s.effect.name().to_string()).collect();
        let (found, chosen, named) = round_of(fits, model, (&base, &accepted), n, round)?;
        candidates.extend(found);
        imitations.extend(named);
        let Some(step) = chosen else {
            break;
        };
        steps.push(step);
        let c = overdispersion_of(model, fits.inputs);
        let config = fits.config;
        removed.extend(prune(fits, &base, &mut steps, model, n, c, config, round)?);
    }
    let accepted = steps.iter().map(|s| s.effect.name().to_string()).collect();
    Ok(Rounds {
        candidates,
        accepted,
        removed,
        imitations,
    })
}

/// Whether `effect` is tried on these photographs: one that only a set
/// can tell apart from the model is not tried on one photograph, nor one
/// the user's `--effects` leaves out.
fn tried_on(effect: &dyn Effect, inputs: &SetInputs, config: &DiagnoseConfig) -> bool {
    let chosen = config
        .effects
        .as_ref()
        .is_none_or(|names| names.iter().any(|n| n == effect.name()));
    chosen && !(effect.set_only() && inputs.shots.len() < 2)
}

/// Pooled evidence: each photograph's R² weighted by its pixels.
fn evidence(residuals: &[Residual], effect: &dyn Effect) -> f64 {
    let parts: Vec<(f64, f64)> = residuals
        .iter()
        .map(|r| (r.pixels.len() as f64, r.evidence(effect)))
        .collect();
    weighted_mean(&parts)
}

/// One round: every effect not in `accepted` tried; its candidates, ranked
/// by evidence, and the accepted effect's step (`model` then its model).
/// `base`: the model before the rounds (the maps it holds are the user's).
fn round_of(
    fits: &mut Refits,
    model: &mut Model,
    (base, accepted): (&Scene, &[String]),
    n: f64,
    round: usize,
) -> Result<(Vec<Candidate>, Option<Step>, Vec<Imitation>)> {
    let inputs = fits.inputs;
    let residuals = model.residuals(inputs);
    let k0 = model.dim(inputs);
    let open: Vec<&'static dyn Effect> = effects::ALL
        .iter()
        .copied()
        .filter(|e| tried_on(*e, inputs, fits.config) && !accepted.iter().any(|a| a == e.name()))
        .collect();
    let best = try_effects(fits, model, &open, round)?;
    let mut tried: Vec<(Candidate, (Model, Step))> = Vec::new();
    for (&effect, found) in open.iter().zip(best) {
        let Some((fitted, values, form, refit)) = found else {
            continue;
        };
        let candidate = Candidate {
            effect: effect.name().to_string(),
            evidence: evidence(&residuals, effect),
            deviation_after: Some(fitted.deviation(inputs)),
            round,
            delta_bic: None,
            overdispersion: None,
            gain: Some(1.0 - fitted.sad / model.sad.max(1e-9)),
            added_params: (fitted.dim(inputs) + values).saturating_sub(k0),
            accepted: false,
            refit: refit.into(),
            footing: None,
        };
        tried.push((candidate, (fitted, Step { effect, form })));
    }
    tried.sort_by(|a, b| b.0.evidence.total_cmp(&a.0.evidence));
    let (mut found, models): (Vec<Candidate>, Vec<(Model, Step)>) = tried.into_iter().unzip();
    let (models, steps): (Vec<Model>, Vec<Step>) = models.into_iter().unzip();
    // A round's warm refits drift along valleys the fit stopped in
    // (measured: on a trap set five effects whose own value did nothing
    // gained the same 2 % texture-free); the unchanged model refitted the
    // same way takes that drift, and each gain is counted from the better.
    let null = fits.null(model)?;
    let sad0 = null.as_ref().map_or(model.sad, |m| m.sad.min(model.sad));
    for (c, m) in found.iter_mut().zip(&models) {
        c.gain = Some(1.0 - m.sad / sad0.max(1e-9));
    }
    weigh_round(&mut found, &models, sad0, n, inputs);
    let before = (&*model, null.as_ref());
    super::footing::weigh_texture_free(fits, before, &mut found, &models, n, round)?;
    super::footing::weigh_finest_map(fits, base, before, &mut found, &models, (n, round))?;
    let chosen = choose(&found, fits.config);
    let named = chosen.map_or_else(Vec::new, |i| {
        imitations_of(&found, i, &models, model, inputs)
    });
    if let Some(i) = chosen {
        found[i].accepted = true;
        let fitted = models.into_iter().nth(i).expect("chosen from these");
        *model = fits.settle(fitted, &mut found[i])?;
    }
    Ok((found, chosen.map(|i| steps[i]), named))
}

/// What an effect's best refit gave: the model, the values it solved
/// beyond its free ones, its form, and which refit it was.
type Best = (Model, usize, usize, &'static str);

/// Every trial of every effect in `open` (each form, at its best start)
/// refitted, the refits side by side (`lanes.rs`); each effect's best
/// refit over its forms and refits (None: it does not apply).
fn try_effects(
    fits: &mut Refits,
    model: &Model,
    open: &[&'static dyn Effect],
    round: usize,
) -> Result<Vec<Option<Best>>> {
    let prepared: Vec<Vec<Trial>> = side_by_side(fits, open, |f, &e| f.trials(model, e))
        .into_iter()
        .collect::<Result<_>>()?;
    // Every trial, with the index of its effect.
    let trials: Vec<(usize, Trial)> = prepared
        .into_iter()
        .enumerate()
        .flat_map(|(e, forms)| forms.into_iter().map(move |t| (e, t)))
        .collect();
    // (trial, refit), the refits from scratch first: they are the
    // longest, and lanes take tasks in order.
    let mut tasks: Vec<(usize, Refit)> = Vec::new();
    for first in [true, false] {
        for (i, (_, t)) in trials.iter().enumerate() {
            let mine = t.refits.iter().filter(|&&r| (r == Refit::Scratch) == first);
            tasks.extend(mine.map(|&r| (i, r)));
        }
    }
    let done = side_by_side(fits, &tasks, |f, &(i, r)| {
        f.refit(&trials[i].1, r, model, round)
    });
    let mut results: Vec<Vec<Option<(Model, usize)>>> = trials
        .iter()
        .map(|(_, t)| t.refits.iter().map(|_| None).collect())
        .collect();
    for (&(i, r), m) in tasks.iter().zip(done) {
        let slot = trials[i].1.refits.iter().position(|&x| x == r);
        results[i][slot.expect("a refit of this trial")] = m?;
    }
    // The best refit of each effect, trials and refits in order: a tie
    // keeps the earlier.
    let schedule = fits.schedule;
    let mut best: Vec<Option<Best>> = open.iter().map(|_| None).collect();
    for ((e, t), refitted) in trials.iter().zip(results) {
        for (m, &refit) in refitted.into_iter().zip(&t.refits) {
            let Some((m, values)) = m else { continue };
            let slot = &mut best[*e];
            if slot.as_ref().is_none_or(|b| m.sad < b.0.sad) {
                *slot = Some((m, values, t.form, schedule.label(refit)));
            }
        }
    }
    Ok(best)
}

/// The effects of a round whose refits changed the renders as the
/// chosen one's did (`imitations.rs`), over every photograph.
fn imitations_of(
    found: &[Candidate],
    chosen: usize,
    models: &[Model],
    model: &Model,
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
fn weigh_round(found: &mut [Candidate], models: &[Model], sad0: f64, n: f64, inputs: &SetInputs) {
    let sads: Vec<f64> = models.iter().map(|m| m.sad).collect();
    weigh(found, &sads, sad0, n, |i| {
        overdispersion_of(&models[i], inputs)
    });
}
