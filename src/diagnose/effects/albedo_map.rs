//! `albedo_map`: the object is not uniform (print, stains, grain, dust): a
//! colour texture in the object's frame (`material.color_map`), shared by
//! every photograph. Solved in closed form per texel (`diagnose/albedo.rs`),
//! not searched: it adds no free entries.

use super::Effect;
use crate::diagnose::features::Features;
use crate::scene::texture::MapKind;
use crate::scene::{FreeParam, Scene};

pub struct AlbedoMap;

impl Effect for AlbedoMap {
    fn name(&self) -> &'static str {
        "albedo_map"
    }

    /// R: a map scales the render where it is lit (a gain that varies from
    /// pixel to pixel, which one map over the image cannot show better).
    fn features(&self, f: &Features) -> Vec<Vec<f64>> {
        vec![f.render.to_vec()]
    }

    /// Applies while some object has a diffuse colour for it to multiply
    /// and no map of its own (`covered`).
    fn extend(&self, scene: &Scene) -> Option<(Scene, Vec<FreeParam>)> {
        if !covered(scene, MapKind::Color).contains(&true) {
            return None;
        }
        Some((scene.clone(), Vec::new()))
    }

    fn map_kind(&self) -> Option<MapKind> {
        Some(MapKind::Color)
    }
}

/// The objects a map of `kind` covers. A colour map: those with a diffuse
/// colour for it to multiply and no map of their own (a colour texture,
/// or a map in the image's frame). A specular map: the glossy ones
/// (specular strength above 0 for it to multiply) with no specular map.
pub(crate) fn covered(scene: &Scene, kind: MapKind) -> Vec<bool> {
    scene
        .objects
        .iter()
        .map(|o| {
            let m = &o.material;
            match kind {
                MapKind::Specular => m.specular > 0.0 && m.specular_map.is_none(),
                _ => {
                    m.diffuse > 0.0
                        && m.color != [0.0; 3]
                        && m.color_map.is_none()
                        && m.albedo_map.is_none()
                }
            }
        })
        .collect()
}
