//! What a scene offers as free parameters, and `free` entries made from a
//! short spec (`lights.*.position`) with default bounds around the current
//! values, so that a scene read from another tool can be fitted without
//! hand-editing its `free` list (docs/interchange.md, "Free parameters").
//!
//! The defaults depend on the kind of field (the table in the docs): a
//! colour or a fraction spans [0, 1]; a positive scale (an intensity, a
//! shininess, a field of view) [v/2, 2v]; a point ± a quarter of its
//! distance from the camera, so that the span follows the scene's units;
//! a direction, an angle, a lens coefficient a fixed offset.

use crate::error::{Error, Result};
use crate::math::V3;
use crate::scene::field::{CameraField, LightField, MaterialField, TransformField};
use crate::scene::{Bound, CameraKind, Field, FreeParam, Scene, Value};

/// The fields every light, material, transform and camera may have; those
/// a scene lacks have no value and are left out. Paths are spelled by
/// `Field::path`, the one writer of field names.
const LIGHT: [LightField; 7] = [
    LightField::Position,
    LightField::Direction,
    LightField::Color,
    LightField::Intensity,
    LightField::Radius,
    LightField::FalloffPower,
    LightField::Distance,
];
const MATERIAL: [MaterialField; 11] = [
    MaterialField::Color,
    MaterialField::Diffuse,
    MaterialField::Specular,
    MaterialField::Shininess,
    MaterialField::Reflection,
    MaterialField::Transmission,
    MaterialField::Ior,
    MaterialField::Fresnel,
    MaterialField::Specular2,
    MaterialField::Shininess2,
    MaterialField::DiffuseF90,
];
const TRANSFORM: [TransformField; 3] = [
    TransformField::Translate,
    TransformField::RotateDeg,
    TransformField::Scale,
];
const CAMERA: [CameraField; 18] = [
    CameraField::Position,
    CameraField::LookAt,
    CameraField::Up,
    CameraField::FovY,
    CameraField::Height,
    CameraField::Exposure,
    CameraField::WhiteBalance,
    CameraField::Fx,
    CameraField::Fy,
    CameraField::Cx,
    CameraField::Cy,
    CameraField::Rotation,
    CameraField::Translation,
    CameraField::Vignetting,
    CameraField::ResponseGain,
    CameraField::ResponseGamma,
    CameraField::ResponseBlack,
    CameraField::Distortion(0),
];

/// One field a scene offers: its path, value and default bounds.
#[derive(Clone, Debug)]
pub struct Offer {
    pub path: String,
    pub value: Value,
    pub min: Bound,
    pub max: Bound,
}

/// Every numeric field of `scene`, in the scene's order.
pub fn offers(scene: &Scene) -> Vec<Offer> {
    let mut fields = vec![Field::Ambient, Field::IndirectLight];
    for i in 0..scene.lights.len() {
        fields.extend(LIGHT.iter().map(|&f| Field::Light(i, f)));
    }
    for (i, o) in scene.objects.iter().enumerate() {
        fields.extend(MATERIAL.iter().map(|&f| Field::Material(i, f)));
        fields.extend(o.shape.fields().iter().map(|(f, _)| Field::Shape(i, f)));
        fields.extend(TRANSFORM.iter().map(|&f| Field::Transform(i, f)));
    }
    for f in CAMERA {
        match f {
            CameraField::Distortion(_) => {
                fields.extend((0..5).map(|k| Field::Camera(CameraField::Distortion(k))))
            }
            // a pinhole is placed by rotation and translation; its `up` is unused
            CameraField::Up if scene.camera.kind == CameraKind::Pinhole => {}
            f => fields.push(Field::Camera(f)),
        }
    }
    fields
        .into_iter()
        .filter_map(|field| {
            let value = field.get(scene)?;
            let (min, max) = default_bounds(scene, &field, value);
            Some(Offer {
                path: field.path(scene),
                value,
                min,
                max,
            })
        })
        .collect()
}

/// How a field's default bounds sit around its value `v`.
#[derive(Clone, Copy)]
enum Rule {
    /// [0, max(1, v)]: a colour or a fraction.
    Unit,
    /// [v/2, 2v]: a positive scale ([0, 1] at 0).
    Factor,
    /// v ± d; `signed`: the bound may go below 0.
    Offset(f64, bool),
    /// v ± a quarter of the distance from the camera (a point).
    Place,
    /// v ± a quarter of |v| per component (a vector whose length is its scale).
    Spread,
}

fn rule(scene: &Scene, field: &Field) -> Rule {
    use Rule::*;
    match *field {
        Field::Ambient | Field::IndirectLight => Unit,
        Field::Light(_, f) => match f {
            LightField::Position => Place,
            LightField::Direction => Offset(0.5, true),
            LightField::Color => Unit,
            LightField::Intensity | LightField::Radius | LightField::Distance => Factor,
            LightField::FalloffPower => Offset(1.0, false),
        },
        Field::Material(_, f) => match f {
            MaterialField::Shininess | MaterialField::Shininess2 => Factor,
            MaterialField::Ior => Offset(0.3, false),
            _ => Unit,
        },
        Field::Shape(_, "radius") => Factor,
        Field::Shape(_, "normal") => Offset(0.5, true),
        Field::Shape(_, "edge_u" | "edge_v") => Spread,
        Field::Shape(..) => Place,
        Field::Transform(_, f) => match f {
            TransformField::Translate => Place,
            TransformField::RotateDeg => Offset(30.0, true),
            TransformField::Scale => Factor,
        },
        Field::Camera(f) => match f {
            CameraField::Position | CameraField::LookAt => Place,
            CameraField::Up => Offset(0.2, true),
            CameraField::Vignetting => Unit,
            CameraField::ResponseBlack => Offset(0.05, true),
            CameraField::Fx | CameraField::Fy | CameraField::Translation => Spread,
            CameraField::Cx => Offset(0.05 * scene.image.width as f64, true),
            CameraField::Cy => Offset(0.05 * scene.image.height as f64, true),
            CameraField::Rotation => Offset(0.1, true),
            CameraField::Distortion(_) => Offset(0.1, true),
            _ => Factor,
        },
    }
}

/// The default bounds of `field`, at value `value`.
fn default_bounds(scene: &Scene, field: &Field, value: Value) -> (Bound, Bound) {
    let v = value.components();
    let eye = V3::from(scene.camera.eye());
    let length = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let (mut lo, mut hi) = (Vec::new(), Vec::new());
    for &x in &v {
        let (a, b) = match rule(scene, field) {
            Rule::Unit => (0.0, x.max(1.0)),
            Rule::Factor if x == 0.0 => (0.0, 1.0),
            Rule::Factor => ((x / 2.0).min(2.0 * x), (x / 2.0).max(2.0 * x)),
            Rule::Offset(d, signed) => (if signed { x - d } else { (x - d).max(0.0) }, x + d),
            Rule::Spread => (x - 0.25 * length, x + 0.25 * length),
            Rule::Place => {
                let p = if v.len() == 3 {
                    V3::new(v[0], v[1], v[2])
                } else {
                    eye
                };
                let mut d = 0.25 * (p - eye).length();
                if d < 1e-9 {
                    d = 0.25 * (V3::from(scene.camera.target()) - eye).length();
                }
                (x - d, x + d)
            }
        };
        lo.push(a);
        hi.push(b);
    }
    let bound = |c: Vec<f64>| match c.as_slice() {
        [x] => Bound::Scalar(*x),
        _ => Bound::Vector([c[0], c[1], c[2]]),
    };
    (bound(lo), bound(hi))
}

/// True when `path` matches `pattern` segment by segment, `*` standing
/// for any run of characters within one segment.
pub fn matches(pattern: &str, path: &str) -> bool {
    let (p, q): (Vec<&str>, Vec<&str>) = (pattern.split('.').collect(), path.split('.').collect());
    p.len() == q.len() && p.iter().zip(&q).all(|(a, b)| segment(a, b))
}

fn segment(pattern: &str, s: &str) -> bool {
    match pattern.split_once('*') {
        None => pattern == s,
        Some((head, rest)) => {
            let Some(tail) = s.strip_prefix(head) else {
                return false;
            };
            (0..=tail.len())
                .filter(|&i| tail.is_char_boundary(i))
                .any(|i| segment(rest, &tail[i..]))
        }
    }
}

/// `scene` with every field a spec matches added to its `free` list at
/// its default bounds (a field already free keeps its entry); the error
/// names a spec that matches nothing. Returns the paths added.
pub fn apply(scene: &mut Scene, specs: &[String], file: &str) -> Result<Vec<String>> {
    let offers = offers(scene);
    let mut added = Vec::new();
    for spec in specs {
        let hits: Vec<&Offer> = offers.iter().filter(|o| matches(spec, &o.path)).collect();
        if hits.is_empty() {
            return Err(Error::Usage(format!(
                "--free {}: matches no field of {file}; `scenefit free {file}` lists them",
                crate::scene::limits::quote(spec)
            )));
        }
        for o in hits {
            if scene.free.iter().any(|f| f.param == o.path) || added.contains(&o.path) {
                continue;
            }
            scene.free.push(FreeParam {
                param: o.path.clone(),
                min: o.min,
                max: o.max,
                space: Default::default(),
                phase: None,
                per_shot: false,
            });
            added.push(o.path.clone());
        }
    }
    Ok(added)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn globs_match_one_segment_per_star() {
        assert!(matches("lights.*.position", "lights.key.position"));
        assert!(!matches("lights.*.position", "lights.key.color"));
        assert!(!matches("lights.*", "lights.key.position"));
        assert!(matches(
            "objects.b*.material.*",
            "objects.ball.material.color"
        ));
        assert!(!matches(
            "objects.b*.material.*",
            "objects.floor.material.color"
        ));
        assert!(matches("camera.distortion.k*", "camera.distortion.k3"));
    }

    #[test]
    fn defaults_follow_the_kind_of_field_and_the_scene_validates() {
        let mut s = crate::scene::test_scene::ball(
            r#""color": [0.5, 0.5, 0.5], "specular": 0.3, "shininess": 20"#,
            "",
        );
        s.free.clear();
        let added = apply(
            &mut s,
            &["lights.*.position".into(), "objects.*.material.*".into()],
            "t.json",
        )
        .unwrap();
        assert!(
            added.contains(&"objects.ball.material.shininess".to_string()),
            "{added:?}"
        );
        let pos = offers(&s)
            .into_iter()
            .find(|o| o.path.ends_with(".position"))
            .unwrap();
        let (Value::Vector(p), Bound::Vector(lo)) = (pos.value, pos.min) else {
            panic!()
        };
        let d = 0.25 * (V3::from(p) - V3::from(s.camera.eye())).length();
        assert!((p[0] - lo[0] - d).abs() < 1e-12);
        let text = serde_json::to_value(&s).unwrap();
        crate::scene::load::from_value(text, "t.json").unwrap();
        let e = apply(&mut s, &["lights.*.nothing".into()], "t.json").unwrap_err();
        assert!(e.to_string().contains("matches no field of t.json"), "{e}");
    }
}
