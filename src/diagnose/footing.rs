//! A set's candidates weighed a second time on the residual without the
//! albedo's part: a colour map solved in closed form (`albedo.rs`) for the
//! model before the round and for each candidate's refitted model as it
//! stands (at the side chosen for the model before), the criterion taken between the two mapped models, and the
//! lower of the two criteria counting (diagnosis.json's `footing`).
//!
//! Why: on an object with a painted albedo that no map yet describes, the
//! albedo's misfit is most of the residual (on the trap sets of issue 32
//! a map takes about half the SAD and cannot pay for its own values), so
//! every other effect's gain is a few per cent of it and an imitation (a
//! blurred light standing in for the files' encoding) sits within a few
//! points of the cause. With the texture's part taken out of both sides,
//! the cause's share of what is left is what the criterion sees. The map
//! is a nuisance here, solved the same way for both models and charged to
//! neither; the candidate is still charged for its own values. The plain
//! footing still counts when it is lower: an effect a map could imitate
//! (a fixed camera's vignetting is a gain per surface point) loses its
//! part to the map on this footing, not on the plain one.
//!
//! One photograph solves no map (`albedo.rs`), so only a set's rounds are
//! weighed twice; a closed-form candidate (the map itself) is weighed
//! plainly.

use super::albedo::texture_free;
use super::diagnosis::Footing;
use super::effects;
use super::model::Model;
use super::refits::Refits;
use super::schedule::Schedule;
use super::selection::{delta_bic, overdispersion_of};
use super::Candidate;
use crate::error::Result;

/// Weighs `found` (refitted into `models`, in order) from `model` again
/// on the texture-free footing, over `n` channel values, in round
/// `round`; a candidate whose criterion is lower there takes that
/// footing's criterion, gain and overdispersion. `null`: the unchanged
/// model refitted as the candidates were; its texture-free SAD is the
/// baseline when lower (the drift of a refit is no effect's).
pub(super) fn weigh_texture_free(
    fits: &mut Refits,
    (model, null): (&Model, Option<&Model>),
    found: &mut [Candidate],
    models: &[Model],
    n: f64,
    round: usize,
) -> Result<()> {
    if fits.schedule != Schedule::Set {
        return Ok(());
    }
    // The map's side chosen once, for the model before: every candidate's
    // map is solved at it, so the nuisance is the same on both sides.
    let tag = format!("round{round}_free_before");
    let Some((before, at)) = texture_free(fits, model, &tag, None)? else {
        return Ok(());
    };
    let mut before_sad = before.sad;
    if let Some(null) = null {
        let tag = format!("round{round}_free_null");
        if let Some((m, _)) = texture_free(fits, null, &tag, Some(&at))? {
            before_sad = before_sad.min(m.sad);
        }
    }
    let mut mapped: Vec<Option<Model>> = Vec::with_capacity(found.len());
    for (cand, m) in found.iter().zip(models) {
        let searched = effects::by_name(&cand.effect).is_some_and(|e| !e.closed_form());
        let tag = format!("round{round}_free_{}", cand.effect);
        mapped.push(match searched {
            true => texture_free(fits, m, &tag, Some(&at))?.map(|(m, _)| m),
            false => None,
        });
    }
    // The round's overdispersion on this footing, as `selection::weigh`
    // takes it: of the most general model tried (the lowest SAD).
    let general = mapped
        .iter()
        .flatten()
        .min_by(|a, b| a.sad.total_cmp(&b.sad));
    let Some(general) = general else {
        return Ok(());
    };
    let c = overdispersion_of(general, fits.inputs);
    for (cand, m) in found.iter_mut().zip(&mapped) {
        let Some(m) = m else { continue };
        let (plain_delta_bic, plain_gain) =
            (cand.delta_bic.unwrap_or(0.0), cand.gain.unwrap_or(0.0));
        let free_delta_bic = delta_bic(before_sad, m.sad, n, cand.added_params, c);
        let free_gain = 1.0 - m.sad / before_sad.max(1e-9);
        let free = free_delta_bic < plain_delta_bic;
        if free {
            cand.delta_bic = Some(free_delta_bic);
            cand.gain = Some(free_gain);
            cand.overdispersion = Some(c);
        }
        cand.footing = Some(Footing {
            counted: if free { "texture-free" } else { "plain" },
            plain_delta_bic,
            plain_gain,
            texture_free_delta_bic: free_delta_bic,
            texture_free_gain: free_gain,
            texture_free_overdispersion: c,
        });
    }
    Ok(())
}
