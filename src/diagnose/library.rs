//! The effect library: for each effect DESIGN.md names, how to extend a
//! scene with it — the optional field set to its neutral value (so the
//! extended scene renders as before) and its parameters freed with bounds.

use crate::math::V3;
use crate::scene::{Bound, Falloff, FreeParam, Light, LightKind, Response, Scene, Vignetting};

/// Every effect the diagnosis tries, in DESIGN.md order.
pub const EFFECTS: [&str; 9] = [
    "ambient",
    "light_falloff",
    "second_light",
    "area_light",
    "vignetting",
    "camera_response",
    "indirect_light",
    "fresnel",
    "specular_lobe",
];

/// A scene with one more effect, and the free entries that effect added.
pub struct Extension {
    pub scene: Scene,
    pub added: Vec<FreeParam>,
}

fn free(param: impl Into<String>, min: Bound, max: Bound) -> FreeParam {
    FreeParam {
        param: param.into(),
        min,
        max,
        space: Default::default(),
        phase: None,
    }
}

fn scalar(param: impl Into<String>, min: f64, max: f64) -> FreeParam {
    free(param, Bound::Scalar(min), Bound::Scalar(max))
}

fn is_free(scene: &Scene, param: &str) -> bool {
    scene.free.iter().any(|f| f.param == param)
}

/// Objects whose specular lobe shows (set or searched).
fn glossy(scene: &Scene) -> Vec<String> {
    scene
        .objects
        .iter()
        .filter(|o| {
            o.material.specular > 0.0
                || is_free(scene, &format!("objects.{}.material.specular", o.name))
        })
        .map(|o| o.name.clone())
        .collect()
}

/// A rough size of the scene: the distance from the camera to what it looks at.
fn scale(scene: &Scene) -> f64 {
    (V3::from(scene.camera.position) - V3::from(scene.camera.look_at)).length()
}

/// `scene` with `effect` added, or None when it does not apply (already
/// there, or nothing it could act on).
pub fn extend(scene: &Scene, effect: &str) -> Option<Extension> {
    let mut s = scene.clone();
    let mut added = Vec::new();
    match effect {
        "ambient" => {
            if is_free(scene, "ambient") {
                return None;
            }
            added.push(free("ambient", Bound::Scalar(0.0), Bound::Scalar(0.3)));
        }
        "light_falloff" => {
            let l = s
                .lights
                .iter_mut()
                .find(|l| l.kind == LightKind::Point && l.falloff_power.is_none())?;
            l.falloff_power = Some(if l.falloff == Falloff::InverseSquare {
                2.0
            } else {
                0.0
            });
            added.push(scalar(format!("lights.{}.falloff_power", l.name), 0.0, 4.0));
        }
        "second_light" => {
            let key = scene.lights.first()?;
            let name = (1..)
                .map(|i| format!("fill{i}"))
                .find(|n| scene.light_index(n).is_none())?;
            let (field, lo, hi, start) = match key.kind {
                LightKind::Point => {
                    let p = key.position?;
                    let own = scene
                        .free
                        .iter()
                        .find(|f| f.param == format!("lights.{}.position", key.name));
                    let r = scale(scene);
                    let (lo, hi) = match own {
                        Some(f) => (f.min, f.max),
                        None => (
                            Bound::Vector([p[0] - r, p[1] - r, p[2] - r]),
                            Bound::Vector([p[0] + r, p[1] + r, p[2] + r]),
                        ),
                    };
                    ("position", lo, hi, p)
                }
                LightKind::Directional => (
                    "direction",
                    Bound::Vector([-1.0, -1.0, -1.0]),
                    Bound::Vector([1.0, 1.0, 1.0]),
                    key.direction?,
                ),
            };
            let mut light = Light {
                name: name.clone(),
                kind: key.kind,
                position: None,
                direction: None,
                color: key.color,
                intensity: 0.0,
                falloff: key.falloff,
                radius: 0.0,
                falloff_power: None,
            };
            if field == "position" {
                light.position = Some(start);
            } else {
                light.direction = Some(start);
            }
            s.lights.push(light);
            added.push(free(format!("lights.{name}.{field}"), lo, hi));
            added.push(scalar(
                format!("lights.{name}.intensity"),
                0.0,
                key.intensity.max(1e-6),
            ));
        }
        "area_light" => {
            let l = s.lights.iter().find(|l| l.radius == 0.0)?;
            let name = l.name.clone();
            let max = match l.kind {
                LightKind::Point => {
                    0.5 * (V3::from(l.position?) - V3::from(scene.camera.look_at)).length()
                }
                LightKind::Directional => 0.3,
            };
            if is_free(scene, &format!("lights.{name}.radius")) {
                return None;
            }
            added.push(scalar(format!("lights.{name}.radius"), 0.0, max));
        }
        "vignetting" => {
            if s.camera.vignetting.is_some() {
                return None;
            }
            s.camera.vignetting = Some(Vignetting { strength: 0.0 });
            added.push(scalar("camera.vignetting.strength", 0.0, 1.0));
        }
        "camera_response" => {
            if s.camera.response.is_some() {
                return None;
            }
            s.camera.response = Some(Response::default());
            added.push(scalar("camera.response.gain", 0.5, 2.0));
            added.push(scalar("camera.response.gamma", 0.4, 2.5));
            added.push(scalar("camera.response.black", 0.0, 0.1));
        }
        "indirect_light" => {
            if s.indirect_light.is_some() {
                return None;
            }
            s.indirect_light = Some(0.0);
            added.push(scalar("indirect_light", 0.0, 8.0));
        }
        "fresnel" => {
            let names = glossy(scene);
            for n in &names {
                let i = s.object_index(n)?;
                if s.objects[i].material.fresnel.is_some() {
                    continue;
                }
                s.objects[i].material.fresnel = Some(1.0);
                added.push(scalar(format!("objects.{n}.material.fresnel"), 0.02, 1.0));
            }
        }
        "specular_lobe" => {
            for n in glossy(scene) {
                let i = s.object_index(&n)?;
                let m = &mut s.objects[i].material;
                if m.specular2.is_some() {
                    continue;
                }
                m.specular2 = Some(0.0);
                m.shininess2 = Some(m.shininess);
                added.push(scalar(format!("objects.{n}.material.specular2"), 0.0, 2.0));
                added.push(scalar(
                    format!("objects.{n}.material.shininess2"),
                    1.0,
                    200.0,
                ));
            }
        }
        _ => return None,
    }
    if added.is_empty() {
        return None;
    }
    s.free.extend(added.iter().cloned());
    Some(Extension { scene: s, added })
}

/// Which effect a free parameter belongs to (for the report).
pub fn dims(added: &[FreeParam], scene: &Scene) -> usize {
    let space = crate::scene::ParamSpace::from_scene(&Scene {
        free: added.to_vec(),
        ..scene.clone()
    });
    space.dim()
}
