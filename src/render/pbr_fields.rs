//! The scene fields the Blender and Mitsuba workers cannot draw, refused
//! with a clear error before any worker starts (a worker would otherwise
//! render another scene than the user's). Everything else is drawn: both
//! workers draw the built-in tracer's material (Lambertian plus normalised
//! Blinn-Phong lobes, `fresnel`, `specular2`) and any `falloff_power`
//! (docs/renderers.md, "One material convention").
//!
//! Refused: a pinhole camera's `distortion` (also by POV-Ray) and, by
//! Mitsuba, its `fy` other than `fx` (non-square pixels), a Mitsuba area light (`radius` > 0: a shape with an area
//! emitter) with a falloff other than 1/d^2, and `fresnel` or `specular2` on a
//! transmitting material (glass is drawn by the principled BSDF, with its
//! own Fresnel term and one lobe), `albedo_map` (a map in the image's
//! frame, drawn by the built-in tracer only) and `diffuse_f90` other than 1
//! (the built-in tracer's grazing factor of the diffuse term), and the
//! texture maps either cannot draw (`maps.rs`). `indirect_light` is the built-in
//! tracer's stand-in for what `render.indirect` traces: not refused.

use super::backend::Refusal;
use crate::scene::{CameraKind, Falloff, LightKind, Scene};

/// What the Blender worker cannot draw (`registry::Backend::supports`).
pub fn blender(scene: &Scene) -> Vec<Refusal> {
    refusals(scene, false)
}

/// What the Mitsuba worker cannot draw (`registry::Backend::supports`).
pub fn mitsuba(scene: &Scene) -> Vec<Refusal> {
    refusals(scene, true)
}

/// A pinhole camera's lens distortion, which the built-in tracer alone
/// draws (the others' cameras have no distortion model); `backend` names
/// the one refusing. None for no distortion, or all coefficients 0.
pub fn distortion(scene: &Scene, backend: &str) -> Option<Refusal> {
    let d = scene.camera.distortion?;
    (d != [0.0; 5]).then(|| {
        Refusal::new(
            "camera.distortion",
            format!("lens distortion is drawn by phong only ({backend}'s camera has no distortion model); use phong, or undistort the photograph (OpenCV's undistort) and drop distortion"),
        )
    })
}

/// Every field either worker cannot draw; `mitsuba` adds what only
/// Mitsuba cannot (area lights are shapes there).
fn refusals(scene: &Scene, mitsuba: bool) -> Vec<Refusal> {
    let name = if mitsuba { "mitsuba" } else { "blender" };
    let mut out: Vec<Refusal> = distortion(scene, name).into_iter().collect();
    out.extend(super::maps::worker_refusals(scene, mitsuba));
    let c = &scene.camera;
    if mitsuba && c.kind == CameraKind::Pinhole && c.fx != c.fy {
        out.push(Refusal::new(
            "camera.fy",
            "Mitsuba's perspective camera has square pixels (its to_world may not scale); give fy the value of fx, or use phong, povray or blender",
        ));
    }
    let mut refuse = |field: String, why: &str| out.push(Refusal::new(field, why));
    for l in &scene.lights {
        if !mitsuba || l.radius <= 0.0 || l.kind != LightKind::Point {
            continue;
        }
        let power = l.falloff_power.unwrap_or(match l.falloff {
            Falloff::InverseSquare => 2.0,
            Falloff::None => 0.0,
        });
        if power != 2.0 {
            refuse(
                format!("lights.{}.radius", l.name),
                "an area light falls off as 1/d^2 here; with falloff_power or falloff \"none\" use radius 0, or phong or blender",
            );
        }
    }
    for o in &scene.objects {
        let m = &o.material;
        if m.albedo_map.is_some() {
            refuse(
                format!("objects.{}.material.albedo_map", o.name),
                "an albedo map in the image's frame is drawn by phong only; use phong",
            );
        }
        if m.diffuse_f90.is_some_and(|f| f != 1.0) {
            refuse(
                format!("objects.{}.material.diffuse_f90", o.name),
                "the grazing factor of the diffuse term is drawn by phong only; use phong",
            );
        }
        if m.transmission <= 0.0 {
            continue;
        }
        if m.specular2.is_some_and(|k| k > 0.0) {
            refuse(
                format!("objects.{}.material.specular2", o.name),
                "a second lobe on a transmitting material is not supported; use phong",
            );
        }
        if m.fresnel.is_some_and(|f| f != 1.0) {
            refuse(
                format!("objects.{}.material.fresnel", o.name),
                "a transmitting material takes its Fresnel term from `ior`; remove `fresnel` or use phong",
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_grazing_factor_is_refused_by_every_other_backend_naming_the_field() {
        let mut scene = crate::scene::test_scene::ball(r#""color": [0.5, 0.5, 0.5]"#, "");
        scene.objects[0].material.diffuse_f90 = Some(1.0);
        assert!(mitsuba(&scene).is_empty(), "1 is Lambertian");
        scene.objects[0].material.diffuse_f90 = Some(0.4);
        let pov = crate::render::pov_sdl::refusals(&scene);
        for refused in [blender(&scene), mitsuba(&scene), pov] {
            assert_eq!(refused.len(), 1, "{refused:?}");
            assert!(
                refused[0].field.ends_with("material.diffuse_f90"),
                "{refused:?}"
            );
        }
    }
}
