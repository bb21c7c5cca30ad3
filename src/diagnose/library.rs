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
    /// Other starting points for the effect's search, where the parameters
    /// the fit without it had bent to absorb it are bent back (the diagnosis
    /// renders each and starts from the best, `scene` included).
    pub starts: Vec<Scene>,
    /// Parameters already fitted that the effect trades with, searched
    /// together with its own.
    pub companions: Companions,
}

/// Which fitted parameters join the search of a new effect's own. Light
/// intensities always do, over their whole bounds: an effect often moves
/// the overall level (a falloff exponent by d^Δp, a response by its gain),
/// which the fit without it had absorbed.
#[derive(Clone, Copy, Debug)]
pub struct Companions {
    /// RGB colours, within ±30 % of their span around the fitted values:
    /// Fresnel whitens highlights the fit had matched with its colours.
    /// (Colours for every effect hurt four effects on the generated data.)
    pub colours: bool,
    /// Light positions over their whole bounds: a fit without a falloff
    /// exponent moves the light to fake it (further away for a slower
    /// falloff), too far for a refit close to the fitted values to undo.
    pub light_positions: bool,
    /// Unit-cube radius of the search's start around the current values (1:
    /// uniform over the bounds).
    pub radius: f64,
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
    let starts = match effect {
        "camera_response" => response_starts(&s),
        "light_falloff" => falloff_starts(&s, &added[0].param),
        _ => Vec::new(),
    };
    let companions = Companions {
        colours: effect == "fresnel",
        light_positions: matches!(effect, "light_falloff" | "camera_response"),
        // Both trade with the light's distance along a narrow valley: a
        // start spread over the whole bounds rarely lands in it, so their
        // searches start around the best of their starts.
        radius: if effect == "camera_response" {
            0.35
        } else {
            1.0
        },
    };
    Some(Extension {
        scene: s,
        added,
        starts,
        companions,
    })
}

/// Gammas tried as starts of a camera response search (its bounds: 0.4-2.5).
const GAMMAS: [f64; 11] = [0.5, 0.6, 0.7, 0.8, 0.9, 1.15, 1.35, 1.6, 1.9, 2.2, 2.5];

/// Scales of a point light's distance to the look-at point tried with them.
const DISTANCES: [f64; 5] = [0.55, 0.7, 0.85, 1.0, 1.2];

/// Falloff exponents tried as starts (bounds 0-4).
const POWERS: [f64; 7] = [0.0, 0.5, 1.0, 1.5, 2.5, 3.0, 4.0];

/// Starts for a falloff exponent: a fit without it had faked a slower
/// falloff by moving the light away (a faster one, closer), so each
/// exponent is tried at several distances, the level matched after.
fn falloff_starts(scene: &Scene, param: &str) -> Vec<Scene> {
    use crate::scene::{Field, Value};
    let Ok(field) = Field::resolve(scene, param) else {
        return Vec::new();
    };
    let mut starts = Vec::new();
    for &p in &POWERS {
        let mut s = scene.clone();
        field.set(&mut s, Value::Scalar(p));
        for &d in &DISTANCES {
            starts.push(closer(&s, d));
        }
    }
    starts
}

/// Starts for a camera response. A fit without it had absorbed the curve
/// into its free colours: a target (c L)^γ is matched best by colours c^γ.
/// So each start sets a gamma and bends them back, c -> c^(1/γ), which
/// keeps the colours the fit found and changes only the shading (the
/// start renders c L^γ, its level then matched). A gamma below 1 flattens the shading, which the
/// fit had also faked by moving a free point light away (keeping the
/// irradiance at the look-at point with more intensity), so each gamma is
/// also tried with the light brought closer, and every start also without
/// its specular lobe ([`matte_variant`]). Without these starts, a search
/// over the curve, colours fixed, cannot reach a strong gamma.
fn response_starts(scene: &Scene) -> Vec<Scene> {
    let mut starts = Vec::new();
    for matte in [false, true] {
        let base = if matte {
            matte_variant(scene)
        } else {
            scene.clone()
        };
        for &d in &DISTANCES {
            let near = closer(&base, d);
            for &g in &GAMMAS {
                starts.push(bend(&near, g));
            }
        }
    }
    starts
}

/// `scene` with its free specular levels at their lower bounds: a fit
/// without the response may have faked the curve's flattened or steepened
/// shading with a broad specular lobe, which under the right curve would
/// be far too bright; the refit grows the real lobe back.
fn matte_variant(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    for f in &scene.free {
        if !(f.param.starts_with("objects.") && f.param.ends_with(".material.specular")) {
            continue;
        }
        if let Ok(field) = crate::scene::Field::resolve(scene, &f.param) {
            field.set(&mut s, crate::scene::Value::Scalar(component(f.min, 0)));
        }
    }
    s
}

/// `scene` with its free point lights at `scale` times their distance to
/// the look-at point, their free intensities scaled to keep the irradiance
/// there.
fn closer(scene: &Scene, scale: f64) -> Scene {
    let mut s = scene.clone();
    let look = V3::from(scene.camera.look_at);
    for l in &mut s.lights {
        let Some(p) = l.position else { continue };
        let Some(f) = scene
            .free
            .iter()
            .find(|f| f.param == format!("lights.{}.position", l.name))
        else {
            continue;
        };
        let q = look + (V3::from(p) - look) * scale;
        let q = [q.x, q.y, q.z];
        l.position = Some(std::array::from_fn(|i| {
            q[i].clamp(component(f.min, i), component(f.max, i))
        }));
        let power = l.falloff_power.unwrap_or(match l.falloff {
            Falloff::InverseSquare => 2.0,
            Falloff::None => 0.0,
        });
        l.intensity *= scale.powf(power);
        if let Some(f) = scene
            .free
            .iter()
            .find(|f| f.param == format!("lights.{}.intensity", l.name))
        {
            l.intensity = l.intensity.clamp(component(f.min, 0), component(f.max, 0));
        }
    }
    s
}

/// `scene` with the response's gamma at `g` and its free RGB colours bent
/// back by 1/g (clamped to their bounds); the diagnosis then matches the
/// level with [`match_level`].
fn bend(scene: &Scene, g: f64) -> Scene {
    use crate::scene::{ColorSpace, Field, Value};
    let mut s = scene.clone();
    if let Some(r) = s.camera.response.as_mut() {
        r.gamma = g;
    }
    for f in &scene.free {
        let colour = f.param.ends_with(".color")
            && f.param.starts_with("objects.")
            && f.space == ColorSpace::Rgb;
        if !colour {
            continue;
        }
        let Ok(field) = Field::resolve(scene, &f.param) else {
            continue;
        };
        let back = |v: f64, i: usize| {
            v.max(0.0)
                .powf(1.0 / g)
                .clamp(component(f.min, i), component(f.max, i))
        };
        let value = match field.get(scene) {
            Some(Value::Scalar(v)) => Value::Scalar(back(v, 0)),
            Some(Value::Vector(v)) => Value::Vector([back(v[0], 0), back(v[1], 1), back(v[2], 2)]),
            _ => continue,
        };
        field.set(&mut s, value);
    }
    s
}

/// `scene` with its free light intensities scaled so that its linear image
/// level is multiplied by `k` (through the response's gamma, if any), each
/// clamped to its bounds: a start's level is matched to the target's before
/// it is compared.
pub fn match_level(scene: &Scene, k: f64) -> Scene {
    let gamma = scene.camera.response.map_or(1.0, |r| r.gamma);
    let factor = k.max(0.0).powf(1.0 / gamma.max(1e-3));
    let mut s = scene.clone();
    for l in &mut s.lights {
        let Some(f) = scene
            .free
            .iter()
            .find(|f| f.param == format!("lights.{}.intensity", l.name))
        else {
            continue;
        };
        l.intensity = (l.intensity * factor).clamp(component(f.min, 0), component(f.max, 0));
    }
    s
}

fn component(b: Bound, i: usize) -> f64 {
    match b {
        Bound::Scalar(x) => x,
        Bound::Vector(v) => v[i],
    }
}

/// Which effect a free parameter belongs to (for the report).
pub fn dims(added: &[FreeParam], scene: &Scene) -> usize {
    let space = crate::scene::ParamSpace::from_scene(&Scene {
        free: added.to_vec(),
        ..scene.clone()
    });
    space.dim()
}
