//! The closed-form effects `albedo_map` and `specular_map`: a colour
//! texture in each object's frame (`material.color_map`), a multiplier of
//! the diffuse colour per texel and channel, or a specular one
//! (`material.specular_map`), a multiplier of the specular strength per
//! texel, shared by every photograph and solved from all of them that see
//! the texel, whatever the camera and light of each
//! (`texels.rs`; the finest resolution the samples support in
//! `texel_layout.rs`, the side kept chosen by the criterion in
//! `solve_for`). No search could fit it. Values with evidence in fewer
//! than two photographs stay 1 (the scalar colour) and are not counted,
//! so on a single photograph nothing is solved and the effect is no
//! candidate; nor are values whose drop of the SAD does not pay for them
//! in the criterion.
//!
//! The map is solved, the model's other free parameters refitted with it
//! in the scene, and the map solved once more against the refitted model
//! (the better of the two kept); a specular map is then solved once more
//! with an exponent per texel beside it (`gloss.rs`), kept when that
//! pays. Its parameters for the criterion are the values solved, ln N
//! each. The maps are written into the diagnosis
//! directory as 16-bit linear PNG (`map_file.rs`, which names them).

use super::effects::covered;
use super::inputs::Params;
use super::map_evidence::{evidence, with_maps, without_maps};
use super::map_side;
use super::model::Model;
use super::refits::Refits;
use super::selection::{channel_values, delta_bic, overdispersion_of};
use super::texel_layout::{layouts, Layout, MAX_MAP_SIDE};
use super::texels::{self, Evidence};
use crate::error::{Error, Result};
use crate::metric::Mask;
use crate::raster::Image;
use crate::scene::texture::{MapKind, TextureRef};
use crate::scene::Scene;
use std::path::{Path, PathBuf};

/// Removes from `out` every map file the diagnosis wrote that `kept` (its
/// final model) does not name: the maps of rejected candidates and the
/// probe, which would otherwise read as results.
pub fn prune(out: &Path, kept: &Scene) {
    let named: Vec<PathBuf> = kept
        .objects
        .iter()
        .flat_map(|o| {
            let m = &o.material;
            let file = |t: Option<&TextureRef>| t.map(|t| t.file().to_string());
            let color = file(m.color_map.as_ref());
            let (specular, shininess) = (m.specular_map.as_ref(), m.shininess_map.as_ref());
            [m.albedo_map.clone(), color, file(specular), file(shininess)]
        })
        .flatten()
        .map(PathBuf::from)
        .collect();
    let Ok(entries) = std::fs::read_dir(out) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if !super::map_file::is_map_file(&name) {
            continue;
        }
        let path = e.path();
        let absolute = std::path::absolute(&path).unwrap_or(path.clone());
        if !named.iter().any(|n| n == &absolute || n == &path) {
            super::map_file::discard(&path);
        }
    }
}

/// How a solve chooses its maps' side below the finest the samples
/// support (`texel_layout.rs`, a ceiling, not a choice).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Side {
    /// Each side scored by the criterion on the model as it stands, not
    /// refitted (`selection::delta_bic`, with the overdispersion of the
    /// finest side's residuals): a finer map buys its texels only where
    /// its drop in SAD pays for them.
    Criterion,
    /// Each side scored by how well its maps predict photographs left out
    /// of their solve (`map_side.rs`, no render).
    Predicted,
}

/// The maps solved for `scene` with each photograph's `own` values,
/// written into the diagnosis directory; the scene naming them, the
/// values solved and their layouts, or None when no value could be
/// solved.
///
/// `at` fixes the layouts (so two models are compared with the same map),
/// as `--map-size` fixes the side; otherwise the maps are solved at the
/// ceiling and at each coarser side in turn (every object's side halved),
/// scored by `side`, and the best kept; the search stops at the first
/// side that scores no better than the finer one.
fn solve_for(
    fits: &mut Refits,
    scene: &Scene,
    own: &[Params],
    held: Option<&[Image]>,
    (kind, tag): (MapKind, &str),
    at: Option<&[Option<Layout>]>,
    side: Side,
) -> Result<Option<Solved>> {
    let covered = covered(scene, kind);
    let evidence = evidence(fits, scene, own, &covered, held, kind)?;
    let inside: Vec<_> = evidence
        .iter()
        .map(|e| {
            let (w, h) = e.target.dimensions();
            (&e.coords, Mask::counted(e.mask, (w * h) as usize))
        })
        .collect();
    let ceiling = layouts(scene, &covered, &inside, fits.config.map_size);
    let written = |fits: &mut Refits, layouts: &[Option<Layout>]| {
        let maps = written_maps(fits, scene, &evidence, layouts, (kind, tag))?;
        Ok::<_, Error>(maps.map(|(s, count)| (s, count, layouts.to_vec())))
    };
    if let Some(at) = at {
        return written(fits, at);
    }
    if fits.config.map_size.is_some() {
        return written(fits, &ceiling);
    }
    let (n, sad0) = texels::totals(&evidence);
    let response = scene.camera.response;
    // The best score, its layouts, and its maps when scoring wrote them.
    let mut best: Option<(f64, Vec<Option<Layout>>, Option<Solved>)> = None;
    let mut c = None;
    for shift in 0..=MAX_MAP_SIDE.trailing_zeros() {
        let sides = coarser(&ceiling, shift);
        if shift > 0 && sides == coarser(&ceiling, shift - 1) {
            break;
        }
        let (score, solved) = match side {
            Side::Predicted => {
                let score = map_side::held_out_sad(&evidence, &sides, response, kind);
                (score, None)
            }
            Side::Criterion => {
                let Some(solved) = written(fits, &sides)? else {
                    break;
                };
                let Some(m) = fits.model_of(solved.0.clone(), own)? else {
                    break;
                };
                // One overdispersion for every side, the finest's: the most
                // general model tried, as the round weighs its candidates.
                let c = *c.get_or_insert_with(|| overdispersion_of(&m, fits.inputs));
                (delta_bic(sad0, m.sad, n, solved.1, c), Some(solved))
            }
        };
        if best.as_ref().is_some_and(|b| score >= b.0) {
            break;
        }
        best = Some((score, sides, solved));
    }
    match best {
        Some((_, _, Some(solved))) => Ok(Some(solved)),
        Some((_, sides, None)) => written(fits, &sides),
        None => Ok(None),
    }
}

/// A solve's result: the scene naming the maps, the values solved, and
/// the layouts they were solved at.
type Solved = (Scene, usize, Vec<Option<Layout>>);

/// `ceiling` with every side shifted down by `shift` (at least 1).
fn coarser(ceiling: &[Option<Layout>], shift: u32) -> Vec<Option<Layout>> {
    ceiling
        .iter()
        .map(|l| {
            l.map(|l| Layout {
                side: (l.side >> shift).max(1),
                ..l
            })
        })
        .collect()
}

/// The maps solved at `layouts` from `evidence`, written into the
/// diagnosis directory; `scene` naming them and the values solved (None:
/// nothing solved).
fn written_maps(
    fits: &Refits,
    scene: &Scene,
    evidence: &[Evidence],
    layouts: &[Option<Layout>],
    (kind, tag): (MapKind, &str),
) -> Result<Option<(Scene, usize)>> {
    let solved = texels::solve(evidence, layouts, scene.camera.response, kind);
    if solved.is_empty() {
        return Ok(None);
    }
    let mut refs = Vec::new();
    for map in &solved {
        let path = super::map_file::path(fits.out, kind, tag, map.object, map.layout.side)?;
        refs.push((map.object, super::map_file::write(&path, map)?));
    }
    let count = solved.iter().map(|m| m.count).sum();
    Ok(Some((with_maps(scene, &refs, kind), count)))
}

/// The model with the maps of `kind` (`albedo_map`, `specular_map`) and
/// the values solved (None: nothing could be solved).
///
/// The side is chosen twice, by predicting photographs left out of the
/// solve and by the criterion on the model as it stands (`Side`), and
/// where the two differ each is carried through the refit (`solved_at`).
/// The predicted side is kept when, refitted, it pays for its values by
/// the round's criterion (with the overdispersion of the better of the
/// two); else the criterion's. So the side is the one that predicts
/// photographs it was not solved from, as long as the criterion would
/// accept it. Neither rule alone holds: on a model still wrong elsewhere
/// the unrefitted criterion reads a coarse map's residual along every
/// edge as noise and keeps a side too coarse for the texture (a checkered
/// plane: side 16, the deviation only halved, where side 64 cut it to a
/// quarter and paid for itself once refitted); the prediction keeps the
/// side that draws the texture best, which the round need not pay for (a
/// broad lobe's highlights still unexplained: 3,278 values, refused,
/// where a coarser map was accepted).
pub(super) fn solved(
    fits: &mut Refits,
    model: &Model,
    round: usize,
    kind: MapKind,
) -> Result<Option<(Model, usize)>> {
    let by_criterion = solved_at(fits, model, round, kind, Side::Criterion, None)?;
    let skip = by_criterion.as_ref().map(|(_, _, first)| first.as_slice());
    let by_prediction = solved_at(fits, model, round, kind, Side::Predicted, skip)?;
    let (a, b) = match (by_criterion, by_prediction) {
        (Some(a), Some(b)) => (a, b),
        (one, other) => return Ok(one.or(other).map(|(m, count, _)| (m, count))),
    };
    let general = if a.0.sad <= b.0.sad { &a.0 } else { &b.0 };
    let c = overdispersion_of(general, fits.inputs);
    let n = channel_values(fits.inputs);
    let pays = delta_bic(model.sad, b.0.sad, n, b.1, c) < 0.0;
    let kept = if pays { b } else { a };
    Ok(Some((kept.0, kept.1)))
}

/// A side carried through the refit: the model, the values solved, and
/// the first solve's layouts.
type Carried = (Model, usize, Vec<Option<Layout>>);

/// `solved`'s model with its side chosen by `side`: the maps solved, the
/// others refitted (`Refits::after_solve`), solved again, the better of
/// the two kept, a specular map's exponent per texel beside it when that
/// pays (`gloss.rs`); with the values solved and the first solve's
/// layouts. None: nothing could be solved, or the first solve chose
/// `skip`'s layouts (already carried through).
fn solved_at(
    fits: &mut Refits,
    model: &Model,
    round: usize,
    kind: MapKind,
    side: Side,
    skip: Option<&[Option<Layout>]>,
) -> Result<Option<Carried>> {
    // Each rule's files are its own: the texels are read once per path.
    let rule = if side == Side::Predicted {
        "_heldout"
    } else {
        ""
    };
    let first = format!("round{round}{rule}_first");
    // The model's renders are its lit evidence: not drawn again.
    let held = Some(&model.images[..]);
    let solve = solve_for(
        fits,
        &model.scene,
        &model.own,
        held,
        (kind, &first),
        None,
        side,
    )?;
    let Some((scene, count1, layouts1)) = solve else {
        return Ok(None);
    };
    if skip == Some(&layouts1[..]) {
        return Ok(None);
    }
    let first_layouts = layouts1.clone();
    // The losing map stays on disk until the diagnosis prunes every map
    // its final model does not name (`prune`).
    let (mut fitted, mut count) = (fits.after_solve(&scene, &model.own)?, count1);
    let mut layouts = layouts1;
    // Solved again on the refitted model without the first map: the
    // objects it covered are covered again.
    let bare = without_maps(&fitted.scene, &scene, &model.scene, kind);
    let tag = format!("round{round}{rule}");
    let again = solve_for(fits, &bare, &fitted.own, None, (kind, &tag), None, side)?;
    if let Some((again, count2, layouts2)) = again {
        let own = fitted.own.clone();
        if let Some(m) = fits.model_of(again, &own)? {
            if m.sad < fitted.sad {
                (fitted, count, layouts) = (m, count2, layouts2);
            }
        }
    }
    if kind == MapKind::Specular {
        let tag = format!("round{round}{rule}_gloss");
        let shine = super::gloss::beside(fits, &fitted, &model.scene, &layouts, (count, &tag))?;
        if let Some((better, values)) = shine {
            return Ok(Some((better, values, first_layouts)));
        }
    }
    Ok(Some((fitted, count, first_layouts)))
}

/// `model` with the maps solved for it as it stands (no refit), the files
/// named by `tag`: the model without the albedo's part of its residual
/// (`footing.rs`), and the layouts solved at — `at` when given (so two
/// models are compared with the same map), else the side the criterion
/// keeps. None: no value could be solved. The model's renders are its
/// lit evidence: they are not drawn again.
pub(super) fn texture_free(
    fits: &mut Refits,
    model: &Model,
    tag: &str,
    at: Option<&[Option<Layout>]>,
) -> Result<Option<(Model, Vec<Option<Layout>>)>> {
    let held = Some(&model.images[..]);
    let color = (MapKind::Color, tag);
    let solve = solve_for(
        fits,
        &model.scene,
        &model.own,
        held,
        color,
        at,
        Side::Criterion,
    )?;
    let Some((scene, _, layouts)) = solve else {
        return Ok(None);
    };
    Ok(fits.model_of(scene, &model.own)?.map(|m| (m, layouts)))
}
