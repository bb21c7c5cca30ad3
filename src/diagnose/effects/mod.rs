//! The effect library: each effect a model may lack is one type
//! implementing [`Effect`] in its own module, and [`ALL`] lists them in the
//! order the diagnosis tries them. An effect says how the residual it
//! leaves looks (its feature maps), how to add it to a scene at its neutral
//! value (so the extended scene renders as before; `near_light`'s lamp,
//! far but not infinitely, to a level) with its parameters
//! freed, where else its search may start, and which fitted parameters it
//! trades with. Adding an effect: its module, and one line in [`ALL`].

mod albedo_map;
pub(crate) use albedo_map::covered;
mod ambient;
mod area_light;
mod camera_response;
pub mod edit;
mod effect;
mod fresnel;
mod grazing_diffuse;
mod indirect_light;
mod light_color;
mod light_falloff;
mod near_light;
mod second_light;
mod specular_lobe;
mod specular_map;
mod vignetting;

use crate::scene::{FreeParam, Scene};
pub use edit::{match_level, Trades};
pub use effect::Effect;

/// Every effect the diagnosis tries, in this order.
pub static ALL: &[&dyn Effect] = &[
    &ambient::Ambient,
    &light_falloff::LightFalloff,
    &near_light::NearLight,
    &second_light::SecondLight,
    &area_light::AreaLight,
    &vignetting::Vignetting,
    &camera_response::CameraResponse,
    &indirect_light::IndirectLight,
    &fresnel::Fresnel,
    &specular_lobe::SpecularLobe,
    &grazing_diffuse::GrazingDiffuse,
    &light_color::LightColor,
    &albedo_map::AlbedoMap,
    &specular_map::SpecularMap,
];

/// The names of [`ALL`], in order.
pub fn names() -> Vec<&'static str> {
    ALL.iter().map(|e| e.name()).collect()
}

/// The effect named `name` in diagnosis.json.
pub fn by_name(name: &str) -> Option<&'static dyn Effect> {
    ALL.iter().copied().find(|e| e.name() == name)
}

/// A scene with one more effect, ready to be searched.
pub struct Extension {
    /// The scene with the effect at its neutral value, its entries freed.
    pub scene: Scene,
    /// The free entries the effect added.
    pub added: Vec<FreeParam>,
    /// Other starting points (the diagnosis renders each and starts from
    /// the best, `scene` included).
    pub starts: Vec<Scene>,
}

/// `scene` extended by `effect`, or None when it does not apply.
pub fn extend(effect: &dyn Effect, scene: &Scene) -> Option<Extension> {
    let (mut s, added) = effect.extend(scene)?;
    if added.is_empty() {
        return None;
    }
    s.free.extend(added.iter().cloned());
    let starts = effect.starts(&s, &added);
    Some(Extension {
        scene: s,
        added,
        starts,
    })
}

/// Every form of `effect` added to `scene` (the neutral one first, then
/// its [`Effect::variants`]), each with its own starts; empty when it does
/// not apply.
pub fn forms(effect: &dyn Effect, scene: &Scene) -> Vec<Extension> {
    let Some(neutral) = extend(effect, scene) else {
        return Vec::new();
    };
    let variants = effect.variants(&neutral.scene);
    let added = neutral.added.clone();
    let mut out = vec![neutral];
    for scene in variants {
        let starts = effect.starts(&scene, &added);
        out.push(Extension {
            scene,
            added: added.clone(),
            starts,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Field;

    const MATERIAL: &str = r#""color": [0.8, 0.7, 0.1], "specular": 0.3"#;
    // The light's position per photograph, so that the effects of a set
    // (light_color) apply too.
    const FREE: &str = r#"
        {"param": "lights.key.position", "min": [-3, 0.5, -3], "max": [3, 5, 5], "per_shot": true},
        {"param": "lights.key.intensity", "min": 1, "max": 50},
        {"param": "objects.ball.material.color", "min": 0, "max": 1}"#;

    /// The ball lit by a directional light instead (the effects of far
    /// lights: `near_light`), turning per photograph.
    fn far_lit() -> Scene {
        let free = FREE.replace(
            r#""lights.key.position", "min": [-3, 0.5, -3], "max": [3, 5, 5]"#,
            r#""lights.key.direction", "min": [-1, 0, -1], "max": [1, 1, 1]"#,
        );
        // Built with no free entry: a point light's direction does not resolve.
        let mut s = crate::scene::test_scene::ball(MATERIAL, "");
        let l = &mut s.lights[0];
        l.kind = crate::scene::LightKind::Directional;
        l.position = None;
        l.direction = Some([1.0, 3.0, 2.0]);
        l.intensity = 10.0 / 14.0;
        s.free = serde_json::from_str(&format!("[{free}]")).unwrap();
        s
    }

    #[test]
    fn every_effect_extends_a_scene_neutrally_with_resolvable_entries() {
        let scenes = [crate::scene::test_scene::ball(MATERIAL, FREE), far_lit()];
        let n = names();
        for (i, a) in n.iter().enumerate() {
            assert!(!n[i + 1..].contains(a), "{a} twice");
        }
        for &e in ALL.iter().filter(|e| !e.closed_form()) {
            let mut applied = 0;
            for scene in scenes.iter() {
                let Some(ext) = extend(e, scene) else {
                    continue;
                };
                applied += 1;
                // Every added entry resolves in the extended scene to the
                // field it was written from.
                for f in &ext.added {
                    let field = Field::resolve(&ext.scene, &f.param);
                    assert!(field.is_ok(), "{}: {} does not resolve", e.name(), f.param);
                    assert_eq!(field.unwrap().path(&ext.scene), f.param);
                }
                // Neutral: the extended scene renders as before. A near
                // lamp's neutral distance is finite, so it is neutral only
                // to a level (near_light.rs tests how closely).
                if e.name() == "near_light" {
                    continue;
                }
                let r = crate::render::from_spec("phong").unwrap();
                let before = crate::render::render_one(r.as_ref(), scene, 0).unwrap();
                let after = crate::render::render_one(r.as_ref(), &ext.scene, 0).unwrap();
                assert!(
                    before.as_raw() == after.as_raw(),
                    "{} is not neutral",
                    e.name()
                );
            }
            assert!(applied > 0, "{} applies to neither scene", e.name());
        }
    }
}
