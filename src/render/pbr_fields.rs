//! The scene fields the Blender and Mitsuba workers cannot map, refused
//! with a clear error before any worker starts (a worker would silently
//! ignore them and render another scene than the user's).
//!
//! Refused: a point light's `falloff_power` other than 2 (their lights fall
//! off as 1/d^2), a directional light's `radius` (their suns and
//! directional lights are points at infinity here), a material's
//! `specular2` (one lobe). Not refused, documented in docs/renderers.md:
//! `fresnel` (the principled BSDF has its own Fresnel term) and
//! `indirect_light` (the built-in tracer's stand-in for what
//! `render.indirect` traces).

use crate::error::{Error, Result};
use crate::scene::{LightKind, Scene};

/// Err naming the first field `backend` cannot render.
pub fn check(scene: &Scene, backend: &str) -> Result<()> {
    let refuse = |field: String, why: &str| Err(Error::Usage(format!("{backend}: {field}: {why}")));
    for l in &scene.lights {
        if let Some(p) = l.falloff_power.filter(|p| *p != 2.0) {
            return refuse(
                format!("lights.{}.falloff_power {p}", l.name),
                "not supported (its lights fall off as 1/d^2); use phong or povray",
            );
        }
        if l.kind == LightKind::Directional && l.radius > 0.0 {
            return refuse(
                format!("lights.{}.radius", l.name),
                "a directional light of angular size is not supported; use phong",
            );
        }
    }
    for o in &scene.objects {
        if o.material.specular2.is_some_and(|k| k > 0.0) {
            return refuse(
                format!("objects.{}.material.specular2", o.name),
                "a second specular lobe is not supported; use phong",
            );
        }
    }
    Ok(())
}
