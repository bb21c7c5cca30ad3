//! Numeric fields of a scene addressed by name: `lights.key.position`,
//! `objects.ball.material.color`, `camera.fov_y_deg`, `ambient`. A path is
//! resolved once against a scene into a `Field`, which then reads and writes
//! that value in any copy of the scene without string matching.
//!
//! A pinhole camera's `camera.fx|fy|cx|cy|rotation|translation` and
//! `camera.distortion.k1|k2|p1|p2|k3` (when it has `distortion`).
//!
//! An object's `objects.NAME.transform.translate|rotate_deg|scale` always
//! resolves: an absent transform is the identity, written when first set.
//!
//! The optional effect fields (`indirect_light`, `lights.NAME.falloff_power|distance`,
//! `objects.NAME.material.fresnel|specular2|shininess2|diffuse_f90`,
//! `camera.vignetting.strength`, `camera.response.gain|gamma|black`) resolve
//! only when the scene has them: set them first, then free them.

use super::transform::{Scale, Transform};
use super::types::{Scene, Vec3};

/// A resolved numeric field of a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    Ambient,
    IndirectLight,
    Light(usize, LightField),
    Material(usize, MaterialField),
    /// A shape's numeric field, by its name in the shape (`Shape::fields`).
    Shape(usize, &'static str),
    Camera(CameraField),
    /// An object's `transform.translate|rotate_deg|scale` (absent: identity).
    Transform(usize, TransformField),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransformField {
    Translate,
    RotateDeg,
    Scale,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightField {
    Position,
    Direction,
    Color,
    Intensity,
    Radius,
    FalloffPower,
    Distance,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MaterialField {
    Color,
    Diffuse,
    Specular,
    Shininess,
    Reflection,
    Transmission,
    Ior,
    Fresnel,
    Specular2,
    Shininess2,
    DiffuseF90,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraField {
    Position,
    LookAt,
    Up,
    FovY,
    Height,
    Vignetting,
    ResponseGain,
    ResponseGamma,
    ResponseBlack,
    Exposure,
    WhiteBalance,
    /// A pinhole camera's calibration (scene/pinhole.rs).
    Fx,
    Fy,
    Cx,
    Cy,
    Rotation,
    Translation,
    /// `camera.distortion.k1|k2|p1|p2|k3`: coefficient i of the five.
    Distortion(usize),
}

/// The names of a pinhole camera's distortion coefficients, in order.
pub const DISTORTION_KEYS: [&str; 5] = ["k1", "k2", "p1", "p2", "k3"];

/// A field's value: a number or a 3-vector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    Scalar(f64),
    Vector(Vec3),
}

impl Value {
    pub fn to_json(self) -> serde_json::Value {
        match self {
            Value::Scalar(x) => serde_json::json!(x),
            Value::Vector(v) => serde_json::json!(v),
        }
    }
    pub fn components(&self) -> Vec<f64> {
        match self {
            Value::Scalar(x) => vec![*x],
            Value::Vector(v) => v.to_vec(),
        }
    }
}

impl Field {
    /// Resolves a dotted path against `scene`; the error says what was expected.
    pub fn resolve(scene: &Scene, path: &str) -> Result<Field, String> {
        let parts: Vec<&str> = path.split('.').collect();
        match parts.as_slice() {
            ["ambient"] => Ok(Field::Ambient),
            ["indirect_light"] => present(scene, Field::IndirectLight, path),
            ["lights", name, field] => light_field(scene, name, field, path),
            ["objects", name, "material", field] => material_field(scene, name, field, path),
            ["objects", name, "shape", field] => shape_field(scene, name, field),
            ["objects", name, "transform", field] => transform_field(scene, name, field),
            ["camera", field] => camera_field(scene, field),
            ["camera", group, field] => camera_group_field(scene, group, field, path),
            _ => Err("expected ambient, indirect_light, lights.NAME.FIELD, objects.NAME.material.FIELD, objects.NAME.shape.FIELD, objects.NAME.transform.FIELD or camera.FIELD".into()),
        }
    }

    /// The current value, or None where the scene does not have it (a
    /// directional light's position).
    pub fn get(&self, scene: &Scene) -> Option<Value> {
        use Value::{Scalar, Vector};
        Some(match *self {
            Field::Ambient => Vector(scene.ambient),
            Field::IndirectLight => Scalar(scene.indirect_light?),
            Field::Light(i, f) => {
                let l = &scene.lights[i];
                match f {
                    LightField::Position => Vector(l.position?),
                    LightField::Direction => Vector(l.direction?),
                    LightField::Color => Vector(l.color),
                    LightField::Intensity => Scalar(l.intensity),
                    LightField::Radius => Scalar(l.radius),
                    LightField::FalloffPower => Scalar(l.falloff_power?),
                    LightField::Distance => Scalar(l.distance?),
                }
            }
            Field::Material(i, f) => {
                let m = &scene.objects[i].material;
                match f {
                    MaterialField::Color => Vector(m.color),
                    MaterialField::Diffuse => Scalar(m.diffuse),
                    MaterialField::Specular => Scalar(m.specular),
                    MaterialField::Shininess => Scalar(m.shininess),
                    MaterialField::Reflection => Scalar(m.reflection),
                    MaterialField::Transmission => Scalar(m.transmission),
                    MaterialField::Ior => Scalar(m.ior),
                    MaterialField::Fresnel => Scalar(m.fresnel?),
                    MaterialField::Specular2 => Scalar(m.specular2?),
                    MaterialField::Shininess2 => Scalar(m.shininess2?),
                    MaterialField::DiffuseF90 => Scalar(m.diffuse_f90?),
                }
            }
            Field::Shape(i, f) => match scene.objects[i].shape.field(f)? {
                [x] => Scalar(*x),
                v => Vector(v.try_into().ok()?),
            },
            Field::Camera(f) => {
                let c = &scene.camera;
                match f {
                    CameraField::Position => Vector(c.position?),
                    CameraField::LookAt => Vector(c.look_at?),
                    CameraField::Up => Vector(c.up),
                    CameraField::FovY => Scalar(c.fov_y_deg?),
                    CameraField::Height => Scalar(c.height?),
                    CameraField::Vignetting => Scalar(c.vignetting?.strength),
                    CameraField::ResponseGain => Scalar(c.response?.gain),
                    CameraField::ResponseGamma => Scalar(c.response?.gamma),
                    CameraField::ResponseBlack => Scalar(c.response?.black),
                    CameraField::Exposure => Scalar(c.exposure?),
                    CameraField::WhiteBalance => Vector(c.white_balance?),
                    CameraField::Fx => Scalar(c.fx?),
                    CameraField::Fy => Scalar(c.fy?),
                    CameraField::Cx => Scalar(c.cx?),
                    CameraField::Cy => Scalar(c.cy?),
                    CameraField::Rotation => Vector(c.rotation?),
                    CameraField::Translation => Vector(c.translation?),
                    CameraField::Distortion(k) => Scalar(c.distortion?[k]),
                }
            }
            Field::Transform(i, f) => transform_value(&scene.objects[i].transform, f),
        })
    }

    /// Writes `value` into the field. The caller resolved the field against a
    /// scene of the same structure, so the shapes match; a mismatch is ignored.
    pub fn set(&self, scene: &mut Scene, value: Value) {
        match *self {
            Field::Ambient => v(&mut scene.ambient, value),
            Field::IndirectLight => os(&mut scene.indirect_light, value),
            Field::Light(i, f) => set_light(&mut scene.lights[i], f, value),
            Field::Material(i, f) => set_material(&mut scene.objects[i].material, f, value),
            Field::Shape(i, f) => set_shape(&mut scene.objects[i].shape, f, value),
            Field::Camera(f) => set_camera(&mut scene.camera, f, value),
            Field::Transform(i, f) => set_transform(&mut scene.objects[i].transform, f, value),
        }
    }

    /// The dotted path that resolves to this field in `scene` (the inverse
    /// of [`Field::resolve`]), so that free entries can be written from
    /// typed fields.
    pub fn path(&self, scene: &Scene) -> String {
        match *self {
            Field::Ambient => "ambient".into(),
            Field::IndirectLight => "indirect_light".into(),
            Field::Light(i, f) => format!("lights.{}.{}", scene.lights[i].name, f.key()),
            Field::Material(i, f) => {
                format!("objects.{}.material.{}", scene.objects[i].name, f.key())
            }
            Field::Shape(i, f) => format!("objects.{}.shape.{f}", scene.objects[i].name),
            Field::Camera(f) => format!("camera.{}", f.key()),
            Field::Transform(i, f) => {
                format!("objects.{}.transform.{}", scene.objects[i].name, f.key())
            }
        }
    }

    /// True for colours (which may be searched in HSV).
    pub fn is_color(&self) -> bool {
        matches!(
            self,
            Field::Ambient
                | Field::Light(_, LightField::Color)
                | Field::Material(_, MaterialField::Color)
        )
    }

    /// True when changing the field moves what camera rays hit: the camera,
    /// a shape, or a refractive index. Renderers that cache ray hits across
    /// candidates must recompute them when such a field varies.
    pub fn moves_geometry(&self) -> bool {
        matches!(
            self,
            Field::Camera(
                CameraField::Position
                    | CameraField::LookAt
                    | CameraField::Up
                    | CameraField::FovY
                    | CameraField::Height
                    | CameraField::Fx
                    | CameraField::Fy
                    | CameraField::Cx
                    | CameraField::Cy
                    | CameraField::Rotation
                    | CameraField::Translation
                    | CameraField::Distortion(_)
            ) | Field::Shape(..)
                | Field::Transform(..)
                | Field::Material(_, MaterialField::Ior)
        )
    }

    /// True for fields applied to the finished image (camera vignetting and
    /// response), whatever renderer made it.
    pub fn is_image_space(&self) -> bool {
        matches!(
            self,
            Field::Camera(
                CameraField::Vignetting
                    | CameraField::ResponseGain
                    | CameraField::ResponseGamma
                    | CameraField::ResponseBlack
                    | CameraField::Exposure
                    | CameraField::WhiteBalance
            )
        )
    }
}

impl LightField {
    fn key(self) -> &'static str {
        match self {
            LightField::Position => "position",
            LightField::Direction => "direction",
            LightField::Color => "color",
            LightField::Intensity => "intensity",
            LightField::Radius => "radius",
            LightField::FalloffPower => "falloff_power",
            LightField::Distance => "distance",
        }
    }
}

impl MaterialField {
    fn key(self) -> &'static str {
        match self {
            MaterialField::Color => "color",
            MaterialField::Diffuse => "diffuse",
            MaterialField::Specular => "specular",
            MaterialField::Shininess => "shininess",
            MaterialField::Reflection => "reflection",
            MaterialField::Transmission => "transmission",
            MaterialField::Ior => "ior",
            MaterialField::Fresnel => "fresnel",
            MaterialField::Specular2 => "specular2",
            MaterialField::Shininess2 => "shininess2",
            MaterialField::DiffuseF90 => "diffuse_f90",
        }
    }
}

impl TransformField {
    fn key(self) -> &'static str {
        match self {
            TransformField::Translate => "translate",
            TransformField::RotateDeg => "rotate_deg",
            TransformField::Scale => "scale",
        }
    }
}

impl CameraField {
    fn key(self) -> &'static str {
        match self {
            CameraField::Position => "position",
            CameraField::LookAt => "look_at",
            CameraField::Up => "up",
            CameraField::FovY => "fov_y_deg",
            CameraField::Height => "height",
            CameraField::Vignetting => "vignetting.strength",
            CameraField::ResponseGain => "response.gain",
            CameraField::ResponseGamma => "response.gamma",
            CameraField::ResponseBlack => "response.black",
            CameraField::Exposure => "exposure",
            CameraField::WhiteBalance => "white_balance",
            CameraField::Fx => "fx",
            CameraField::Fy => "fy",
            CameraField::Cx => "cx",
            CameraField::Cy => "cy",
            CameraField::Rotation => "rotation",
            CameraField::Translation => "translation",
            CameraField::Distortion(0) => "distortion.k1",
            CameraField::Distortion(1) => "distortion.k2",
            CameraField::Distortion(2) => "distortion.p1",
            CameraField::Distortion(3) => "distortion.p2",
            CameraField::Distortion(_) => "distortion.k3",
        }
    }
}

/// `field` when the scene has it; optional effect fields must be set before
/// they can be freed.
fn present(scene: &Scene, field: Field, path: &str) -> Result<Field, String> {
    if field.get(scene).is_none() {
        return Err(format!(
            "the scene has no \"{path}\" (an optional field: give it a value first)"
        ));
    }
    Ok(field)
}

/// `lights.NAME.FIELD`.
fn light_field(scene: &Scene, name: &str, field: &str, path: &str) -> Result<Field, String> {
    let i = scene.light_index(name).ok_or_else(|| {
        format!(
            "no light named \"{name}\" (lights: {})",
            names(scene.lights.iter().map(|l| &l.name))
        )
    })?;
    let f = match field {
        "position" => LightField::Position,
        "direction" => LightField::Direction,
        "color" => LightField::Color,
        "intensity" => LightField::Intensity,
        "radius" => LightField::Radius,
        "falloff_power" => LightField::FalloffPower,
        "distance" => LightField::Distance,
        other => return Err(format!("a light has no numeric field \"{other}\" (expected position, direction, color, intensity, radius, falloff_power or distance)")),
    };
    if matches!(f, LightField::FalloffPower | LightField::Distance) {
        return present(scene, Field::Light(i, f), path);
    }
    Ok(Field::Light(i, f))
}

/// `objects.NAME.material.FIELD`.
fn material_field(scene: &Scene, name: &str, field: &str, path: &str) -> Result<Field, String> {
    let i = object(scene, name)?;
    let f = match field {
        "color" => MaterialField::Color,
        "diffuse" => MaterialField::Diffuse,
        "specular" => MaterialField::Specular,
        "shininess" => MaterialField::Shininess,
        "reflection" => MaterialField::Reflection,
        "transmission" => MaterialField::Transmission,
        "ior" => MaterialField::Ior,
        "fresnel" => MaterialField::Fresnel,
        "specular2" => MaterialField::Specular2,
        "shininess2" => MaterialField::Shininess2,
        "diffuse_f90" => MaterialField::DiffuseF90,
        other => return Err(format!("a material has no field \"{other}\" (expected color, diffuse, specular, shininess, reflection, transmission, ior, fresnel, specular2, shininess2 or diffuse_f90)")),
    };
    if matches!(
        f,
        MaterialField::Fresnel
            | MaterialField::Specular2
            | MaterialField::Shininess2
            | MaterialField::DiffuseF90
    ) {
        return present(scene, Field::Material(i, f), path);
    }
    Ok(Field::Material(i, f))
}

/// `objects.NAME.shape.FIELD`, when the object's shape has that field.
fn shape_field(scene: &Scene, name: &str, field: &str) -> Result<Field, String> {
    let i = object(scene, name)?;
    let shape = &scene.objects[i].shape;
    let names = shape.field_names();
    match names.iter().find(|k| **k == field) {
        Some(k) => Ok(Field::Shape(i, k)),
        None => Err(format!(
            "object \"{name}\" is a {} and has no numeric field \"{field}\" (expected {})",
            shape.type_name(),
            names.join(" or ")
        )),
    }
}

/// `objects.NAME.transform.FIELD`: resolves whether or not the object has
/// a transform (absent keys are the identity, written when first set).
fn transform_field(scene: &Scene, name: &str, field: &str) -> Result<Field, String> {
    let i = object(scene, name)?;
    let f = match field {
        "translate" => TransformField::Translate,
        "rotate_deg" => TransformField::RotateDeg,
        "scale" => TransformField::Scale,
        other => {
            return Err(format!(
                "a transform has no field \"{other}\" (expected translate, rotate_deg or scale)"
            ))
        }
    };
    Ok(Field::Transform(i, f))
}

/// A transform's value; an absent one is the identity's. A scale is a
/// number unless the scene gives one per axis.
fn transform_value(t: &Option<Transform>, f: TransformField) -> Value {
    let t = t.as_ref();
    match f {
        TransformField::Translate => Value::Vector(t.and_then(|t| t.translate).unwrap_or_default()),
        TransformField::RotateDeg => {
            Value::Vector(t.and_then(|t| t.rotate_deg).unwrap_or_default())
        }
        TransformField::Scale => match t.and_then(|t| t.scale) {
            Some(Scale::Axes(v)) => Value::Vector(v),
            Some(Scale::Uniform(x)) => Value::Scalar(x),
            None => Value::Scalar(1.0),
        },
    }
}

fn set_transform(t: &mut Option<Transform>, f: TransformField, value: Value) {
    let t = t.get_or_insert_with(Transform::default);
    match (f, value) {
        (TransformField::Translate, Value::Vector(v)) => t.translate = Some(v),
        (TransformField::RotateDeg, Value::Vector(v)) => t.rotate_deg = Some(v),
        (TransformField::Scale, Value::Vector(v)) => t.scale = Some(Scale::Axes(v)),
        (TransformField::Scale, Value::Scalar(x)) => t.scale = Some(Scale::Uniform(x)),
        _ => {}
    }
}

/// `camera.FIELD`, when the camera model has it.
fn camera_field(scene: &Scene, key: &str) -> Result<Field, String> {
    let f = match key {
        "position" => CameraField::Position,
        "look_at" => CameraField::LookAt,
        "up" => CameraField::Up,
        "fov_y_deg" => CameraField::FovY,
        "height" => CameraField::Height,
        "exposure" => CameraField::Exposure,
        "white_balance" => CameraField::WhiteBalance,
        "fx" => CameraField::Fx,
        "fy" => CameraField::Fy,
        "cx" => CameraField::Cx,
        "cy" => CameraField::Cy,
        "rotation" => CameraField::Rotation,
        "translation" => CameraField::Translation,
        other => return Err(format!("the camera has no numeric field \"{other}\"")),
    };
    let resolved = Field::Camera(f);
    if resolved.get(scene).is_none() {
        return Err(format!("this camera has no \"{field}\"", field = key));
    }
    Ok(resolved)
}

/// `camera.vignetting.strength`, `camera.response.gain|gamma|black`.
fn camera_group_field(
    scene: &Scene,
    group: &str,
    field: &str,
    path: &str,
) -> Result<Field, String> {
    let f = match (group, field) {
        ("vignetting", "strength") => CameraField::Vignetting,
        ("response", "gain") => CameraField::ResponseGain,
        ("response", "gamma") => CameraField::ResponseGamma,
        ("response", "black") => CameraField::ResponseBlack,
        ("distortion", k) if DISTORTION_KEYS.contains(&k) => {
            CameraField::Distortion(DISTORTION_KEYS.iter().position(|x| *x == k).unwrap_or(0))
        }
        _ => {
            return Err(
                "expected camera.vignetting.strength, camera.response.gain|gamma|black or camera.distortion.k1|k2|p1|p2|k3".into(),
            )
        }
    };
    present(scene, Field::Camera(f), path)
}

// Writers for one slot; a value of the other shape, or an absent optional
// slot, leaves it as it was.
fn s(slot: &mut f64, v: Value) {
    if let Value::Scalar(x) = v {
        *slot = x;
    }
}
fn v(slot: &mut [f64; 3], v: Value) {
    if let Value::Vector(x) = v {
        *slot = x;
    }
}
fn ov(slot: &mut Option<[f64; 3]>, val: Value) {
    if let (Some(slot), Value::Vector(x)) = (slot.as_mut(), val) {
        *slot = x;
    }
}
fn os(slot: &mut Option<f64>, val: Value) {
    if let (Some(slot), Value::Scalar(x)) = (slot.as_mut(), val) {
        *slot = x;
    }
}

fn set_light(l: &mut super::types::Light, f: LightField, value: Value) {
    match f {
        LightField::Position => ov(&mut l.position, value),
        LightField::Direction => ov(&mut l.direction, value),
        LightField::Color => v(&mut l.color, value),
        LightField::Intensity => s(&mut l.intensity, value),
        LightField::Radius => s(&mut l.radius, value),
        LightField::FalloffPower => os(&mut l.falloff_power, value),
        LightField::Distance => os(&mut l.distance, value),
    }
}

fn set_material(m: &mut super::types::Material, f: MaterialField, value: Value) {
    match f {
        MaterialField::Color => v(&mut m.color, value),
        MaterialField::Diffuse => s(&mut m.diffuse, value),
        MaterialField::Specular => s(&mut m.specular, value),
        MaterialField::Shininess => s(&mut m.shininess, value),
        MaterialField::Reflection => s(&mut m.reflection, value),
        MaterialField::Transmission => s(&mut m.transmission, value),
        MaterialField::Ior => s(&mut m.ior, value),
        MaterialField::Fresnel => os(&mut m.fresnel, value),
        MaterialField::Specular2 => os(&mut m.specular2, value),
        MaterialField::Shininess2 => os(&mut m.shininess2, value),
        MaterialField::DiffuseF90 => os(&mut m.diffuse_f90, value),
    }
}

fn set_shape(sh: &mut super::types::Shape, name: &str, value: Value) {
    match (sh.field_mut(name), value) {
        (Some([slot]), Value::Scalar(x)) => *slot = x,
        (Some(slot), Value::Vector(x)) if slot.len() == 3 => slot.copy_from_slice(&x),
        _ => {}
    }
}

fn set_camera(c: &mut super::types::Camera, f: CameraField, value: Value) {
    match f {
        CameraField::Position => ov(&mut c.position, value),
        CameraField::LookAt => ov(&mut c.look_at, value),
        CameraField::Up => v(&mut c.up, value),
        CameraField::FovY => os(&mut c.fov_y_deg, value),
        CameraField::Height => os(&mut c.height, value),
        CameraField::Vignetting => {
            if let Some(vg) = c.vignetting.as_mut() {
                s(&mut vg.strength, value)
            }
        }
        CameraField::ResponseGain => {
            if let Some(r) = c.response.as_mut() {
                s(&mut r.gain, value)
            }
        }
        CameraField::ResponseGamma => {
            if let Some(r) = c.response.as_mut() {
                s(&mut r.gamma, value)
            }
        }
        CameraField::ResponseBlack => {
            if let Some(r) = c.response.as_mut() {
                s(&mut r.black, value)
            }
        }
        CameraField::Exposure => os(&mut c.exposure, value),
        CameraField::WhiteBalance => ov(&mut c.white_balance, value),
        CameraField::Fx => os(&mut c.fx, value),
        CameraField::Fy => os(&mut c.fy, value),
        CameraField::Cx => os(&mut c.cx, value),
        CameraField::Cy => os(&mut c.cy, value),
        CameraField::Rotation => ov(&mut c.rotation, value),
        CameraField::Translation => ov(&mut c.translation, value),
        CameraField::Distortion(k) => {
            if let (Some(d), Value::Scalar(x)) = (c.distortion.as_mut(), value) {
                d[k] = x;
            }
        }
    }
}

fn object(scene: &Scene, name: &str) -> Result<usize, String> {
    scene.object_index(name).ok_or_else(|| {
        format!(
            "no object named \"{name}\" (objects: {})",
            names(scene.objects.iter().map(|o| &o.name))
        )
    })
}

fn names<'a>(it: impl Iterator<Item = &'a String>) -> String {
    let v: Vec<&str> = it.map(|s| s.as_str()).collect();
    if v.is_empty() {
        "none".into()
    } else {
        v.join(", ")
    }
}
