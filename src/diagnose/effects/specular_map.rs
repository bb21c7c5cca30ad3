//! `specular_map`: the surface's gloss varies over it (a varnished print,
//! metal flakes beside matte paint, worn patches): a specular strength
//! per texel in the object's frame (`material.specular_map`), shared by
//! every photograph. A render is linear in it, so it is solved in closed
//! form per texel from the highlights every photograph of a set puts on
//! the texel (`diagnose/albedo.rs`), not searched; texels no highlight
//! constrains keep the scalar strength. Where the highlights' widths
//! vary too, a shininess per texel is solved beside the strength
//! (`material.shininess_map`, `diagnose/gloss.rs`), kept only when it
//! pays for its values.

use super::albedo_map::covered;
use super::Effect;
use crate::diagnose::features::Features;
use crate::scene::texture::MapKind;
use crate::scene::{FreeParam, Scene};

pub struct SpecularMap;

impl Effect for SpecularMap {
    fn name(&self) -> &'static str {
        "specular_map"
    }

    /// The highlight excess: a map scales the highlights where they fall.
    fn features(&self, f: &Features) -> Vec<Vec<f64>> {
        vec![f.highlight().0]
    }

    /// Applies while some glossy object has no specular map (`covered`).
    fn extend(&self, scene: &Scene) -> Option<(Scene, Vec<FreeParam>)> {
        if !covered(scene, MapKind::Specular).contains(&true) {
            return None;
        }
        Some((scene.clone(), Vec::new()))
    }

    fn map_kind(&self) -> Option<MapKind> {
        Some(MapKind::Specular)
    }

    /// A shininess map beside the strength where the highlights' widths
    /// vary over the surface (`diagnose/gloss.rs`).
    fn written_kinds(&self) -> Vec<MapKind> {
        vec![MapKind::Specular, MapKind::Shininess]
    }
}
