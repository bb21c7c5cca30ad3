//! A scene written as POV-Ray 3.7 scene description language, following
//! docs/renderers.md ("POV-Ray"), so that POV-Ray renders what the built-in
//! Phong-Blinn tracer renders.
//!
//! Scene fields read, and how they map:
//! - coordinates: POV-Ray is left-handed; z is mirrored (x, y, z) -> (x, y, -z),
//!   which keeps the image the same with POV-Ray's left-handed camera.
//! - `camera`: perspective (`angle` = horizontal field of view computed from
//!   `fov_y_deg` and the aspect ratio) or orthographic (`up` = height, `right`
//!   = height * aspect); `position`, `look_at`, `up` (as `sky`); `pinhole`:
//!   a perspective camera with its own `direction`, `right` and `up`
//!   built from fx, fy, cx, cy (see `pinhole_camera`); its `distortion` is
//!   refused.
//! - `ambient` A: `global_settings { ambient_light A }` and finish
//!   `ambient kd` (unoccluded, as in Phong).
//! - `render.max_depth` m: `max_trace_level` m + 1 (POV-Ray counts the camera ray).
//! - `render.antialias` n > 1: command-line `+A0.0 +AM1 +Rn -J`, see `povray.rs`.
//! - `render.indirect`: true adds radiosity (POV-Ray's indirect light); the
//!   ambient light is then an emitting sphere around the scene, hidden from
//!   the camera (radiosity ignores finish `ambient`).
//! - lights: `point` -> `light_source` with `fade_distance` FADE_DISTANCE,
//!   `fade_power 2`, colour I*color / (2 FADE_DISTANCE^2) (`inverse_square`),
//!   or colour I*color without fade (`none`); `falloff_power` p: `fade_power`
//!   p with `fade_distance` 1e-8^(1/p); `radius` r > 0 -> a circular,
//!   oriented `area_light` of diameter 2r (9x9). `directional` -> a
//!   `parallel` light 1e6 m away along `direction`, colour E*color.
//! - objects: `sphere`, `plane`, `quad` (`polygon`), `box`, `mesh`
//!   (`mesh2`, with `normal_vectors` when the file has vertex normals); a
//!   normal-mapped mesh, and a primitive whose normal map no height field
//!   has, as a `mesh2` cut finer, its normals the map's (`pov_mesh_bumps`); an
//!   object's `transform` after the shape as `scale`, `rotate`, `translate`
//!   (see `placement`).
//! - names: never written (comments say `lights[i]`, `objects[i]`): the
//!   SDL holds only numbers and fixed keywords, whatever a scene contains.
//! - refused (a clear error): a directional light's `radius`, a material's
//!   `fresnel` (other than 1), `diffuse_f90` (other than 1), `specular2` on glass, `albedo_map`. `indirect_light` (the
//!   built-in tracer's estimate) is not used: `render.indirect` is POV-Ray's.
//! - material (kd, ks, n, kr, kt, ior; T = min(kt, MAX_TRANSMIT)):
//!   pigment `rgbt <color, T>`; finish `ambient kd/(1-T)`,
//!   `diffuse kd/(pi (1-T))` (POV-Ray's diffuse has no 1/pi and is scaled by
//!   1-T), `specular ks (n+8)/(8 pi)`, `roughness 1/n` (Blinn's N.H^n),
//!   `reflection kr`; `interior { ior }` when kt > 0. `specular2` ks2,
//!   `shininess2` n2: a second texture layered on top, fully transparent
//!   (`rgbt <1,1,1,1>`, no ambient, no diffuse) with `specular
//!   ks2 (n2+8)/(8 pi)`, `roughness 1/n2`: POV-Ray adds a layer's highlight
//!   whatever its transparency (measured: the same image as the lobe in the
//!   bottom finish).
//! - texture maps (`color_map`, `specular_map`; `mapped_material`): the
//!   files `pov_maps` wrote into the run directory (the SDL names only
//!   them) as bilinear `image_pattern`s placed by `mapping`; the colour
//!   map as a pigment averaging three channel patterns, the specular map
//!   as a patterned texture blending the texture without and with its
//!   highlight, the shininess map as a patterned texture with an entry
//!   per exponent; a mapped box as a `union` of its six faces, each a
//!   `polygon` with the texture placed on it. Refused
//!   (`maps::povray_refusals`): a map on glass, a specular or shininess
//!   map beside `specular2`.

use super::backend::Refusal;
use super::pov_bumps::{self, Lay};
use super::pov_maps::Channels;
use crate::math::V3;
use crate::scene::pinhole::Pinhole;
use crate::scene::texture::MapKind;
use crate::scene::{
    CameraKind, Falloff, LightKind, Material, Object, Scene, Shape, TextureRef, Transform, Vec3,
};
use std::f64::consts::PI;
use std::fmt::Write;
use std::sync::Arc;

/// `fade_distance` of inverse-square lights, metres. POV-Ray's fade is
/// 2 / (1 + (d/D)^2); with the colour scaled by 1/(2 D^2) that is
/// 1 / (d^2 + D^2): within D^2/d^2 = 1e-6 of 1/d^2 at 10 cm from the light
/// (single-precision colours hold the 5e7 scale without loss).
pub const FADE_DISTANCE: f64 = 1e-4;

/// D^p for any fade power p (see `fade`): 1e-8, so that p = 2 gives D = 0.1 mm.
const FADE_SCALE: f64 = FADE_DISTANCE * FADE_DISTANCE;

/// The largest transmission POV-Ray can render: its surface shading is
/// scaled by 1 - transmit, which we undo by dividing; at 1 that is 0/0.
pub const MAX_TRANSMIT: f64 = 0.999;

/// Radius of the sphere that stands for the ambient environment when
/// radiosity is on.
const ENVIRONMENT_RADIUS: f64 = 1e5;

/// Distance of the stand-in position of a directional light.
const PARALLEL_DISTANCE: f64 = 1e6;

/// Mirrors z: scene (right-handed) -> POV-Ray (left-handed).
fn pov(v: Vec3) -> Vec3 {
    [v[0], v[1], -v[2]]
}

fn vec(v: Vec3) -> String {
    format!("<{}, {}, {}>", num(v[0]), num(v[1]), num(v[2]))
}

/// A number as POV-Ray reads it (shortest exact decimal; no NaN/inf reach here).
fn num(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        format!("{x:e}")
    }
}

fn rgb(c: Vec3, scale: f64) -> String {
    format!("rgb {}", vec([c[0] * scale, c[1] * scale, c[2] * scale]))
}

/// What POV-Ray cannot render of `scene`, if anything.
pub fn refusals(scene: &Scene) -> Vec<Refusal> {
    let mut out = Vec::new();
    if scene.render.max_depth > 254 {
        out.push(Refusal::new(
            "render.max_depth",
            format!(
                "{} asked; POV-Ray traces at most 255 levels",
                scene.render.max_depth
            ),
        ));
    }
    for l in &scene.lights {
        if l.kind == LightKind::Directional && l.radius > 0.0 {
            out.push(Refusal::new(
                format!("lights.{}.radius", l.name),
                "a directional light of angular size is not supported (POV-Ray's parallel lights are points at infinity); use phong or blender",
            ));
        }
    }
    if let Some(r) = super::pbr_fields::distortion(scene, "povray") {
        out.push(r);
    }
    out.extend(super::maps::povray_refusals(scene));
    for o in &scene.objects {
        let m = &o.material;
        if m.albedo_map.is_some() {
            out.push(Refusal::new(
                format!("objects.{}.material.albedo_map", o.name),
                "an albedo map in the image's frame is drawn by phong only; use phong",
            ));
        }
        if m.fresnel.is_some_and(|f| f != 1.0) {
            out.push(Refusal::new(
                format!("objects.{}.material.fresnel", o.name),
                "not supported (POV-Ray's specular highlight has no Fresnel term); use phong, blender or mitsuba",
            ));
        }
        if m.diffuse_f90.is_some_and(|f| f != 1.0) {
            out.push(Refusal::new(
                format!("objects.{}.material.diffuse_f90", o.name),
                "not supported (POV-Ray's diffuse term is Lambertian); use phong",
            ));
        }
        if m.specular2.is_some_and(|k| k > 0.0) && m.transmission > 0.0 {
            out.push(Refusal::new(
                format!("objects.{}.material.specular2", o.name),
                "a second specular lobe on a transmitting material is not supported by POV-Ray; use phong",
            ));
        }
    }
    out
}

/// The fade of a point light whose irradiance falls as 1/d^p: POV-Ray's
/// `2 / (1 + (d/D)^p)` with D^p = FADE_SCALE, times a colour scale of
/// 1/(2 FADE_SCALE), is 1/(d^p + FADE_SCALE): within FADE_SCALE/d^p of 1/d^p.
/// For p = 2, D = 0.1 mm (FADE_DISTANCE). p = 0: no fade.
fn fade(p: f64) -> (f64, String) {
    if p <= 0.0 {
        return (1.0, String::new());
    }
    let d = FADE_SCALE.powf(1.0 / p);
    (
        1.0 / (2.0 * FADE_SCALE),
        format!(" fade_distance {} fade_power {}", num(d), num(p)),
    )
}

/// Where the SDL finds a map's files (`pov_maps::PovMaps::get`).
pub type MapSource<'a> =
    &'a dyn Fn(&TextureRef, MapKind, Option<Lay>) -> Result<Arc<Channels>, String>;

/// The scene file POV-Ray renders, for a scene without texture maps (a
/// map needs files in a run directory: `sdl_with`).
pub fn sdl(scene: &Scene) -> Result<String, String> {
    sdl_with(scene, &|_, k, _| {
        Err(format!("{}: no run directory to write it into", k.key()))
    })
}

/// The scene file POV-Ray renders, its maps' files from `maps`.
pub fn sdl_with(scene: &Scene, maps: MapSource) -> Result<String, String> {
    // a variant may move a free field where POV-Ray cannot follow
    if let Some(r) = refusals(scene).first() {
        return Err(format!("{}: {}", r.field, r.why));
    }
    let mut s = String::with_capacity(4096);
    let _ = writeln!(
        s,
        "// written by scenefit (docs/renderers.md, POV-Ray)\n#version 3.7;"
    );
    let _ = writeln!(
        s,
        "global_settings {{ assumed_gamma 1.0 max_trace_level {} adc_bailout 0 ambient_light {}{} }}",
        scene.render.max_depth + 1,
        rgb(scene.ambient, 1.0),
        if scene.render.indirect { RADIOSITY } else { "" }
    );
    camera(&mut s, scene);
    if scene.render.indirect && scene.ambient.iter().any(|a| *a > 0.0) {
        // radiosity ignores finish ambient: the ambient light becomes an
        // environment of that radiance, hidden from the camera as in the
        // physically based backends
        let _ = writeln!(
            s,
            "// ambient\nsphere {{ <0, 0, 0>, {} hollow no_image no_shadow texture {{ pigment {{ {} }} finish {{ emission 1 ambient 0 diffuse 0 }} }} }}",
            num(ENVIRONMENT_RADIUS),
            rgb(scene.ambient, 1.0)
        );
    }
    for (i, l) in scene.lights.iter().enumerate() {
        light(&mut s, i, l)?;
    }
    for (i, o) in scene.objects.iter().enumerate() {
        object(&mut s, i, o, maps)?;
    }
    Ok(s)
}

/// One object: its shape, its texture and its placement. A box with maps
/// is its six faces (`Shape::faces`), each a polygon with the texture
/// placed on it: POV-Ray's `box` has no coordinates per face.
fn object(s: &mut String, i: usize, o: &Object, maps: MapSource) -> Result<(), String> {
    let mapped = o.material.has_maps();
    let place = o.transform.as_ref().map_or(String::new(), placement);
    if super::pov_mesh_bumps::bakes(o) {
        let text = super::pov_mesh_bumps::written(o, |m| mesh2(m, true))?;
        // its other maps laid as a mesh's, by the baked texture coordinates
        let as_mesh = Object {
            shape: Shape::Mesh {
                file: String::new(),
            },
            ..o.clone()
        };
        let texture = mapped_material(&as_mesh, maps)?;
        let _ = writeln!(
            s,
            "// objects[{i}], baked with its normal map\n{text}\n  {texture}{place}\n}}"
        );
        return Ok(());
    }
    if mapped && matches!(o.shape, Shape::Box { .. }) {
        let _ = writeln!(s, "// objects[{i}], a box as its six faces\nunion {{");
        for face in o.shape.faces() {
            let face = Object {
                shape: face,
                transform: None,
                ..o.clone()
            };
            let (shape, texture) = (shape_of(&face, true)?, mapped_material(&face, maps)?);
            let _ = writeln!(s, "{shape}\n  {texture}\n}}");
        }
        let _ = writeln!(s, "{place}\n}}");
        return Ok(());
    }
    let shape = shape_of(o, mapped)?;
    let texture = if mapped {
        mapped_material(o, maps)?
    } else {
        material(&o.material)
    };
    // names are never written: the SDL holds only numbers and keywords
    let _ = writeln!(s, "// objects[{i}]\n{shape}\n  {texture}{place}\n}}");
    Ok(())
}

/// An object's shape, its brace left open (`mapped`: a mesh's texture
/// coordinates written).
fn shape_of(o: &Object, mapped: bool) -> Result<String, String> {
    Ok(match o.shape {
        Shape::Sphere { center, radius } => {
            format!("sphere {{ {}, {}", vec(pov(center)), num(radius))
        }
        Shape::Plane { point, normal } => {
            let n = normalized(pov(normal)).ok_or_else(|| {
                format!(
                    "objects.{}.shape.normal: expected a non-zero vector",
                    o.name
                )
            })?;
            format!("plane {{ {}, {}", vec(n), num(dot(n, pov(point))))
        }
        Shape::Quad {
            corner,
            edge_u,
            edge_v,
        } => {
            let (c, u, v) = (pov(corner), pov(edge_u), pov(edge_v));
            let p = [c, add(c, u), add(add(c, u), v), add(c, v), c];
            format!(
                "polygon {{ 5, {}",
                p.iter().map(|x| vec(*x)).collect::<Vec<_>>().join(", ")
            )
        }
        Shape::Box { min: lo, max: hi } => format!(
            "box {{ {}, {}",
            vec([lo[0], lo[1], -hi[2]]),
            vec([hi[0], hi[1], -lo[2]])
        ),
        Shape::Mesh { ref file } => {
            let m = crate::scene::mesh::get(std::path::Path::new(file))
                .map_err(|e| format!("objects.{}.shape.file: {e}", o.name))?;
            mesh2(&m, mapped)
        }
    })
}

/// A mesh as `mesh2` (its numbers only, z mirrored like every point):
/// smooth triangles when the file gives vertex normals (POV-Ray then takes
/// the face indices for the normals too), flat ones otherwise; `uv`: the
/// file's texture coordinates as `uv_vectors` (indexed as the vertices).
fn mesh2(m: &crate::scene::mesh::Mesh, uv: bool) -> String {
    let mut s = String::with_capacity(64 * (m.positions.len() + m.triangles.len()));
    let list = |s: &mut String, name: &str, items: &mut dyn Iterator<Item = String>, n: usize| {
        let _ = write!(s, "\n  {name} {{ {n}");
        for it in items {
            let _ = write!(s, ", {it}");
        }
        s.push_str(" }");
    };
    s.push_str("mesh2 {");
    let n = m.positions.len();
    list(
        &mut s,
        "vertex_vectors",
        &mut m.positions.iter().map(|p| vec(pov(*p))),
        n,
    );
    if !m.normals.is_empty() {
        list(
            &mut s,
            "normal_vectors",
            &mut m.normals.iter().map(|p| vec(pov(*p))),
            n,
        );
    }
    if uv && !m.texcoords.is_empty() {
        list(
            &mut s,
            "uv_vectors",
            &mut m
                .texcoords
                .iter()
                .map(|t| format!("<{}, {}>", num(t[0]), num(t[1]))),
            m.texcoords.len(),
        );
    }
    let faces = &mut m
        .triangles
        .iter()
        .map(|t| format!("<{}, {}, {}>", t[0], t[1], t[2]));
    list(&mut s, "face_indices", faces, m.triangles.len());
    s
}

/// Radiosity for `render.indirect`: gathered light is the mean radiance
/// around a point, which POV-Ray multiplies by `diffuse`; ours is kd/pi,
/// so `brightness` pi makes it kd times the mean radiance, as for a
/// Lambertian surface. `recursion_limit` 8: up to 8 bounces, as Blender
/// and Mitsuba trace (3 left a box room 5 % darker than Mitsuba).
const RADIOSITY: &str = "\n  radiosity { pretrace_start 0.08 pretrace_end 0.01 count 200 nearest_count 10 error_bound 0.5 recursion_limit 8 low_error_factor 0.5 gray_threshold 0 minimum_reuse 0.005 brightness 3.14159265358979 adc_bailout 0.001 always_sample off }";

fn camera(s: &mut String, scene: &Scene) {
    let c = &scene.camera;
    if let Some(p) = Pinhole::of(c) {
        let _ = writeln!(s, "{}", pinhole_camera(&p, scene.image));
        return;
    }
    let aspect = scene.image.width as f64 / scene.image.height as f64;
    let common = format!("location {} sky {}", vec(pov(c.eye())), vec(pov(c.up)));
    let look_at = vec(pov(c.target()));
    if c.kind == CameraKind::Orthographic {
        let h = c.height.unwrap_or(1.0);
        let _ = writeln!(
            s,
            "camera {{ orthographic {common} right x*{} up y*{} look_at {look_at} }}",
            num(h * aspect),
            num(h),
        );
    } else {
        let fov_y = c.fov_y_deg.unwrap_or(40.0).to_radians();
        let fov_x = 2.0 * ((fov_y / 2.0).tan() * aspect).atan();
        let _ = writeln!(
            s,
            "camera {{ perspective {common} right x*{} up y angle {} look_at {look_at} }}",
            num(aspect),
            num(fov_x.to_degrees()),
        );
    }
}

/// A calibrated pinhole (without distortion, which is refused) as POV-Ray's
/// perspective camera with its own vectors: its ray through the screen
/// point (sx, sy), each in [-0.5, 0.5] from the left and the bottom, is
/// `direction + sx right + sy up`. The pixel whose centre is at sx, sy has
/// OpenCV coordinates u = (sx + 1/2) W - 1/2, v = (1/2 - sy) H - 1/2, seen
/// along ((u - cx)/fx, (v - cy)/fy, 1) in the camera's frame: so right =
/// (W/fx, 0, 0), up = (0, -H/fy, 0) and direction = ((W/2 - 1/2 - cx)/fx,
/// (H/2 - 1/2 - cy)/fy, 1), each carried into the world and mirrored.
fn pinhole_camera(p: &Pinhole, size: crate::scene::ImageSize) -> String {
    let (w, h) = (size.width as f64, size.height as f64);
    let (fx, fy, cx, cy) = p.intrinsics();
    let world = |v: [f64; 3]| vec(pov(p.camera_to_world(V3::from(v)).to_array()));
    format!(
        "camera {{ perspective location {} direction {} right {} up {} }}",
        vec(pov(p.centre().to_array())),
        world([(w / 2.0 - 0.5 - cx) / fx, (h / 2.0 - 0.5 - cy) / fy, 1.0]),
        world([w / fx, 0.0, 0.0]),
        world([0.0, -h / fy, 0.0]),
    )
}

/// An object's transform after its shape: `scale`, `rotate` (POV-Ray
/// turns about x, then y, then z, as the scene does) and `translate`. The
/// mirrored z turns a rotation about x or y the other way: P Rx(a) P =
/// Rx(-a) with P = diag(1, 1, -1), while Rz and the scale are unchanged.
fn placement(t: &Transform) -> String {
    let sc = t.scale.map_or([1.0; 3], |k| k.axes());
    let [rx, ry, rz] = t.rotate_deg.unwrap_or_default();
    format!(
        "\n  scale {} rotate {} translate {}",
        vec(sc),
        vec([-rx, -ry, rz]),
        vec(pov(t.translate.unwrap_or_default()))
    )
}

fn light(s: &mut String, i: usize, l: &crate::scene::Light) -> Result<(), String> {
    match l.kind {
        LightKind::Point => {
            let p = l
                .position
                .ok_or_else(|| format!("lights.{}: a point light needs a position", l.name))?;
            let power = match (l.falloff_power, l.falloff) {
                (Some(p), _) => p,
                (None, Falloff::InverseSquare) => 2.0,
                (None, Falloff::None) => 0.0,
            };
            let (scale, fade) = fade(power);
            let area = if l.radius > 0.0 {
                let d = num(2.0 * l.radius);
                format!(" area_light <{d}, 0, 0>, <0, {d}, 0>, 9, 9 circular orient adaptive 1")
            } else {
                String::new()
            };
            let _ = writeln!(
                s,
                "// lights[{i}]\nlight_source {{ {} color {}{fade}{area} }}",
                vec(pov(p)),
                rgb(l.color, l.intensity * scale)
            );
        }
        LightKind::Directional => {
            let d = l.direction.ok_or_else(|| {
                format!("lights.{}: a directional light needs a direction", l.name)
            })?;
            let d = normalized(pov(d))
                .ok_or_else(|| format!("lights.{}.direction: zero vector", l.name))?;
            let at = [
                d[0] * PARALLEL_DISTANCE,
                d[1] * PARALLEL_DISTANCE,
                d[2] * PARALLEL_DISTANCE,
            ];
            let _ = writeln!(
                s,
                "// lights[{i}]\nlight_source {{ {} color {} parallel point_at <0, 0, 0> }}",
                vec(at),
                rgb(l.color, l.intensity)
            );
        }
    }
    Ok(())
}

/// The texture (and interior) of a material, see the module doc.
fn material(m: &Material) -> String {
    let t = m.transmission.min(MAX_TRANSMIT);
    let c = m.color;
    let pigment = if t > 0.0 {
        format!(
            "rgbt <{}, {}, {}, {}>",
            num(c[0]),
            num(c[1]),
            num(c[2]),
            num(t)
        )
    } else {
        rgb(c, 1.0)
    };
    let finish = finish(m, 1.0 - t, 1.0);
    let interior = if t > 0.0 {
        format!(" interior {{ ior {} }}", num(m.ior))
    } else {
        String::new()
    };
    let layer = second_lobe(m, t, "");
    format!("texture {{ pigment {{ {pigment} }} finish {{ {finish} }} }}{layer}{interior}")
}

/// A material's finish: ambient and diffuse (undoing POV-Ray's scaling by
/// `opacity`), the first lobe with ks x `ks_scale`, the mirror.
fn finish(m: &Material, opacity: f64, ks_scale: f64) -> String {
    let mut finish = format!(
        "ambient {} diffuse {}",
        num(m.diffuse / opacity),
        num(m.diffuse / (PI * opacity))
    );
    if m.specular * ks_scale > 0.0 {
        let ks = m.specular * (m.shininess + 8.0) / (8.0 * PI) * ks_scale;
        let _ = write!(
            finish,
            " specular {} roughness {}",
            num(ks),
            num(1.0 / m.shininess.max(1e-9))
        );
    }
    if m.reflection > 0.0 {
        let _ = write!(finish, " reflection {{ {} }}", num(m.reflection));
    }
    finish
}

/// The second lobe as a transparent layer on top (none on glass), its
/// surface perturbed by `normal` as the layer below is.
fn second_lobe(m: &Material, t: f64, normal: &str) -> String {
    let mut layer = String::new();
    if let Some(ks2) = m.specular2.filter(|&k| k > 0.0 && t == 0.0) {
        let n2 = m.shininess2.unwrap_or(m.shininess);
        let _ = write!(
            layer,
            " texture {{ pigment {{ rgbt <1, 1, 1, 1> }}{normal} finish {{ ambient 0 diffuse 0 specular {} roughness {} }} }}",
            num(ks2 * (n2 + 8.0) / (8.0 * PI)),
            num(1.0 / n2.max(1e-9))
        );
    }
    layer
}

/// The texture of a material with maps (opaque; see the module doc): the
/// pigment `mapped_pigment`; a specular map as a patterned texture
/// blending that texture without and with its highlight, which is linear
/// in ks, so the blend is ks x the map; a shininess map as a patterned
/// texture with one entry per exponent it holds (`pov_maps::levels`),
/// each that texture with its highlight at that exponent.
fn mapped_material(o: &Object, maps: MapSource) -> Result<String, String> {
    let m = &o.material;
    let get = |k: MapKind, t: &TextureRef, outer: Option<&TextureRef>| placed(o, maps, k, t, outer);
    // On a planar map a nested pattern is carried by every enclosing
    // pattern's transform, so the pigment is placed for the texture it
    // sits in: the specular map's entries, or the shininess map's.
    let in_specular = surface(o, maps, m.specular_map.as_ref())?;
    let in_shininess = match &m.shininess_map {
        Some(t) => surface(o, maps, Some(t))?,
        None => in_specular.clone(),
    };
    let with = |(pigment, normal): (&str, &str), mat: &Material, ks: f64| {
        format!(
            "pigment {{ {pigment} }}{normal} finish {{ {} }}",
            finish(mat, 1.0, ks)
        )
    };
    let in_spec = (&in_specular.0[..], &in_specular.1[..]);
    let in_shine = (&in_shininess.0[..], &in_shininess.1[..]);
    let base = |mat: &Material, ks: f64| with(in_spec, mat, ks);
    // The texture with its highlight (ks x `ks`): at the material's
    // exponent, or per texel at the shininess map's.
    let lit = |ks: f64| -> Result<String, String> {
        let Some(t) = &m.shininess_map else {
            return Ok(base(m, ks));
        };
        let (ch, pre, post) = get(MapKind::Shininess, t, m.specular_map.as_ref())?;
        let at = |n: f64| {
            let mut mat = m.clone();
            mat.shininess = n;
            with(in_shine, &mat, ks)
        };
        if let [n] = ch.levels[..] {
            // One exponent: no pattern, so the pigment sits where `base` is.
            let mut mat = m.clone();
            mat.shininess = n;
            return Ok(base(&mat, ks));
        }
        let entries: String = ch
            .levels
            .iter()
            .map(|&n| format!(" [{} {}]", num(n / ch.scale), at(n)))
            .collect();
        Ok(format!(
            "{pre}{}{post} texture_map {{{entries} }}",
            pattern(&ch.files[0], spherical(o))
        ))
    };
    Ok(match &m.specular_map {
        None => format!(
            "texture {{ {} }}{}",
            lit(1.0)?,
            second_lobe(m, 0.0, &in_specular.1)
        ),
        Some(t) => {
            let (ch, pre, post) = get(MapKind::Specular, t, None)?;
            format!(
                "texture {{ {pre}{}{post} texture_map {{ [0 {}] [1 {}] }} }}",
                pattern(&ch.files[0], spherical(o)),
                base(m, 0.0),
                lit(ch.scale)?
            )
        }
    })
}

/// The pigment and the normal of a material with maps, placed for the
/// patterned texture they sit in (`outer`'s map; None: none).
fn surface(
    o: &Object,
    maps: MapSource,
    outer: Option<&TextureRef>,
) -> Result<(String, String), String> {
    Ok((
        mapped_pigment(o, maps, outer)?,
        mapped_normal(o, maps, outer)?,
    ))
}

/// Map `t` of kind `k` as POV-Ray reads it: its files, and what goes
/// before and after its pattern. A pattern nested in a patterned texture
/// (`outer`'s): on a planar map it is carried by the enclosing pattern's
/// transform too (measured), so only the ratio of the two scales is left
/// to apply.
fn placed(
    o: &Object,
    maps: MapSource,
    k: MapKind,
    t: &TextureRef,
    outer: Option<&TextureRef>,
) -> Result<(Arc<Channels>, String, String), String> {
    let spherical = spherical(o);
    let lay = match k {
        MapKind::Normal => Some(pov_bumps::laid(&o.shape, t.scale()).ok_or_else(|| {
            format!(
                "objects.{}.material.normal_map: drawn by POV-Ray on a plane, quad or sphere only",
                o.name
            )
        })?),
        _ if spherical => pov_bumps::laid(&o.shape, t.scale()),
        _ => None,
    };
    let ch = maps(t, k, lay).map_err(|e| format!("objects.{}.material.{e}", o.name))?;
    let (pre, mut post) = mapping(&o.shape, t.scale(), spherical).ok_or_else(|| {
        format!(
            "objects.{}.material.{}: not drawn on this shape by POV-Ray",
            o.name,
            k.key()
        )
    })?;
    match (spherical, outer) {
        // laid over the whole sphere: the enclosing pattern's translation
        // carries it, and its `scale` is in its texels
        (true, Some(_)) => post.clear(),
        (false, Some(outer)) if pre.is_empty() => {
            let (a, b) = (outer.scale(), t.scale());
            post = format!(" scale <{}, {}, 1>", num(a[0] / b[0]), num(a[1] / b[1]));
        }
        _ => {}
    }
    Ok((ch, pre, post))
}

/// Whether `o`'s maps are spherical images about its centre: a sphere
/// with a normal map, whose heights POV-Ray reads only so
/// (`pov_bumps::sphere_heights`); its other maps are then laid out the
/// same way (`pov_bumps::over_sphere`) so that the patterns nest.
fn spherical(o: &Object) -> bool {
    matches!(o.shape, Shape::Sphere { .. }) && o.material.normal_map.is_some()
}

/// The pigment of a material with maps: c x the colour map as the
/// average of three channel patterns, channel k `color_map`ped from 0 to
/// 3 c_k s (s the factor the files were divided by: `pov_maps`), placed
/// for the patterned texture it is nested in (`outer`'s map, None: none).
fn mapped_pigment(
    o: &Object,
    maps: MapSource,
    outer: Option<&TextureRef>,
) -> Result<String, String> {
    let m = &o.material;
    let Some(t) = &m.color_map else {
        return Ok(rgb(m.color, 1.0));
    };
    let (ch, pre, post) = placed(o, maps, MapKind::Color, t, outer)?;
    let entries: String = (0..3)
        .map(|k| {
            let mut c = [0.0; 3];
            c[k] = 3.0 * m.color[k] * ch.scale;
            format!(
                " [1 {pre}{} color_map {{ [0 rgb 0] [1 {}] }}{post}]",
                pattern(&ch.files[k], spherical(o)),
                rgb(c, 1.0)
            )
        })
        .collect();
    Ok(format!("average pigment_map {{{entries} }}"))
}

/// The surface's normal perturbed by its normal map (`pov_bumps`: the
/// height field of its slopes, `scale` its range in world length) as a
/// pattern's gradient, placed for the patterned texture it sits in; ""
/// without a normal map. POV-Ray adds `-BUMP_GAIN bump_size` times the
/// pattern's gradient to the normal (four samples `accuracy` apart; the
/// gain measured), so `bump_size` is the height's range over the gain.
fn mapped_normal(
    o: &Object,
    maps: MapSource,
    outer: Option<&TextureRef>,
) -> Result<String, String> {
    let Some(t) = &o.material.normal_map else {
        return Ok(String::new());
    };
    if matches!(o.shape, Shape::Mesh { .. }) {
        // a mesh's is in its normals (`object`, `pov_mesh_bumps`)
        return Ok(String::new());
    }
    let (ch, pre, post) = placed(o, maps, MapKind::Normal, t, outer)?;
    if ch.scale <= 0.0 {
        return Ok(String::new());
    }
    // a sphere's heights are a spherical image about its centre
    // (`mapping`): the gradient's step is an angle, so it goes with the radius
    let accuracy = match o.shape {
        Shape::Sphere { radius, .. } => BUMP_ACCURACY * radius,
        _ => BUMP_ACCURACY,
    };
    let image = pattern(&ch.files[0], spherical(o));
    Ok(format!(
        " normal {{ {pre}{image} bump_size {} accuracy {}{post} }}",
        num(ch.scale / BUMP_GAIN),
        num(accuracy)
    ))
}

/// What POV-Ray's `normal` adds per unit of `bump_size` and of the
/// pattern's gradient: 5 x 0.02 (its two fixed factors) x 4/3 (the sum
/// of its four sample directions' outer products).
const BUMP_GAIN: f64 = 0.4 / 3.0;

/// The step of POV-Ray's gradient, in the map's coordinates: far inside
/// one cell of the height field (`pov_bumps`, at most 1024 a side).
const BUMP_ACCURACY: f64 = 1e-4;

/// A written map file as a bilinear, linear pattern (`pov_maps`), read
/// as a spherical image (`map_type 1`) when `spherical`.
fn pattern(file: &str, spherical: bool) -> String {
    let map_type = if spherical { " map_type 1" } else { "" };
    format!("image_pattern {{ png \"{file}\" gamma 1.0{map_type} interpolate 2 }}")
}

/// How a pattern in POV-Ray's image space [0, 1]^2 lands on `shape` at
/// scenefit's (u, v) x `scale` (docs/scene-format.md "Textures"): what
/// goes before the pattern and what after. A sphere's and a mesh's
/// `uv_mapping` are scenefit's (measured: within 0.03 % of phong), but
/// not for a sphere's normal map: its heights are laid over the
/// longitude and latitude as POV-Ray's spherical image (`map_type 1`)
/// reads the direction from the centre (`pov_bumps::sphere_heights`), a
/// pattern of the point in space whose gradient lies in the surface,
/// where `uv_mapping` would tilt the normal along the world's axes; so
/// every map of such a sphere is (`spherical`: `pov_bumps::over_sphere`); a
/// plane and a quad are planar maps carried onto their axes (e_u, e_v;
/// edge_u, edge_v) by a matrix; a box: None (`object` writes a mapped
/// box as its faces, quads).
fn mapping(shape: &Shape, scale: [f64; 2], spherical: bool) -> Option<(String, String)> {
    let sc = format!(
        " scale <{}, {}, 1>",
        num(1.0 / scale[0]),
        num(1.0 / scale[1])
    );
    // The scale folded into the one matrix: POV-Ray turns a normal
    // pattern's gradient back through its transforms in the wrong order
    // (measured: a `scale` before a `matrix` tilts an anisotropic map's
    // bumps), which one transform cannot.
    let frame = |u: Vec3, v: Vec3, n: Vec3, at: Vec3| {
        let (u, v) = (u.map(|x| x / scale[0]), v.map(|x| x / scale[1]));
        let m: Vec<String> = [u, v, n, at]
            .iter()
            .flat_map(|x| pov(*x).map(num))
            .collect();
        format!(" matrix <{}>", m.join(", "))
    };
    match *shape {
        Shape::Sphere { center, .. } if spherical => {
            Some((String::new(), format!(" translate {}", vec(pov(center)))))
        }
        Shape::Sphere { .. } | Shape::Mesh { .. } => Some(("uv_mapping ".into(), sc)),
        Shape::Plane { point, normal } => {
            let (eu, ev) = crate::scene::texture::uv::plane_axes(V3::from(normal));
            let n = V3::from(normal).normalized();
            Some((
                String::new(),
                frame(eu.to_array(), ev.to_array(), n.to_array(), point),
            ))
        }
        Shape::Quad {
            corner,
            edge_u,
            edge_v,
        } => {
            let n = V3::from(edge_u).cross(V3::from(edge_v)).normalized();
            Some((String::new(), frame(edge_u, edge_v, n.to_array(), corner)))
        }
        Shape::Box { .. } => None,
    }
}

fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn normalized(v: Vec3) -> Option<Vec3> {
    let l = dot(v, v).sqrt();
    (l > 0.0 && l.is_finite()).then(|| [v[0] / l, v[1] / l, v[2] / l])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Names are data: even an unvalidated scene whose names hold SDL
    /// directives and newlines writes none of them.
    #[test]
    fn names_never_reach_the_sdl() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenes/sphere_floor.json"
        ))
        .unwrap();
        let mut scene = crate::scene::parse(&text, "sphere_floor.json", &[]).unwrap();
        let evil = "x\n#fopen F \"/tmp/scenefit_pwned\" write #write (F, \"1\") #fclose F\n//";
        for l in &mut scene.lights {
            l.name = format!("{evil}L");
        }
        for o in &mut scene.objects {
            o.name = format!("{evil}O");
        }
        let out = sdl(&scene).unwrap();
        assert!(!out.contains("fopen") && !out.contains('"'), "{out}");
        assert_eq!(out.matches('#').count(), 1, "only #version: {out}");
        assert!(crate::render::povray::only_version_directive(&out).is_ok());
        assert!(
            crate::render::povray::only_version_directive("#version 3.7;\n#include \"x\"").is_err()
        );
    }

    /// A mesh is written as `mesh2` from the triangles read (z mirrored,
    /// vertex normals kept, a quad fanned into two triangles), numbers only.
    #[test]
    fn a_mesh_is_written_as_mesh2() {
        let d = tempfile::tempdir().unwrap();
        let ply = d.path().join("q.ply");
        let head = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
        let body = "0 0 1 0 0 1\n1 0 1 0 0 1\n1 1 1 0 0 1\n0 1 1 0 0 1\n4 0 1 2 3\n";
        std::fs::write(&ply, format!("{head}{body}")).unwrap();
        let mut scene = crate::scene::test_scene::ball(r#""color": [0.5, 0.5, 0.5]"#, "");
        scene.objects[0].shape = Shape::Mesh {
            file: ply.display().to_string(),
        };
        let out = sdl(&scene).unwrap();
        assert!(
            out.contains("mesh2 {\n  vertex_vectors { 4, <0, 0, -1e0>, <1e0, 0, -1e0>"),
            "{out}"
        );
        assert!(out.contains("normal_vectors { 4, <0, 0, -1e0>"), "{out}");
        assert!(
            out.contains("face_indices { 2, <0, 1, 2>, <0, 2, 3> }"),
            "{out}"
        );
        assert!(!out.contains("q.ply"), "the path is not written: {out}");
    }

    #[test]
    fn numbers_povray_reads() {
        assert_eq!(num(0.0), "0");
        assert_eq!(num(1.5), "1.5e0");
        assert_eq!(num(-2e-7), "-2e-7");
    }

    #[test]
    fn fade_powers() {
        for p in [1.0f64, 1.5, 2.0, 3.0] {
            let (scale, text) = fade(p);
            let dist: f64 = text.split_whitespace().nth(1).unwrap().parse().unwrap();
            for d in [0.1f64, 1.0, 10.0] {
                let pov = scale * 2.0 / (1.0 + (d / dist).powf(p));
                assert!((pov * d.powf(p) - 1.0).abs() <= 1e-4, "p {p} d {d}: {pov}");
            }
        }
        assert_eq!(fade(0.0), (1.0, String::new()));
        assert!(fade(2.0).1.contains("fade_distance 1e-4 fade_power 2e0"));
    }

    #[test]
    fn fade_is_inverse_square() {
        // colour * 2 / (1 + (d/D)^2) against 1/d^2
        for d in [0.1f64, 1.0, 10.0] {
            let pov = 1.0 / (2.0 * FADE_DISTANCE * FADE_DISTANCE) * 2.0
                / (1.0 + (d / FADE_DISTANCE).powi(2));
            assert!((pov * d * d - 1.0).abs() <= 1e-6, "{d}: {pov}");
        }
    }
}
