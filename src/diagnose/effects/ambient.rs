//! `ambient`: light reaching every surface alike, which shows in the
//! region the lights leave unlit.

use super::edit::{free, is_free};
use super::Effect;
use crate::diagnose::features::Features;
use crate::scene::{Bound, Field, FreeParam, Scene};

pub struct Ambient;

impl Effect for Ambient {
    fn name(&self) -> &'static str {
        "ambient"
    }

    /// The unlit region (R below 2 % of its peak).
    fn features(&self, f: &Features) -> Vec<Vec<f64>> {
        let r = f.render;
        vec![f.map(|i| (r[i] < 0.02 * f.peak) as u8 as f64)]
    }

    fn extend(&self, scene: &Scene) -> Option<(Scene, Vec<FreeParam>)> {
        if is_free(scene, Field::Ambient) {
            return None;
        }
        let added = free(
            scene,
            Field::Ambient,
            Bound::Scalar(0.0),
            Bound::Scalar(0.3),
        );
        Some((scene.clone(), vec![added]))
    }
}
