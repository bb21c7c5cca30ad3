//! The closed-form effects `albedo_map` and `specular_map`: a colour
//! texture in each object's frame (`material.color_map`), a multiplier of
//! the diffuse colour per texel and channel, or a specular one
//! (`material.specular_map`), a multiplier of the specular strength per
//! texel, shared by every photograph and solved from all of them that see
//! the texel, whatever the camera and light of each (`map_solve.rs`: the
//! evidence, the finest resolution the samples support, a side chosen
//! below it; the side kept here, `solved`). No search could fit it.
//! Values with evidence in fewer than two photographs stay 1 (the scalar
//! colour) and are not counted, so on a single photograph nothing is
//! solved and the effect is no candidate; nor are values whose drop of
//! the SAD does not pay for them in the criterion.
//!
//! The map is solved, the model's other free parameters refitted with it
//! in the scene, and the map solved once more against the refitted model
//! (the better of the two kept); a specular map is then solved once more
//! with an exponent per texel beside it (`gloss.rs`), kept when that
//! pays. Its parameters for the criterion are the values solved, ln N
//! each. The maps are written into the diagnosis
//! directory as 16-bit linear PNG (`map_file.rs`, which names them).

use super::map_evidence::without_maps;
use super::map_solve::{choose, gather, solve_for, solve_gathered, written_at, Side, Solved};
use super::model::Model;
use super::refits::Refits;
use super::selection::{channel_values, delta_bic, overdispersion_of};
use super::texel_layout::Layout;
use crate::error::Result;
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

/// The model with the maps of `kind` (`albedo_map`, `specular_map`) and
/// the values solved (None: nothing could be solved).
///
/// The side is chosen twice, by predicting photographs left out of the
/// solve and by the criterion on the model as it stands (`Side`), and
/// where the two differ each is carried through the refit
/// (`first_solves`, `carried`). The predicted side is kept when,
/// refitted, it pays for its values by the round's criterion (with the
/// overdispersion of the better of the two) and is not dominated (as
/// many values or more for no lower SAD); else the criterion's. So the
/// side is the one that predicts photographs it was not solved from, as
/// long as the criterion would accept it. Neither rule alone holds: on a model still wrong elsewhere
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
    let (first_criterion, first_prediction) = first_solves(fits, model, round, kind)?;
    let mut carry = |first: Option<Solved>, side| {
        first
            .map(|first| carried(fits, model, round, kind, side, first))
            .transpose()
    };
    let by_criterion = carry(first_criterion, Side::Criterion)?;
    let by_prediction = carry(first_prediction, Side::Predicted)?;
    let (a, b) = match (by_criterion, by_prediction) {
        (Some(a), Some(b)) => (a, b),
        (one, other) => return Ok(one.or(other)),
    };
    let general = if a.0.sad <= b.0.sad { &a.0 } else { &b.0 };
    let c = overdispersion_of(general, fits.inputs);
    let n = channel_values(fits.inputs);
    // A predicted side with no fewer values and no lower SAD than the
    // criterion's is dominated: it can only be paying against the model
    // before, which the criterion's side beats with less.
    let dominated = b.1 >= a.1 && b.0.sad >= a.0.sad;
    let pays = !dominated && delta_bic(model.sad, b.0.sad, n, b.1, c) < 0.0;
    Ok(Some(if pays { b } else { a }))
}

/// Each rule's first solve for `model`, both from one evidence (the
/// model's renders are its lit evidence: not drawn again): the
/// criterion's, and the prediction's where its layouts differ (None
/// where they are the same: those maps are already carried). The files
/// of each rule are its own (`_heldout` for the prediction's), so the
/// texels are read once per path.
fn first_solves(
    fits: &mut Refits,
    model: &Model,
    round: usize,
    kind: MapKind,
) -> Result<(Option<Solved>, Option<Solved>)> {
    let (scene, own) = (&model.scene, &model.own);
    let g = gather(fits, scene, own, Some(&model.images[..]), kind)?;
    let tag = format!("round{round}_first");
    let by_criterion = solve_gathered(fits, scene, own, &g, (kind, &tag), None, Side::Criterion)?;
    let tag = format!("round{round}_heldout_first");
    let predicted = choose(fits, scene, own, &g, (kind, &tag), Side::Predicted)?;
    let by_prediction = match predicted {
        Some(p) if by_criterion.as_ref().map(|s| &s.2[..]) != Some(p.layouts()) => {
            written_at(fits, scene, &g, p.layouts(), (kind, &tag))?
        }
        _ => None,
    };
    Ok((by_criterion, by_prediction))
}

/// `solved`'s model from a rule's `first` solve: the others refitted with
/// its maps (`Refits::after_solve`), the maps solved again by the same
/// rule on the refitted model, the better of the two kept, a specular
/// map's exponent per texel beside it when that pays (`gloss.rs`); with
/// the values solved.
fn carried(
    fits: &mut Refits,
    model: &Model,
    round: usize,
    kind: MapKind,
    side: Side,
    (scene, count1, layouts1): Solved,
) -> Result<(Model, usize)> {
    let rule = if side == Side::Predicted {
        "_heldout"
    } else {
        ""
    };
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
        if let Some(better) = shine {
            return Ok(better);
        }
    }
    Ok((fitted, count))
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
