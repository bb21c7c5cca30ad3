//! Which texture maps in the object's frame (`scene::texture`) each
//! backend draws, and the refusal of the others (its `supports`), so
//! that no backend renders another scene than the user's. The one place
//! a backend's list of drawn maps is written.

use super::backend::Refusal;
use crate::scene::texture::MapKind;
use crate::scene::Scene;

/// Every map: the built-in tracer, Blender and Mitsuba draw them all.
const ALL_MAPS: &[MapKind] = &MapKind::ALL;
pub const PHONG: &[MapKind] = ALL_MAPS;
pub const BLENDER: &[MapKind] = ALL_MAPS;
pub const MITSUBA: &[MapKind] = ALL_MAPS;

/// The maps POV-Ray draws: all four, a plane's normal map only where a
/// height field has its slopes (`povray_refusals`).
pub const POVRAY: &[MapKind] = ALL_MAPS;

/// Every map refusal of the Blender worker (`mitsuba` false) or the
/// Mitsuba worker: the maps it does not draw, and what it does not draw
/// them on (`limits`).
pub fn worker_refusals(scene: &Scene, mitsuba: bool) -> Vec<Refusal> {
    let (name, drawn) = if mitsuba {
        ("mitsuba", MITSUBA)
    } else {
        ("blender", BLENDER)
    };
    let mut out = refusals(scene, name, drawn);
    out.extend(limits(scene));
    out
}

/// Every map refusal of POV-Ray: the maps it does not draw, and what it
/// does not draw them on: glass, a specular or shininess map beside
/// `specular2` (each is a patterned texture, and POV-Ray layers nothing
/// over one), or a plane's normal map whose slopes are no height
/// field's there or whose transform scales unevenly (a mesh's, and such a
/// sphere's, quad's or box's, is baked into a mesh's normals,
/// `pov_mesh_bumps`, and drawn whatever it holds).
pub fn povray_refusals(scene: &Scene) -> Vec<Refusal> {
    let mut out = refusals(scene, "povray", POVRAY);
    out.extend(limits(scene));
    for o in &scene.objects {
        let m = &o.material;
        // what POV-Ray cannot draw as a height field it bakes, but on a plane
        let baked = super::pov_mesh_bumps::bakes(o);
        let lays = m.normal_map.as_ref().filter(|_| !baked).and_then(|t| {
            let faces = o.shape.faces();
            let lays: Option<Vec<_>> = faces
                .iter()
                .map(|f| super::pov_bumps::laid(f, t.scale()))
                .collect();
            lays.map(|l| (t, l))
        });
        if let Some((t, lays)) = &lays {
            // an unreadable file is the scene check's to report
            let missed = lays
                .iter()
                .filter_map(|&lay| super::pov_bumps::missed(t, lay).ok().flatten())
                .max_by(f64::total_cmp);
            if let Some(m) = missed {
                let why = super::pov_bumps::not_a_height_field(m);
                out.push(Refusal::new(
                    format!("objects.{}.material.normal_map", o.name),
                    why,
                ));
            }
        }
        if lays.is_some() && super::pov_mesh_bumps::scaled_unevenly(o) {
            out.push(Refusal::new(
                format!("objects.{}.transform.scale", o.name),
                "a normal_map on an object scaled unevenly is not drawn by povray (it turns the height's gradient as a normal, the built-in tracer turns the map's frame); use phong, blender or mitsuba, or scale the shape itself",
            ));
        }
        let patterned = m.specular_map.is_some() || m.shininess_map.is_some();
        if patterned && m.specular2.is_some_and(|k| k > 0.0) {
            out.push(Refusal::new(
                format!("objects.{}.material.specular2", o.name),
                "a second lobe beside a specular_map or shininess_map is not drawn by povray (it layers no texture over a patterned one); use phong, blender or mitsuba",
            ));
        }
    }
    out
}

/// What a worker draws maps on: not glass (Blender's and Mitsuba's
/// principled BSDF, which takes no maps here). A box's faces each hold
/// the map: Blender's box template and Mitsuba's cube carry scenefit's
/// coordinates per face, POV-Ray draws the faces as quads.
fn limits(scene: &Scene) -> Vec<Refusal> {
    let mut out = Vec::new();
    for o in scene.objects.iter().filter(|o| o.material.has_maps()) {
        if o.material.transmission > 0.0 {
            out.push(Refusal::new(
                format!("objects.{}.material.transmission", o.name),
                "texture maps on a transmitting material are drawn by phong only; use phong",
            ));
        }
    }
    out
}

/// A refusal for every map of `scene` that `backend` (drawing `drawn`)
/// cannot draw, naming the field and the backends that draw it.
pub fn refusals(scene: &Scene, backend: &str, drawn: &[MapKind]) -> Vec<Refusal> {
    let mut out = Vec::new();
    for o in &scene.objects {
        for kind in MapKind::ALL {
            if o.material.map(kind).is_none() || drawn.contains(&kind) {
                continue;
            }
            let by: Vec<&str> = [
                ("phong", PHONG),
                ("povray", POVRAY),
                ("blender", BLENDER),
                ("mitsuba", MITSUBA),
            ]
            .iter()
            .filter(|(_, d)| d.contains(&kind))
            .map(|(n, _)| *n)
            .collect();
            let why = if by.is_empty() {
                format!("{} is not drawn by any backend yet; remove it", kind.key())
            } else {
                format!(
                    "{} is not drawn by {backend}; use {}",
                    kind.key(),
                    by.join(" or ")
                )
            };
            out.push(Refusal::new(
                format!("objects.{}.material.{}", o.name, kind.key()),
                why,
            ));
        }
    }
    out
}
