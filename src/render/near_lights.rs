//! Near lights: a directional light with a `distance` stands for a point
//! light at that distance from the origin along its `direction`, whose
//! irradiance at the origin is the light's `intensity` (so a far light and
//! a near one of the same intensity light the origin alike). A wrapper
//! around every renderer draws it as that point light, so no backend needs
//! to know the field.
//!
//! ```json
//! {"name": "led", "type": "directional", "direction": [0.1, 0.2, 0.97],
//!  "intensity": 3.0, "distance": 12.0}
//! ```
//! A lamp of a light stage or a photometric-stereo rig is a few object
//! sizes away: across the object its direction turns and its irradiance
//! falls off, which a directional light cannot show.

use super::layer::{Layer, Prepared};
use crate::scene::{Falloff, LightKind, ParamSpace, Scene};
use std::borrow::Cow;

/// The layer that draws near lights as point lights, before any backend.
#[derive(Clone, Copy, Debug)]
pub struct NearLights;

impl Layer for NearLights {
    fn prepare<'a>(&self, base: &'a Scene, varying: &'a ParamSpace) -> Prepared<'a> {
        // `varying` still names the direction and distance of a lowered
        // light: the built-in tracer then treats it as a light that turns,
        // which is what it is.
        Ok((lower(base), Cow::Borrowed(varying)))
    }

    fn before(&self, scenes: &[Scene]) -> Option<Vec<Scene>> {
        let near = scenes.iter().any(has_near_lights);
        near.then(|| scenes.iter().map(|s| lower(s).into_owned()).collect())
    }
}

fn has_near_lights(scene: &Scene) -> bool {
    scene
        .lights
        .iter()
        .any(|l| l.kind == LightKind::Directional && l.distance.is_some())
}

/// `scene` with every near light replaced by its point light.
pub fn lower(scene: &Scene) -> Cow<'_, Scene> {
    if !has_near_lights(scene) {
        return Cow::Borrowed(scene);
    }
    let mut s = scene.clone();
    for l in &mut s.lights {
        let (Some(position), Some(d)) = (l.near_position(), l.distance) else {
            continue;
        };
        let power = l.falloff_power.unwrap_or(match l.falloff {
            Falloff::InverseSquare => 2.0,
            Falloff::None => 0.0,
        });
        l.kind = LightKind::Point;
        l.position = Some(position);
        l.direction = None;
        l.distance = None;
        l.intensity *= d.powf(power);
        // A directional light's radius is an angle; a point light's, a length.
        l.radius *= d;
    }
    Cow::Owned(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{from_spec, render_one};

    fn scene(distance: Option<f64>) -> Scene {
        let mut s: Scene = serde_json::from_str(
            r#"{"format": "scenefit-scene/1", "image": {"width": 32, "height": 32},
                "camera": {"type": "orthographic", "position": [0, 0, 5], "look_at": [0, 0, 0],
                           "up": [0, 1, 0], "height": 1.2},
                "lights": [{"name": "l", "type": "directional", "direction": [0, 0.6, 0.8],
                            "intensity": 2.0}],
                "objects": [{"name": "ball", "shape": {"type": "sphere", "center": [0, 0, 0], "radius": 0.5},
                             "material": {"color": [0.5, 0.5, 0.5], "diffuse": 1.0, "specular": 0.0,
                                          "shininess": 10.0}}]}"#,
        )
        .unwrap();
        s.lights[0].distance = distance;
        s
    }

    #[test]
    fn a_near_light_is_a_point_light_lighting_the_origin_alike() {
        let s = lower(&scene(Some(4.0))).into_owned();
        let l = &s.lights[0];
        assert_eq!(l.kind, LightKind::Point);
        let p = l.position.unwrap();
        assert!((p[1] - 2.4).abs() < 1e-12 && (p[2] - 3.2).abs() < 1e-12);
        assert!((l.intensity - 2.0 * 16.0).abs() < 1e-9);
        assert!(matches!(lower(&scene(None)), Cow::Borrowed(_)));
    }

    /// Far away a near light draws what the directional light draws; close
    /// by, the side facing it is brighter and the terminator moves.
    #[test]
    fn a_near_light_tends_to_the_directional_one() {
        let phong = from_spec("phong").unwrap();
        let far = render_one(&*phong, &scene(None), 0).unwrap();
        let dist = |d: f64| {
            let img = render_one(&*phong, &scene(Some(d)), 0).unwrap();
            let diff: u64 = img
                .as_raw()
                .iter()
                .zip(far.as_raw())
                .map(|(a, b)| u64::from(a.abs_diff(*b)))
                .sum();
            diff
        };
        let (near, distant) = (dist(2.0), dist(1000.0));
        assert!(distant * 20 < near, "far {distant}, near {near}");
        // 2,000 radii away the irradiance still varies by 0.1 % over the
        // ball: at most a level here and there.
        let values = 32.0 * 32.0 * 3.0;
        assert!(
            distant as f64 / values < 0.05,
            "2,000 radii away it still differs: {distant}"
        );
    }
}
