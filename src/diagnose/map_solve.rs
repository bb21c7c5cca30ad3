//! One solve of an object-frame map (`albedo_map`, `specular_map`, the
//! footing's nuisance map): each photograph's evidence gathered once
//! (`map_evidence.rs`), the finest layouts its samples support
//! (`texel_layout.rs`), a side chosen below them by a rule (`Side`), and
//! the maps solved there (`texels.rs`) and written into the diagnosis
//! directory (`map_file.rs`). What the effect does with a solve (refit,
//! solve again, keep a rule's side) is `albedo.rs`'s.

use super::effects::covered;
use super::inputs::Params;
use super::map_evidence::{evidence, with_maps};
use super::map_side;
use super::refits::Refits;
use super::selection::{delta_bic, overdispersion_of};
use super::texel_layout::{layouts, Layout, MAX_MAP_SIDE};
use super::texels::{self, Evidence};
use crate::error::Result;
use crate::metric::Mask;
use crate::raster::Image;
use crate::scene::texture::MapKind;
use crate::scene::Scene;

/// How a solve chooses its maps' side below the finest the samples
/// support (`texel_layout.rs`, a ceiling, not a choice).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Side {
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
/// solved: [`gather`] then [`solve_gathered`].
pub(super) fn solve_for(
    fits: &mut Refits,
    scene: &Scene,
    own: &[Params],
    held: Option<&[Image]>,
    (kind, tag): (MapKind, &str),
    at: Option<&[Option<Layout>]>,
    side: Side,
) -> Result<Option<Solved>> {
    let g = gather(fits, scene, own, held, kind)?;
    solve_gathered(fits, scene, own, &g, (kind, tag), at, side)
}

/// What a solve reads for one model: each photograph's evidence
/// (`map_evidence::evidence`) and the finest layouts its samples support
/// (`texel_layout.rs`, a ceiling, not a choice).
pub(super) struct Gathered<'a> {
    evidence: Vec<Evidence<'a>>,
    pub(super) ceiling: Vec<Option<Layout>>,
}

/// [`Gathered`] for `scene` with each photograph's `own` values (`held`:
/// the lit renders when the caller holds them).
pub(super) fn gather<'a>(
    fits: &mut Refits<'a>,
    scene: &Scene,
    own: &[Params],
    held: Option<&[Image]>,
    kind: MapKind,
) -> Result<Gathered<'a>> {
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
    Ok(Gathered { evidence, ceiling })
}

/// The maps solved from `g` at `at` when given (so two models are
/// compared with the same map), else at the layouts `side` keeps
/// ([`choose`]), written into the diagnosis directory.
pub(super) fn solve_gathered(
    fits: &mut Refits,
    scene: &Scene,
    own: &[Params],
    g: &Gathered,
    (kind, tag): (MapKind, &str),
    at: Option<&[Option<Layout>]>,
    side: Side,
) -> Result<Option<Solved>> {
    let layouts = match at {
        Some(at) => at.to_vec(),
        None => match choose(fits, scene, own, g, (kind, tag), side)? {
            None => return Ok(None),
            Some(Choice::Written(solved)) => return Ok(Some(*solved)),
            Some(Choice::Layouts(layouts)) => layouts,
        },
    };
    written_at(fits, scene, g, &layouts, (kind, tag))
}

/// The maps solved from `g` at `layouts`, written (`written_maps`).
pub(super) fn written_at(
    fits: &Refits,
    scene: &Scene,
    g: &Gathered,
    layouts: &[Option<Layout>],
    (kind, tag): (MapKind, &str),
) -> Result<Option<Solved>> {
    let maps = written_maps(fits, scene, &g.evidence, layouts, (kind, tag))?;
    Ok(maps.map(|(s, count)| (s, count, layouts.to_vec())))
}

/// What a side's rule chose: layouts only (the prediction renders and
/// writes nothing), or the maps the criterion wrote while scoring them.
pub(super) enum Choice {
    Layouts(Vec<Option<Layout>>),
    Written(Box<Solved>),
}

impl Choice {
    pub(super) fn layouts(&self) -> &[Option<Layout>] {
        match self {
            Choice::Layouts(l) => l,
            Choice::Written(s) => &s.2,
        }
    }
}

/// The layouts `side` keeps for `g` (the ceiling when `--map-size` fixes
/// the side): the maps are solved at the ceiling and at each coarser side
/// in turn (every object's side halved), scored by `side`, and the best
/// kept (the finer of two equal scores). Every side is scored: where the
/// photographs fix the camera, the finest sides give each pixel its own
/// texel and score alike, so a search that stopped at the first side no
/// better than the finer one stalled on that plateau and kept a per-pixel
/// map. It stops only at a side where nothing can be solved, or where
/// halving no longer changes a side. None: no value could be solved.
pub(super) fn choose(
    fits: &mut Refits,
    scene: &Scene,
    own: &[Params],
    g: &Gathered,
    (kind, tag): (MapKind, &str),
    side: Side,
) -> Result<Option<Choice>> {
    if fits.config.map_size.is_some() {
        return Ok(Some(Choice::Layouts(g.ceiling.clone())));
    }
    let (n, sad0) = texels::totals(&g.evidence);
    let response = scene.camera.response;
    let mut best: Option<(f64, Choice)> = None;
    let mut c = None;
    for shift in 0..=MAX_MAP_SIDE.trailing_zeros() {
        let sides = coarser(&g.ceiling, shift);
        if shift > 0 && sides == coarser(&g.ceiling, shift - 1) {
            break;
        }
        let (score, choice) = match side {
            Side::Predicted => {
                let score = map_side::held_out_sad(&g.evidence, &sides, response, kind);
                (score, Choice::Layouts(sides))
            }
            Side::Criterion => {
                let Some(solved) = written_at(fits, scene, g, &sides, (kind, tag))? else {
                    break;
                };
                let Some(m) = fits.model_of(solved.0.clone(), own)? else {
                    break;
                };
                // One overdispersion for every side, the finest's: the most
                // general model tried, as the round weighs its candidates.
                let c = *c.get_or_insert_with(|| overdispersion_of(&m, fits.inputs));
                (
                    delta_bic(sad0, m.sad, n, solved.1, c),
                    Choice::Written(Box::new(solved)),
                )
            }
        };
        if best.as_ref().is_some_and(|b| score >= b.0) {
            continue;
        }
        best = Some((score, choice));
    }
    Ok(best.map(|(_, choice)| choice))
}

/// A solve's result: the scene naming the maps, the values solved, and
/// the layouts they were solved at.
pub(super) type Solved = (Scene, usize, Vec<Option<Layout>>);

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
