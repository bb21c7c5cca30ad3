//! `albedo_map`: the object is not uniform (stains, grain, dust): a map of
//! multipliers of the diffuse colour, shared by every photograph, in the
//! image's frame. Solved in closed form per pixel (`diagnose/albedo.rs`),
//! not searched: it adds no free entries.

use super::Effect;
use crate::diagnose::features::Features;
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

    /// Applies while no object has a map and some object has a diffuse
    /// colour for it to multiply.
    fn extend(&self, scene: &Scene) -> Option<(Scene, Vec<FreeParam>)> {
        let objects = &scene.objects;
        if objects.iter().any(|o| o.material.albedo_map.is_some())
            || !objects
                .iter()
                .any(|o| o.material.diffuse > 0.0 && o.material.color != [0.0; 3])
        {
            return None;
        }
        Some((scene.clone(), Vec::new()))
    }

    fn closed_form(&self) -> bool {
        true
    }
}
