//! Checks a parsed scene for values the types cannot rule out: missing or
//! misplaced fields per kind, negative radii, a degenerate camera, duplicate
//! names, free parameters that name nothing or have bad bounds. Every error
//! names the key path and what was expected.

use super::checks::{finite3, non_negative, non_negative3, nonzero3, positive};
use super::field::{Field, TransformField, Value};
use super::limits::*;
use super::types::*;
use crate::error::{Error, Result};
use crate::math::V3;

/// A light's or object's name: data, never code, in every backend; and a
/// segment of dotted paths, so no '.'.
fn name(file: &str, at: &str, name: &str) -> Result<()> {
    if !valid_name(name) {
        return Err(Error::invalid(
            file,
            format!("{at}.name"),
            format!("expected {NAME_CHARS}, got {}", quote(name)),
        ));
    }
    Ok(())
}

/// Validates `scene`, read from `file` (for messages).
pub fn validate(scene: &Scene, file: &str) -> Result<()> {
    settings(scene, file)?;
    counts(scene, file)?;
    non_negative3(file, "ambient", scene.ambient)?;
    camera(&scene.camera, file)?;
    effects(scene, file)?;
    lights(scene, file)?;
    objects(scene, file)?;
    albedo_maps(scene, file)?;
    meshes(scene, file)?;
    textures(scene, file)?;
    free_list(scene, file)
}

/// Every `material.albedo_map`: an OpenEXR file of the image's size with
/// finite non-negative values (read once, `albedo_map.rs`).
fn albedo_maps(scene: &Scene, file: &str) -> Result<()> {
    let size = (scene.image.width, scene.image.height);
    for (i, o) in scene.objects.iter().enumerate() {
        if let Some(p) = &o.material.albedo_map {
            let key = format!("objects[{i}].material.albedo_map");
            super::albedo_map::check(std::path::Path::new(p), size, file, &key)?;
        }
    }
    Ok(())
}

/// Every texture map (`texture/`): readable, its values in range; a
/// mapped mesh must have texture coordinates.
fn textures(scene: &Scene, file: &str) -> Result<()> {
    use super::texture::MapKind;
    for (i, o) in scene.objects.iter().enumerate() {
        for kind in MapKind::ALL {
            let Some(t) = o.material.map(kind) else {
                continue;
            };
            let key = format!("objects[{i}].material.{}", kind.key());
            super::texture::check(t, kind, file, &key)?;
            if let super::shape::Shape::Mesh { file: p } = &o.shape {
                let mesh = super::mesh::get(std::path::Path::new(p))?;
                if mesh.texcoords.is_empty() {
                    return Err(Error::invalid(
                        file,
                        key,
                        format!("the mesh {} has no texture coordinates; expected a PLY (s, t or u, v) or OBJ (vt) file with them", quote(p)),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Every mesh shape's file: read once and checked (`mesh.rs`), so that a
/// bad file is refused before anything renders.
fn meshes(scene: &Scene, file: &str) -> Result<()> {
    for (i, o) in scene.objects.iter().enumerate() {
        if let super::shape::Shape::Mesh { file: p } = &o.shape {
            let key = format!("objects[{i}].shape.file");
            super::mesh::check(std::path::Path::new(p), file, &key)?;
        }
    }
    Ok(())
}

/// The format tag, image size and render settings.
fn settings(scene: &Scene, file: &str) -> Result<()> {
    let err = |key: String, msg: String| Err(Error::invalid(file, key, msg));
    if scene.format != FORMAT {
        return err(
            "format".into(),
            format!("expected \"{FORMAT}\", got {}", quote(&scene.format)),
        );
    }
    if scene.image.width == 0
        || scene.image.height == 0
        || scene.image.width > MAX_IMAGE_SIDE
        || scene.image.height > MAX_IMAGE_SIDE
    {
        return err(
            "image".into(),
            format!("expected width and height between 1 and {MAX_IMAGE_SIDE}"),
        );
    }
    if !(1..=MAX_SAMPLES).contains(&scene.render.samples) {
        return err(
            "render.samples".into(),
            format!("expected 1 to {MAX_SAMPLES}, got {}", scene.render.samples),
        );
    }
    if !(1..=16).contains(&scene.render.antialias) {
        return err("render.antialias".into(), "expected 1 to 16".into());
    }
    if scene.render.max_depth > MAX_DEPTH {
        return err(
            "render.max_depth".into(),
            format!(
                "expected 0 to {MAX_DEPTH} bounces, got {}",
                scene.render.max_depth
            ),
        );
    }
    Ok(())
}

/// No list longer than its limit.
fn counts(scene: &Scene, file: &str) -> Result<()> {
    for (key, n, max) in [
        ("lights", scene.lights.len(), MAX_LIGHTS),
        ("objects", scene.objects.len(), MAX_OBJECTS),
        ("free", scene.free.len(), MAX_FREE),
    ] {
        if n > max {
            return Err(Error::invalid(
                file,
                key,
                format!("expected at most {max} entries, got {n}"),
            ));
        }
    }
    Ok(())
}

/// Every light, under a unique name.
fn lights(scene: &Scene, file: &str) -> Result<()> {
    let err = |key: String, msg: String| Err(Error::invalid(file, key, msg));
    let mut seen = std::collections::HashSet::new();
    for (i, l) in scene.lights.iter().enumerate() {
        let at = format!("lights[{i}]");
        name(file, &at, &l.name)?;
        if !seen.insert(&l.name) {
            return err(
                format!("{at}.name"),
                format!("duplicate light name \"{}\"", l.name),
            );
        }
        light(l, file, &at)?;
    }
    Ok(())
}

/// Every object, under a unique name.
fn objects(scene: &Scene, file: &str) -> Result<()> {
    let err = |key: String, msg: String| Err(Error::invalid(file, key, msg));
    let mut seen = std::collections::HashSet::new();
    for (i, o) in scene.objects.iter().enumerate() {
        let at = format!("objects[{i}]");
        name(file, &at, &o.name)?;
        if !seen.insert(&o.name) {
            return err(
                format!("{at}.name"),
                format!("duplicate object name \"{}\"", o.name),
            );
        }
        o.shape.check(file, &format!("{at}.shape"))?;
        if let Some(t) = &o.transform {
            transform(t, &o.shape, file, &format!("{at}.transform"))?;
        }
        material(&o.material, file, &format!("{at}.material"))?;
    }
    Ok(())
}

/// Every free parameter, each free once.
fn free_list(scene: &Scene, file: &str) -> Result<()> {
    let err = |key: String, msg: String| Err(Error::invalid(file, key, msg));
    let mut seen = std::collections::HashSet::new();
    for (i, f) in scene.free.iter().enumerate() {
        let at = format!("free[{i}]");
        if !seen.insert(&f.param) {
            return err(
                format!("{at}.param"),
                format!("{} is free twice", quote(&f.param)),
            );
        }
        free(scene, f, file, &at)?;
    }
    Ok(())
}

fn required<T: Copy>(file: &str, key: &str, v: Option<T>, what: &str) -> Result<T> {
    v.ok_or_else(|| Error::invalid(file, key, format!("missing; {what}")))
}

fn forbidden<T>(file: &str, key: &str, v: &Option<T>, what: &str) -> Result<()> {
    if v.is_some() {
        return Err(Error::invalid(file, key, format!("not used by {what}")));
    }
    Ok(())
}

fn camera(c: &Camera, file: &str) -> Result<()> {
    if c.kind == CameraKind::Pinhole {
        return super::pinhole::check(c, file);
    }
    super::pinhole::forbid_in_other_kinds(c, file)?;
    placement(c, file)?;
    match c.kind {
        CameraKind::Perspective => {
            let fov = required(
                file,
                "camera.fov_y_deg",
                c.fov_y_deg,
                "a perspective camera needs fov_y_deg",
            )?;
            if !(fov > 0.0 && fov < 180.0) {
                return Err(Error::invalid(
                    file,
                    "camera.fov_y_deg",
                    format!("expected a number in (0, 180), got {fov}"),
                ));
            }
            forbidden(
                file,
                "camera.height",
                &c.height,
                "a perspective camera (use fov_y_deg)",
            )
        }
        // its own check, above
        CameraKind::Pinhole => Ok(()),
        CameraKind::Orthographic => {
            let h = required(
                file,
                "camera.height",
                c.height,
                "an orthographic camera needs height (metres)",
            )?;
            positive(file, "camera.height", h)?;
            forbidden(
                file,
                "camera.fov_y_deg",
                &c.fov_y_deg,
                "an orthographic camera (use height)",
            )
        }
    }
}

/// A look-at camera's `position`, `look_at` and `up`: present, finite, and
/// not degenerate.
fn placement(c: &Camera, file: &str) -> Result<()> {
    let position = required(
        file,
        "camera.position",
        c.position,
        "a perspective or orthographic camera needs position and look_at",
    )?;
    let look_at = required(
        file,
        "camera.look_at",
        c.look_at,
        "a perspective or orthographic camera needs position and look_at",
    )?;
    if !finite3(position) || !finite3(look_at) {
        return Err(Error::invalid(
            file,
            "camera.position",
            "expected finite numbers",
        ));
    }
    let view = V3::from(look_at) - V3::from(position);
    if view.length() < 1e-9 {
        return Err(Error::invalid(
            file,
            "camera.look_at",
            "must differ from camera.position",
        ));
    }
    nonzero3(file, "camera.up", c.up)?;
    let up = V3::from(c.up).normalized();
    if view.normalized().cross(up).length() < 1e-6 {
        return Err(Error::invalid(
            file,
            "camera.up",
            "is parallel to the view direction (look_at - position); expected a vector that is not",
        ));
    }
    Ok(())
}

/// The optional effect fields of the scene and camera.
fn effects(scene: &Scene, file: &str) -> Result<()> {
    if let Some(k) = scene.indirect_light {
        non_negative(file, "indirect_light", k)?;
    }
    if let Some(v) = scene.camera.vignetting {
        if !(v.strength.is_finite() && v.strength <= 1.0) {
            return Err(Error::invalid(
                file,
                "camera.vignetting.strength",
                format!("expected a number up to 1, got {}", v.strength),
            ));
        }
    }
    if let Some(e) = scene.camera.exposure {
        positive(file, "camera.exposure", e)?;
    }
    if let Some(wb) = scene.camera.white_balance {
        for (c, v) in ["r", "g", "b"].iter().zip(wb) {
            positive(file, &format!("camera.white_balance ({c})"), v)?;
        }
    }
    if let Some(r) = scene.camera.response {
        positive(file, "camera.response.gain", r.gain)?;
        positive(file, "camera.response.gamma", r.gamma)?;
        if !r.black.is_finite() {
            return Err(Error::invalid(
                file,
                "camera.response.black",
                "expected a finite number",
            ));
        }
    }
    Ok(())
}

fn light(l: &Light, file: &str, at: &str) -> Result<()> {
    non_negative3(file, &format!("{at}.color"), l.color)?;
    non_negative(file, &format!("{at}.intensity"), l.intensity)?;
    non_negative(file, &format!("{at}.radius"), l.radius)?;
    if let Some(p) = l.falloff_power {
        non_negative(file, &format!("{at}.falloff_power"), p)?;
        if p > MAX_FALLOFF_POWER {
            return Err(Error::invalid(
                file,
                format!("{at}.falloff_power"),
                format!("expected at most {MAX_FALLOFF_POWER}, got {p}"),
            ));
        }
    }
    match l.kind {
        LightKind::Point => {
            let p = required(
                file,
                &format!("{at}.position"),
                l.position,
                "a point light needs a position",
            )?;
            if !finite3(p) {
                return Err(Error::invalid(
                    file,
                    format!("{at}.position"),
                    "expected finite numbers",
                ));
            }
            forbidden(
                file,
                &format!("{at}.distance"),
                &l.distance,
                "a point light (its position says where it is)",
            )?;
            forbidden(
                file,
                &format!("{at}.direction"),
                &l.direction,
                "a point light (use position)",
            )
        }
        LightKind::Directional => {
            if let Some(d) = l.distance {
                positive(file, &format!("{at}.distance"), d)?;
            }
            let d = required(
                file,
                &format!("{at}.direction"),
                l.direction,
                "a directional light needs a direction (towards the light)",
            )?;
            nonzero3(file, &format!("{at}.direction"), d)?;
            forbidden(
                file,
                &format!("{at}.position"),
                &l.position,
                "a directional light (use direction)",
            )
        }
    }
}

/// Finite numbers and positive scales; one scale for a sphere (a
/// stretched sphere, an ellipsoid, is not drawn).
fn transform(t: &Transform, s: &Shape, file: &str, at: &str) -> Result<()> {
    for (k, v) in [("translate", t.translate), ("rotate_deg", t.rotate_deg)] {
        if v.is_some_and(|v| !finite3(v)) {
            return Err(Error::invalid(
                file,
                format!("{at}.{k}"),
                "expected finite numbers",
            ));
        }
    }
    let Some(scale) = t.scale else {
        return Ok(());
    };
    for x in scale.axes() {
        positive(file, &format!("{at}.scale"), x)?;
    }
    if scale.uniform().is_none() && !s.takes_axis_scales() {
        return Err(Error::invalid(
            file,
            format!("{at}.scale"),
            format!(
                "a {t} takes one scale for every axis (scaled per axis it would no longer be a {t}); expected a number, got {:?}",
                scale.axes(),
                t = s.type_name()
            ),
        ));
    }
    Ok(())
}

fn material(m: &Material, file: &str, at: &str) -> Result<()> {
    let key = |k: &str| format!("{at}.{k}");
    non_negative3(file, &key("color"), m.color)?;
    non_negative(file, &key("diffuse"), m.diffuse)?;
    non_negative(file, &key("specular"), m.specular)?;
    positive(file, &key("shininess"), m.shininess)?;
    non_negative(file, &key("reflection"), m.reflection)?;
    non_negative(file, &key("transmission"), m.transmission)?;
    positive(file, &key("ior"), m.ior)?;
    if let Some(f0) = m.fresnel {
        if !(f0 > 0.0 && f0 <= 1.0) {
            return Err(Error::invalid(
                file,
                key("fresnel"),
                format!("expected F0 in (0, 1], got {f0}"),
            ));
        }
    }
    if let Some(k) = m.specular2 {
        non_negative(file, &key("specular2"), k)?;
    }
    if let Some(f) = m.diffuse_f90 {
        non_negative(file, &key("diffuse_f90"), f)?;
    }
    if let Some(n) = m.shininess2 {
        positive(file, &key("shininess2"), n)?;
    }
    Ok(())
}

fn free(scene: &Scene, f: &FreeParam, file: &str, at: &str) -> Result<()> {
    let field = Field::resolve(scene, &f.param).map_err(|m| {
        Error::invalid(
            file,
            format!("{at}.param"),
            format!("{}: {m}", quote(&f.param)),
        )
    })?;
    let current = field.get(scene).ok_or_else(|| {
        Error::invalid(
            file,
            format!("{at}.param"),
            format!("{} is not set in this scene", quote(&f.param)),
        )
    })?;
    let n = current.components().len();
    let lo = expand_bound(f, f.min, n, file, at, "min")?;
    let hi = expand_bound(f, f.max, n, file, at, "max")?;
    bounds_in_range(&lo, &hi, file, at)?;
    colour_bounds(&field, f, &lo, &hi, file, at)?;
    if f.phase == Some(0) {
        return Err(Error::invalid(
            file,
            format!("{at}.phase"),
            "expected 1 or more",
        ));
    }
    if let Value::Scalar(_) = current {
        physical_minimum(&field, f, lo[0], file, at)?;
    }
    if matches!(field, Field::Transform(_, TransformField::Scale)) && lo.iter().any(|&x| x <= 0.0) {
        return Err(Error::invalid(
            file,
            format!("{at}.min"),
            format!("\"{}\" cannot go below or to 0", f.param),
        ));
    }
    Ok(())
}

/// A bound as one number per component of the field it bounds.
fn expand_bound(
    f: &FreeParam,
    b: Bound,
    n: usize,
    file: &str,
    at: &str,
    which: &str,
) -> Result<Vec<f64>> {
    match (b, n) {
        (Bound::Scalar(x), 1) => Ok(vec![x]),
        (Bound::Scalar(x), 3) => Ok(vec![x; 3]),
        (Bound::Vector(v), 3) => Ok(v.to_vec()),
        (Bound::Vector(_), _) => Err(Error::invalid(
            file,
            format!("{at}.{which}"),
            format!(
                "\"{}\" is a number; expected a number, not a vector",
                f.param
            ),
        )),
        _ => unreachable!("fields are scalars or 3-vectors"),
    }
}

/// Finite, not huge, and min <= max in every component.
fn bounds_in_range(lo: &[f64], hi: &[f64], file: &str, at: &str) -> Result<()> {
    for c in 0..lo.len() {
        for (which, x) in [("min", lo[c]), ("max", hi[c])] {
            if !(x.is_finite() && x.abs() <= MAX_MAGNITUDE) {
                return Err(Error::invalid(
                    file,
                    format!("{at}.{which}"),
                    format!("expected a number between -{MAX_MAGNITUDE:e} and {MAX_MAGNITUDE:e}, got {x:e}"),
                ));
            }
        }
        if lo[c] > hi[c] {
            return Err(Error::invalid(
                file,
                format!("{at}.max"),
                format!("expected max >= min, got min {:?} and max {:?}", lo, hi),
            ));
        }
    }
    Ok(())
}

/// HSV only for colours, within [0, 1]; RGB colours not below 0.
fn colour_bounds(
    field: &Field,
    f: &FreeParam,
    lo: &[f64],
    hi: &[f64],
    file: &str,
    at: &str,
) -> Result<()> {
    if f.space == ColorSpace::Hsv {
        if !field.is_color() {
            return Err(Error::invalid(
                file,
                format!("{at}.space"),
                format!("\"hsv\" is for colours; \"{}\" is not one", f.param),
            ));
        }
        if lo
            .iter()
            .chain(hi.iter())
            .any(|&x| !(0.0..=1.0).contains(&x))
        {
            return Err(Error::invalid(
                file,
                format!("{at}.min"),
                "HSV bounds must lie in [0, 1]",
            ));
        }
    }
    if field.is_color() && f.space == ColorSpace::Rgb && lo.iter().any(|&x| x < 0.0) {
        return Err(Error::invalid(
            file,
            format!("{at}.min"),
            "colours cannot go below 0",
        ));
    }
    Ok(())
}

/// A scalar's lower bound may not leave its physical range (no negative
/// strengths; no zero shininess, index of refraction, field of view, ...).
fn physical_minimum(field: &Field, f: &FreeParam, lo: f64, file: &str, at: &str) -> Result<()> {
    let physical_min = match field {
        Field::Material(
            _,
            super::field::MaterialField::Shininess | super::field::MaterialField::Ior,
        ) => f64::MIN_POSITIVE,
        Field::Camera(
            super::field::CameraField::FovY
            | super::field::CameraField::Height
            | super::field::CameraField::ResponseGain
            | super::field::CameraField::ResponseGamma
            | super::field::CameraField::Exposure,
        )
        | Field::Shape(..) => f64::MIN_POSITIVE,
        Field::Camera(super::field::CameraField::Fx | super::field::CameraField::Fy) => {
            f64::MIN_POSITIVE
        }
        // A black level below 0 is one subtracted (clipped at 0); a
        // principal point or a distortion coefficient may be negative.
        Field::Camera(
            super::field::CameraField::ResponseBlack
            | super::field::CameraField::Cx
            | super::field::CameraField::Cy
            | super::field::CameraField::Distortion(_),
        ) => f64::NEG_INFINITY,
        _ => 0.0,
    };
    if lo < physical_min {
        return Err(Error::invalid(
            file,
            format!("{at}.min"),
            format!(
                "\"{}\" cannot go below {}",
                f.param,
                if physical_min > 0.0 { "or to 0" } else { "0" }
            ),
        ));
    }
    Ok(())
}
