//! `near_light`: a light the scene calls directional is a few object sizes
//! away (a lamp of a light stage or a photometric-stereo rig): across the
//! object its direction turns and its irradiance falls off. The light gets
//! a `distance` (render/near_lights.rs), shared by every photograph of a
//! set: a rig's lamps sit at about one distance from the object.

use super::edit::{field_of, first_light, scalar, scale, Trades};
use super::Effect;
use crate::diagnose::features::Features;
use crate::scene::field::LightField;
use crate::scene::{Field, FreeParam, LightKind, Scene, Value};

pub struct NearLight;

/// The distance's bounds, in units of the scene's size (the camera's
/// distance to what it looks at). The upper bound is the neutral value:
/// that far, the irradiance varies by well under 1 % over an object the
/// camera frames.
const NEAREST: f64 = 0.2;
const FARTHEST: f64 = 50.0;

/// Distances tried as starts, in the same units.
const STARTS: [f64; 6] = [0.5, 1.0, 2.0, 4.0, 8.0, 16.0];

impl Effect for NearLight {
    fn name(&self) -> &'static str {
        "near_light"
    }

    /// A smooth multiplicative ramp: irradiance rising towards the light.
    fn features(&self, f: &Features) -> Vec<Vec<f64>> {
        f.ramp()
    }

    /// The first directional light without a distance gets one, far away.
    fn extend(&self, scene: &Scene) -> Option<(Scene, Vec<FreeParam>)> {
        let i = first_light(scene, LightKind::Directional, |l| l.distance.is_none())?;
        let size = scale(scene);
        if size.is_nan() || size <= 0.0 {
            return None;
        }
        let mut s = scene.clone();
        s.lights[i].distance = Some(FARTHEST * size);
        let added = scalar(
            &s,
            Field::Light(i, LightField::Distance),
            NEAREST * size,
            FARTHEST * size,
        );
        Some((s, vec![added]))
    }

    /// A fit without the distance has nothing it bent to fake it but the
    /// light's direction and level, so the starts only bring the light in.
    fn starts(&self, extended: &Scene, added: &[FreeParam]) -> Vec<Scene> {
        let Some(field) = added.first().and_then(|f| field_of(extended, f)) else {
            return Vec::new();
        };
        let size = scale(extended);
        STARTS
            .iter()
            .map(|&d| {
                let mut s = extended.clone();
                field.set(&mut s, Value::Scalar(d * size));
                s
            })
            .collect()
    }

    /// The distance is searched near its best start: over the whole box a
    /// uniform population would hardly ever come near.
    fn trades(&self) -> Trades {
        Trades {
            radius: 0.15,
            ..Trades::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{from_spec, render_one};

    fn ball() -> Scene {
        crate::scene::parse(
            r#"{"format": "scenefit-scene/1", "image": {"width": 48, "height": 48},
                "camera": {"type": "orthographic", "position": [0, 0, 5], "look_at": [0, 0, 0],
                           "up": [0, 1, 0], "height": 1.2},
                "lights": [{"name": "l", "type": "directional", "direction": [0.3, 0.4, 0.866],
                            "intensity": 3.0}],
                "objects": [{"name": "ball", "shape": {"type": "sphere", "center": [0, 0, 0], "radius": 0.5},
                             "material": {"color": [0.6, 0.6, 0.6], "diffuse": 1.0, "specular": 0.2,
                                          "shininess": 20.0}}],
                "free": [{"param": "lights.l.direction", "min": [-1, -1, 0], "max": [1, 1, 1]}]}"#,
            "near.json",
            &[],
        )
        .unwrap()
    }

    /// Added at its neutral distance, the light draws what it drew; the
    /// starts bring it in, and the distance is freed.
    #[test]
    fn neutral_far_away_and_starts_nearer() {
        let base = ball();
        let (ext, added) = NearLight.extend(&base).expect("a directional light");
        assert_eq!(added[0].param, "lights.l.distance");
        let phong = from_spec("phong").unwrap();
        let (a, b) = (
            render_one(&*phong, &base, 0).unwrap(),
            render_one(&*phong, &ext, 0).unwrap(),
        );
        // 250 units away the irradiance still varies by ±0.4 % over the
        // ball (a level up or down here and there), and along the
        // terminator, where sRGB magnifies the faintest light, the lamp's
        // turn of 0.1 degrees shows by a few levels.
        let diff: Vec<u8> = a
            .as_raw()
            .iter()
            .zip(b.as_raw())
            .map(|(x, y)| x.abs_diff(*y))
            .collect();
        let mean = diff.iter().map(|&d| f64::from(d)).sum::<f64>() / diff.len() as f64;
        let moved = diff.iter().filter(|&&d| d > 1).count();
        assert!(mean < 0.2, "neutral distance: mean difference {mean}");
        assert!(
            moved * 100 < diff.len(),
            "neutral distance moved {moved} values by 2 or more"
        );
        let starts = NearLight.starts(&ext, &added);
        let nearest = starts
            .iter()
            .filter_map(|s| s.lights[0].distance)
            .fold(f64::MAX, f64::min);
        assert!(nearest < 5.0, "nearest start {nearest}");
        assert!(
            NearLight.extend(&ext).is_none(),
            "a light gets one distance"
        );
    }
}
