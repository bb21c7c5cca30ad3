//! `light_color`: each photograph's light has a colour of its own (the
//! LEDs of a light stage, a lamp changed between shots). With one material
//! shared by a set, it shows as each photograph's channels off by factors
//! of their own, which the shared colour cannot follow and the fit then
//! bends the shading to absorb.

use super::edit::{field_of, free, is_free};
use super::Effect;
use crate::diagnose::features::Features;
use crate::scene::field::LightField;
use crate::scene::{Bound, Field, FreeParam, Scene};

pub struct LightColor;

/// How far a light's red and blue may move from its colour, as a factor.
const LOW: f64 = 0.5;
const HIGH: f64 = 1.5;

impl Effect for LightColor {
    fn name(&self) -> &'static str {
        "light_color"
    }

    fn set_only(&self) -> bool {
        true
    }

    /// R: a colour factor scales a channel of the render.
    fn features(&self, f: &Features) -> Vec<Vec<f64>> {
        vec![f.render.to_vec()]
    }

    /// Every light searched per photograph (it moves or changes from one
    /// to the next) whose colour is not searched gets its colour free per
    /// photograph: its chromaticity only, green held at the light's own
    /// (the intensity carries the level, so the search has no direction
    /// that changes nothing), red and blue from half to one and a half
    /// times the light's.
    fn extend(&self, scene: &Scene) -> Option<(Scene, Vec<FreeParam>)> {
        let mut added = Vec::new();
        for (i, light) in scene.lights.iter().enumerate() {
            let moves = scene.free.iter().any(|f| {
                f.per_shot && matches!(field_of(scene, f), Some(Field::Light(j, _)) if j == i)
            });
            let field = Field::Light(i, LightField::Color);
            if !moves || is_free(scene, field) {
                continue;
            }
            let c = light.color;
            let mut entry = free(
                scene,
                field,
                Bound::Vector([LOW * c[0], c[1], LOW * c[2]]),
                Bound::Vector([HIGH * c[0], c[1], HIGH * c[2]]),
            );
            entry.per_shot = true;
            added.push(entry);
        }
        (!added.is_empty()).then(|| (scene.clone(), added))
    }
}
