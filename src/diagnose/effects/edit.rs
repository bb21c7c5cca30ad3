//! Typed scene edits the effects share: free entries written from fields,
//! a free entry looked up by field, the parameters an effect trades with,
//! and the starts that move point lights or match a render's level.

use crate::math::V3;
use crate::scene::field::{LightField, MaterialField};
use crate::scene::{Bound, ColorSpace, Falloff, Field, FreeParam, Light, LightKind, Scene, Value};

/// A free entry for `field` of `scene` over `min`..`max`.
pub fn free(scene: &Scene, field: Field, min: Bound, max: Bound) -> FreeParam {
    FreeParam {
        param: field.path(scene),
        min,
        max,
        space: Default::default(),
        phase: None,
        per_shot: false,
    }
}

/// A free entry for a numeric `field` over `min`..`max`.
pub fn scalar(scene: &Scene, field: Field, min: f64, max: f64) -> FreeParam {
    free(scene, field, Bound::Scalar(min), Bound::Scalar(max))
}

/// The field a free entry of `scene` addresses (None: it does not resolve).
pub fn field_of(scene: &Scene, f: &FreeParam) -> Option<Field> {
    Field::resolve(scene, &f.param).ok()
}

/// The free entry of `scene` that searches `field`, if any.
pub fn free_entry(scene: &Scene, field: Field) -> Option<&FreeParam> {
    scene
        .free
        .iter()
        .find(|f| field_of(scene, f) == Some(field))
}

/// True when `field` is searched.
pub fn is_free(scene: &Scene, field: Field) -> bool {
    free_entry(scene, field).is_some()
}

/// The index of the first light of `kind` that `lacks` a field an effect
/// adds.
pub fn first_light(
    scene: &Scene,
    kind: LightKind,
    lacks: impl Fn(&Light) -> bool,
) -> Option<usize> {
    (scene.lights.iter()).position(|l| l.kind == kind && lacks(l))
}

/// Indices of the objects whose specular lobe shows (set or searched).
pub fn glossy(scene: &Scene) -> Vec<usize> {
    (0..scene.objects.len())
        .filter(|&i| {
            scene.objects[i].material.specular > 0.0
                || is_free(scene, Field::Material(i, MaterialField::Specular))
        })
        .collect()
}

/// A rough size of the scene: the distance from the camera to what it looks at.
pub fn scale(scene: &Scene) -> f64 {
    (V3::from(scene.camera.eye()) - V3::from(scene.camera.target())).length()
}

/// Which fitted parameters join the search of a new effect's own. Light
/// intensities always do, over their whole bounds: an effect often moves
/// the overall level (a falloff exponent by d^Δp, a response by its gain),
/// which the fit without it had absorbed.
#[derive(Clone, Copy, Debug)]
pub struct Trades {
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

impl Default for Trades {
    fn default() -> Self {
        Trades {
            colours: false,
            light_positions: false,
            radius: 1.0,
        }
    }
}

impl Trades {
    /// The free entries of `scene` searched with an effect's `added` ones,
    /// in the scene's order, then `added`.
    pub fn search(&self, scene: &Scene, added: &[FreeParam]) -> Vec<FreeParam> {
        scene
            .free
            .iter()
            .filter(|f| !added.iter().any(|a| a.param == f.param))
            .filter_map(|f| self.companion(scene, f))
            .chain(added.iter().cloned())
            .collect()
    }

    /// `f` as it joins the search (None: it stays fixed there).
    fn companion(&self, scene: &Scene, f: &FreeParam) -> Option<FreeParam> {
        match field_of(scene, f)? {
            Field::Light(_, LightField::Intensity) => Some(f.clone()),
            Field::Light(_, LightField::Position) if self.light_positions => Some(f.clone()),
            Field::Light(_, LightField::Color) | Field::Material(_, MaterialField::Color)
                if self.colours && f.space == ColorSpace::Rgb =>
            {
                narrowed(scene, f)
            }
            _ => None,
        }
    }
}

/// A colour entry within ±30 % of its span around its current value.
fn narrowed(scene: &Scene, f: &FreeParam) -> Option<FreeParam> {
    let Value::Vector(v) = field_of(scene, f)?.get(scene)? else {
        return None;
    };
    let mut lo = [0.0; 3];
    let mut hi = [0.0; 3];
    for i in 0..3 {
        let (a, b) = (f.min.at(i), f.max.at(i));
        let r = 0.3 * (b - a);
        lo[i] = (v[i] - r).max(a);
        hi[i] = (v[i] + r).min(b);
    }
    Some(FreeParam {
        min: Bound::Vector(lo),
        max: Bound::Vector(hi),
        ..f.clone()
    })
}

/// Scales of a point light's distance to the look-at point tried as starts.
pub const DISTANCES: [f64; 5] = [0.55, 0.7, 0.85, 1.0, 1.2];

/// `scene` with its free point lights at `scale` times their distance to
/// the look-at point, their free intensities scaled to keep the irradiance
/// there.
pub fn closer(scene: &Scene, scale: f64) -> Scene {
    let mut s = scene.clone();
    let look = V3::from(scene.camera.target());
    for (i, l) in s.lights.iter_mut().enumerate() {
        let Some(p) = l.position else { continue };
        let Some(f) = free_entry(scene, Field::Light(i, LightField::Position)) else {
            continue;
        };
        let q = look + (V3::from(p) - look) * scale;
        let q = [q.x, q.y, q.z];
        l.position = Some(std::array::from_fn(|c| {
            q[c].clamp(f.min.at(c), f.max.at(c))
        }));
        let power = l.falloff_power.unwrap_or(match l.falloff {
            Falloff::InverseSquare => 2.0,
            Falloff::None => 0.0,
        });
        l.intensity *= scale.powf(power);
        if let Some(f) = free_entry(scene, Field::Light(i, LightField::Intensity)) {
            l.intensity = l.intensity.clamp(f.min.at(0), f.max.at(0));
        }
    }
    s
}

/// `scene` with its free light intensities scaled so that its linear image
/// level is multiplied by `k` (through the response's gamma, if any), each
/// clamped to its bounds: a start's level is matched to the target's before
/// it is compared.
pub fn match_level(scene: &Scene, k: f64) -> Scene {
    match_level_where(scene, k, |_| true)
}

/// [`match_level`] over the free intensities whose entries `which` picks
/// (a set's per-shot or shared ones).
pub fn match_level_where(scene: &Scene, k: f64, which: impl Fn(&FreeParam) -> bool) -> Scene {
    let gamma = scene.camera.response.map_or(1.0, |r| r.gamma);
    let factor = k.max(0.0).powf(1.0 / gamma.max(1e-3));
    let mut s = scene.clone();
    for (i, l) in s.lights.iter_mut().enumerate() {
        let Some(f) = free_entry(scene, Field::Light(i, LightField::Intensity)) else {
            continue;
        };
        if which(f) {
            l.intensity = (l.intensity * factor).clamp(f.min.at(0), f.max.at(0));
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_matching_scales_only_the_intensities_picked_through_the_gamma() {
        let mut scene = crate::scene::test_scene::ball(
            r#""color": [0.5, 0.5, 0.5]"#,
            r#"{"param": "lights.key.intensity", "min": 1, "max": 50, "per_shot": true}"#,
        );
        // Not picked: unchanged.
        let same = match_level_where(&scene, 4.0, |f| !f.per_shot);
        assert_eq!(same.lights[0].intensity, 10.0);
        // Picked: the linear level times 4 is the intensity times 4^(1/γ).
        scene.camera.response = Some(crate::scene::Response {
            gamma: 2.0,
            ..Default::default()
        });
        let matched = match_level_where(&scene, 4.0, |f| f.per_shot);
        assert!((matched.lights[0].intensity - 20.0).abs() < 1e-9);
        // Clamped to the entry's bounds.
        let capped = match_level(&scene, 100.0);
        assert_eq!(capped.lights[0].intensity, 50.0);
    }
}
