//! A set's candidates weighed a second time on the residual without the
//! albedo's part: a colour map solved in closed form (`albedo.rs`) for the
//! model before the round and for each candidate's refitted model as it
//! stands (at the side chosen for the model before), the criterion taken
//! between the two mapped models, and the lower of the two criteria
//! counting (diagnosis.json's `footing`).
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
//! Once the diagnosis has added a colour map, each candidate is weighed
//! a third time, against the finest colour map the photographs support
//! (the map's ceiling, `texel_layout.rs`), solved for the model before and
//! for each candidate, again charged to neither; there the higher
//! criterion counts. Why: a map at the side the criterion keeps draws the
//! texture only as well as its texels do, and what it misses is a
//! residual that any global effect can take a share of. On the broad-lobe
//! sets of issue 32 (sRGB files, the response right as assumed) the fit
//! with the true painted albedo reaches 0.0001 %; with the diagnosis's
//! side-32 map 0.18 %, and a false response (a near-sRGB curve) took 17 %
//! of that. An effect that explains the photographs gains whatever the
//! map's side; one that takes only the coarse map's misfit gains nothing
//! against the finest. It is not the whole cure: against the finest map
//! that response still took 8.3 %, the lobe the map was solved against
//! (docs/results.md, "The finest-map footing").
//!
//! One photograph solves no map (`albedo.rs`), so only a set's rounds are
//! weighed again; a closed-form colour map (the map itself) is weighed
//! plainly.

use super::albedo::texture_free;
use super::diagnosis::Footing;
use super::effects;
use super::map_evidence::without_maps;
use super::map_solve::{gather, solve_for, written_at, Side};
use super::model::Model;
use super::refits::Refits;
use super::schedule::Schedule;
use super::selection::{delta_bic, overdispersion_of};
use super::texel_layout::Layout;
use super::Candidate;
use crate::error::Result;
use crate::scene::texture::MapKind;
use crate::scene::Scene;

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
    let Some((c, weighed)) = weighed(fits, found, &mapped, before_sad, n) else {
        return Ok(());
    };
    for (cand, w) in found.iter_mut().zip(weighed) {
        let Some((free_delta_bic, free_gain)) = w else {
            continue;
        };
        let (plain_delta_bic, plain_gain) =
            (cand.delta_bic.unwrap_or(0.0), cand.gain.unwrap_or(0.0));
        let free = free_delta_bic < plain_delta_bic;
        if free {
            cand.delta_bic = Some(free_delta_bic);
            cand.gain = Some(free_gain);
            cand.overdispersion = Some(c);
        }
        cand.footing = Some(Footing {
            counted: if free { "texture-free" } else { "plain" },
            texture_free_delta_bic: Some(free_delta_bic),
            texture_free_gain: Some(free_gain),
            texture_free_overdispersion: Some(c),
            ..Footing::plain(plain_delta_bic, plain_gain)
        });
    }
    Ok(())
}

/// Weighs `found` (refitted into `models`, in order) from `model` again
/// against the finest colour map, when the diagnosis has added one to
/// `model` (`base`: the model before the rounds, whose maps are the
/// user's), over `n` channel values, in round `round`. A candidate whose
/// criterion is higher there takes that footing's criterion, gain and
/// overdispersion. `null` as in [`weigh_texture_free`].
pub(super) fn weigh_finest_map(
    fits: &mut Refits,
    base: &Scene,
    (model, null): (&Model, Option<&Model>),
    found: &mut [Candidate],
    models: &[Model],
    (n, round): (f64, usize),
) -> Result<()> {
    if fits.schedule != Schedule::Set || !adds_colour_map(&model.scene, base) {
        return Ok(());
    }
    let tag = format!("round{round}_finest_before");
    let Some((before, at)) = finest(fits, model, base, &tag)? else {
        return Ok(());
    };
    let mut before_sad = before.sad;
    if let Some(null) = null {
        let tag = format!("round{round}_finest_null");
        if let Some(m) = finest_at(fits, null, base, &tag, &at)? {
            before_sad = before_sad.min(m.sad);
        }
    }
    let mut mapped: Vec<Option<Model>> = Vec::with_capacity(found.len());
    for (cand, m) in found.iter().zip(models) {
        let colour = effects::by_name(&cand.effect).and_then(|e| e.map_kind());
        let tag = format!("round{round}_finest_{}", cand.effect);
        mapped.push(match colour {
            Some(MapKind::Color) => None,
            _ => finest_at(fits, m, base, &tag, &at)?,
        });
    }
    let Some((c, weighed)) = weighed(fits, found, &mapped, before_sad, n) else {
        return Ok(());
    };
    for (cand, w) in found.iter_mut().zip(weighed) {
        let Some((fine_delta_bic, fine_gain)) = w else {
            continue;
        };
        let (counted_delta_bic, counted_gain) =
            (cand.delta_bic.unwrap_or(0.0), cand.gain.unwrap_or(0.0));
        let stricter = fine_delta_bic > counted_delta_bic;
        let footing = cand
            .footing
            .get_or_insert_with(|| Footing::plain(counted_delta_bic, counted_gain));
        footing.finest_map_delta_bic = Some(fine_delta_bic);
        footing.finest_map_gain = Some(fine_gain);
        footing.finest_map_overdispersion = Some(c);
        if stricter {
            footing.counted = "finest-map";
            cand.delta_bic = Some(fine_delta_bic);
            cand.gain = Some(fine_gain);
            cand.overdispersion = Some(c);
        }
    }
    Ok(())
}

/// A footing's overdispersion, and each candidate's criterion and gain
/// there (None: not weighed there).
type Weighed = (f64, Vec<Option<(f64, f64)>>);

/// Each candidate's criterion and gain on a footing whose models are
/// `mapped` (None: not weighed there), from `before_sad`, over `n`
/// channel values; with the overdispersion used, as `selection::weigh`
/// takes it: of the most general model mapped (the lowest SAD). None:
/// no candidate was mapped.
fn weighed(
    fits: &Refits,
    found: &[Candidate],
    mapped: &[Option<Model>],
    before_sad: f64,
    n: f64,
) -> Option<Weighed> {
    let general = mapped
        .iter()
        .flatten()
        .min_by(|a, b| a.sad.total_cmp(&b.sad))?;
    let c = overdispersion_of(general, fits.inputs);
    let each = found.iter().zip(mapped).map(|(cand, m)| {
        let m = m.as_ref()?;
        let gain = 1.0 - m.sad / before_sad.max(1e-9);
        Some((delta_bic(before_sad, m.sad, n, cand.added_params, c), gain))
    });
    Some((c, each.collect()))
}

/// Whether `scene` holds a colour map that `base` does not: one the
/// diagnosis solved.
fn adds_colour_map(scene: &Scene, base: &Scene) -> bool {
    scene.objects.iter().zip(&base.objects).any(|(o, b)| {
        let map = o.material.map(MapKind::Color);
        map.is_some() && map != b.material.map(MapKind::Color)
    })
}

/// `model` with the colour maps the diagnosis added solved again at the
/// finest layouts the photographs support (the ceiling), the files named
/// by `tag`; and those layouts. None: nothing could be solved.
fn finest(
    fits: &mut Refits,
    model: &Model,
    base: &Scene,
    tag: &str,
) -> Result<Option<(Model, Vec<Option<Layout>>)>> {
    let bare = without_maps(&model.scene, &model.scene, base, MapKind::Color);
    let g = gather(fits, &bare, &model.own, None, MapKind::Color)?;
    let Some((scene, _, layouts)) = written_at(fits, &bare, &g, &g.ceiling, (MapKind::Color, tag))?
    else {
        return Ok(None);
    };
    Ok(fits.model_of(scene, &model.own)?.map(|m| (m, layouts)))
}

/// [`finest`] for `model` at the layouts `at` (another model's ceiling:
/// both sides of a comparison hold the same map).
fn finest_at(
    fits: &mut Refits,
    model: &Model,
    base: &Scene,
    tag: &str,
    at: &[Option<Layout>],
) -> Result<Option<Model>> {
    let bare = without_maps(&model.scene, &model.scene, base, MapKind::Color);
    let colour = (MapKind::Color, tag);
    let solved = solve_for(
        fits,
        &bare,
        &model.own,
        None,
        colour,
        Some(at),
        Side::Criterion,
    )?;
    let Some((scene, _, _)) = solved else {
        return Ok(None);
    };
    fits.model_of(scene, &model.own)
}
