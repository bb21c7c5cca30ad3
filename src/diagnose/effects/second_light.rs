//! `second_light`: a fill light the scene lacks, a smooth additive field.

use super::edit::{free, free_entry, scalar, scale};
use super::Effect;
use crate::diagnose::features::Features;
use crate::scene::field::LightField;
use crate::scene::{Bound, Field, FreeParam, Light, LightKind, Scene};

pub struct SecondLight;

impl Effect for SecondLight {
    fn name(&self) -> &'static str {
        "second_light"
    }

    /// x, y, x², y², xy.
    fn features(&self, f: &Features) -> Vec<Vec<f64>> {
        let (xs, ys) = (&f.xs, &f.ys);
        vec![
            xs.clone(),
            ys.clone(),
            f.map(|i| xs[i] * xs[i]),
            f.map(|i| ys[i] * ys[i]),
            f.map(|i| xs[i] * ys[i]),
        ]
    }

    /// A light of the first light's kind and colour at zero intensity
    /// (up to the first's), placed over the first's position bounds (or
    /// the scene's size around it), or any direction.
    fn extend(&self, scene: &Scene) -> Option<(Scene, Vec<FreeParam>)> {
        let key = scene.lights.first()?;
        let name = (1..)
            .map(|i| format!("fill{i}"))
            .find(|n| scene.light_index(n).is_none())?;
        let (field, lo, hi, start) = match key.kind {
            LightKind::Point => {
                let p = key.position?;
                let r = scale(scene);
                let (lo, hi) = match free_entry(scene, Field::Light(0, LightField::Position)) {
                    Some(f) => (f.min, f.max),
                    None => (
                        Bound::Vector([p[0] - r, p[1] - r, p[2] - r]),
                        Bound::Vector([p[0] + r, p[1] + r, p[2] + r]),
                    ),
                };
                (LightField::Position, lo, hi, p)
            }
            LightKind::Directional => (
                LightField::Direction,
                Bound::Vector([-1.0, -1.0, -1.0]),
                Bound::Vector([1.0, 1.0, 1.0]),
                key.direction?,
            ),
        };
        let mut light = Light {
            name,
            kind: key.kind,
            position: None,
            direction: None,
            color: key.color,
            intensity: 0.0,
            falloff: key.falloff,
            radius: 0.0,
            falloff_power: None,
            distance: key.distance,
        };
        if field == LightField::Position {
            light.position = Some(start);
        } else {
            light.direction = Some(start);
        }
        let max = key.intensity.max(1e-6);
        let mut s = scene.clone();
        s.lights.push(light);
        let i = s.lights.len() - 1;
        let added = vec![
            free(&s, Field::Light(i, field), lo, hi),
            scalar(&s, Field::Light(i, LightField::Intensity), 0.0, max),
        ];
        Some((s, added))
    }
}
