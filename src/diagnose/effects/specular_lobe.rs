//! `specular_lobe`: a second, broader highlight lobe on every glossy
//! object.

use super::edit::{glossy, scalar};
use super::Effect;
use crate::diagnose::features::Features;
use crate::scene::field::MaterialField;
use crate::scene::{Field, FreeParam, Scene};

pub struct SpecularLobe;

impl Effect for SpecularLobe {
    fn name(&self) -> &'static str {
        "specular_lobe"
    }

    /// The highlight excess and its blur at two scales.
    fn features(&self, f: &Features) -> Vec<Vec<f64>> {
        let (s, s1, s2) = f.highlight();
        vec![s, s1, s2]
    }

    fn extend(&self, scene: &Scene) -> Option<(Scene, Vec<FreeParam>)> {
        let mut s = scene.clone();
        let mut added = Vec::new();
        for i in glossy(scene) {
            let m = &mut s.objects[i].material;
            if m.specular2.is_some() {
                continue;
            }
            m.specular2 = Some(0.0);
            m.shininess2 = Some(m.shininess);
            let lobe = Field::Material(i, MaterialField::Specular2);
            let shininess = Field::Material(i, MaterialField::Shininess2);
            added.push(scalar(&s, lobe, 0.0, 2.0));
            added.push(scalar(&s, shininess, 1.0, 200.0));
        }
        Some((s, added))
    }
}
