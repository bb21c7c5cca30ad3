//! What a map's solve reads, for `albedo.rs` and `gloss.rs` alike: each
//! photograph's evidence (the model rendered with the covered objects'
//! maps as they are and at 0, and the surface pass), and the scene with
//! maps set or taken out again.

use super::inputs::Params;
use super::model::shots_of;
use super::refits::Refits;
use super::texels::Evidence;
use crate::error::{Error, Result};
use crate::fit::set::shots::Shot;
use crate::raster::Image;
use crate::render::surface_coords;
use crate::scene::texture::{MapKind, TextureRef};
use crate::scene::Scene;

/// `scene` with each `(object, map)` set as that object's map of `kind`.
pub(super) fn with_maps(scene: &Scene, maps: &[(usize, TextureRef)], kind: MapKind) -> Scene {
    let mut s = scene.clone();
    for (o, t) in maps {
        *s.objects[*o].material.map_slot(kind) = Some(t.clone());
    }
    s
}

/// Each photograph's evidence for `scene` with its `own` values: its
/// model rendered with the covered objects' colours (or specular
/// strengths, by `kind`) as they are (`lit`: `held` when the caller
/// already holds those renders) and at 0 (`dark`), and the surface pass
/// of its camera.
pub(super) fn evidence<'a>(
    fits: &mut Refits<'a>,
    scene: &Scene,
    own: &[Params],
    covered: &[bool],
    held: Option<&[Image]>,
    kind: MapKind,
) -> Result<Vec<Evidence<'a>>> {
    let inputs = fits.inputs;
    let (zero_path, zero) = super::map_file::zero(fits.out, kind)?;
    let probe: Vec<(usize, TextureRef)> = (0..covered.len())
        .filter(|&o| covered[o])
        .map(|o| (o, zero.clone()))
        .collect();
    let dark_scene = with_maps(scene, &probe, kind);
    let (shots, lit) = match held {
        Some(images) => (shots_of(scene, inputs, own)?, images.to_vec()),
        None => rendered(fits, scene, own, kind)?,
    };
    let dark = rendered(fits, &dark_scene, own, kind);
    super::map_file::discard(&zero_path);
    let (_, dark) = dark?;
    Ok(inputs
        .shots
        .iter()
        .zip(shots.iter().zip(lit.into_iter().zip(dark)))
        .map(|(s, (shot, (lit, dark)))| Evidence {
            target: &s.target.image,
            mask: s.target.mask.as_ref(),
            lit,
            dark,
            coords: surface_coords(&shot.scene),
        })
        .collect())
}

/// Each photograph's shot of `scene` with its `own` values, and its
/// render: the lit half of `evidence`, alone for a caller that varies
/// only what the dark render does not see (`gloss.rs`'s exponent).
pub(super) fn rendered(
    fits: &mut Refits,
    scene: &Scene,
    own: &[Params],
    kind: MapKind,
) -> Result<(Vec<Shot>, Vec<Image>)> {
    let shots: Vec<Shot> = shots_of(scene, fits.inputs, own)?;
    let images = fits.render(&shots)?.map(|(images, _)| images);
    let images = images.ok_or_else(|| {
        Error::Run(format!(
            "{}: a render of the photographs failed",
            kind.key()
        ))
    })?;
    Ok((shots, images))
}

/// `scene` with the maps of `kind` that `with` added to `without` removed.
pub(super) fn without_maps(scene: &Scene, with: &Scene, without: &Scene, kind: MapKind) -> Scene {
    let mut s = scene.clone();
    for (o, (a, b)) in s
        .objects
        .iter_mut()
        .zip(with.objects.iter().zip(&without.objects))
    {
        if a.material.map(kind) != b.material.map(kind) {
            *o.material.map_slot(kind) = b.material.map(kind).cloned();
        }
    }
    s
}
