//! `indirect_light`: light bounced off other surfaces, a blurred copy of
//! the direct shading.

use super::edit::scalar;
use super::Effect;
use crate::diagnose::features::Features;
use crate::scene::{Field, FreeParam, Scene};

pub struct IndirectLight;

impl Effect for IndirectLight {
    fn name(&self) -> &'static str {
        "indirect_light"
    }

    /// R blurred over an eighth and a quarter of the image.
    fn features(&self, f: &Features) -> Vec<Vec<f64>> {
        let s = (f.width.max(f.height) / 8).max(1);
        vec![f.blur(f.render, s), f.blur(f.render, 2 * s)]
    }

    fn extend(&self, scene: &Scene) -> Option<(Scene, Vec<FreeParam>)> {
        if scene.indirect_light.is_some() {
            return None;
        }
        let mut s = scene.clone();
        s.indirect_light = Some(0.0);
        let added = scalar(&s, Field::IndirectLight, 0.0, 8.0);
        Some((s, vec![added]))
    }
}
