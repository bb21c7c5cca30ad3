//! `area_light`: a light with a size, whose soft shadows and highlights
//! blur the shading.

use super::edit::{is_free, scalar};
use super::Effect;
use crate::diagnose::features::Features;
use crate::math::V3;
use crate::scene::field::LightField;
use crate::scene::{Field, FreeParam, LightKind, Scene};

pub struct AreaLight;

impl Effect for AreaLight {
    fn name(&self) -> &'static str {
        "area_light"
    }

    /// The Laplacian of R at two scales (blurring adds it).
    fn features(&self, f: &Features) -> Vec<Vec<f64>> {
        let r = f.render;
        let b1 = f.blur(r, 1);
        let b3 = f.blur(r, 3);
        vec![f.map(|i| b1[i] - r[i]), f.map(|i| b3[i] - r[i])]
    }

    /// The first light without a size gets a radius, up to half its
    /// distance to the look-at point (0.3 for a directional light).
    fn extend(&self, scene: &Scene) -> Option<(Scene, Vec<FreeParam>)> {
        let i = scene.lights.iter().position(|l| l.radius == 0.0)?;
        let l = &scene.lights[i];
        let max = match l.kind {
            LightKind::Point => {
                0.5 * (V3::from(l.position?) - V3::from(scene.camera.target())).length()
            }
            LightKind::Directional => 0.3,
        };
        let field = Field::Light(i, LightField::Radius);
        if is_free(scene, field) {
            return None;
        }
        Some((scene.clone(), vec![scalar(scene, field, 0.0, max)]))
    }
}
