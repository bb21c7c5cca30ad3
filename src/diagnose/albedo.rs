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
use super::model::Model;
use super::refits::Refits;
use super::selection::{delta_bic, overdispersion_of};
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

/// The maps solved for `scene` with each photograph's `own` values,
/// written into the diagnosis directory; the scene naming them and the
/// values solved, or None when no value could be solved.
///
/// The finest side the samples support (`texel_layout.rs`) is a ceiling,
/// not a choice: the maps are solved at it and at each coarser side in
/// turn (every object's side halved), each model scored by the criterion
/// the round applies (`selection::delta_bic`, with the overdispersion of
/// the finest side's residuals), and the best kept; the search stops at
/// the first side that scores worse than the finer one. A finer map thus buys its
/// texels only where its drop in SAD pays for them; `--map-size` fixes
/// the side instead.
fn solve_for(
    fits: &mut Refits,
    scene: &Scene,
    own: &[Params],
    held: Option<&[Image]>,
    (kind, tag): (MapKind, &str),
    at: Option<&[Option<Layout>]>,
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
    let mut best: Option<(f64, Solved)> = None;
    let mut c = None;
    for shift in 0..=MAX_MAP_SIDE.trailing_zeros() {
        let sides = coarser(&ceiling, shift);
        if shift > 0 && sides == coarser(&ceiling, shift - 1) {
            break;
        }
        let Some((s, count, _)) = written(fits, &sides)? else {
            break;
        };
        let Some(m) = fits.model_of(s.clone(), own)? else {
            break;
        };
        // One overdispersion for every side, the finest's: the most general
        // model tried, as the round weighs its candidates (`selection::weigh`).
        let c = *c.get_or_insert_with(|| overdispersion_of(&m, fits.inputs));
        let score = delta_bic(sad0, m.sad, n, count, c);
        if best.as_ref().is_some_and(|b| score >= b.0) {
            break;
        }
        best = Some((score, (s, count, sides)));
    }
    Ok(best.map(|(_, solved)| solved))
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

/// The model with the maps of `kind` (`albedo_map`, `specular_map`):
/// solved, the others refitted (`Refits::after_solve`), solved again, the
/// better of the two kept, a specular map's exponent per texel beside it
/// when that pays (`gloss.rs`); the model and the values solved (None:
/// nothing could be solved).
pub(super) fn solved(
    fits: &mut Refits,
    model: &Model,
    round: usize,
    kind: MapKind,
) -> Result<Option<(Model, usize)>> {
    let first = format!("round{round}_first");
    // The model's renders are its lit evidence: not drawn again.
    let held = Some(&model.images[..]);
    let solve = solve_for(fits, &model.scene, &model.own, held, (kind, &first), None)?;
    let Some((scene, count1, layouts1)) = solve else {
        return Ok(None);
    };
    // The losing map stays on disk until the diagnosis prunes every map
    // its final model does not name (`prune`).
    let (mut fitted, mut count) = (fits.after_solve(&scene, &model.own)?, count1);
    let mut layouts = layouts1;
    // Solved again on the refitted model without the first map: the
    // objects it covered are covered again.
    let bare = without_maps(&fitted.scene, &scene, &model.scene, kind);
    let tag = format!("round{round}");
    let again = solve_for(fits, &bare, &fitted.own, None, (kind, &tag), None)?;
    if let Some((again, count2, layouts2)) = again {
        let own = fitted.own.clone();
        if let Some(m) = fits.model_of(again, &own)? {
            if m.sad < fitted.sad {
                (fitted, count, layouts) = (m, count2, layouts2);
            }
        }
    }
    if kind == MapKind::Specular {
        let tag = format!("round{round}_gloss");
        let shine = super::gloss::beside(fits, &fitted, &model.scene, &layouts, (count, &tag))?;
        if let Some(better) = shine {
            return Ok(Some(better));
        }
    }
    Ok(Some((fitted, count)))
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
    let Some((scene, _, layouts)) = solve_for(fits, &model.scene, &model.own, held, color, at)?
    else {
        return Ok(None);
    };
    Ok(fits.model_of(scene, &model.own)?.map(|m| (m, layouts)))
}
