//! An object's placement: `"transform": {"translate": [x, y, z],
//! "rotate_deg": [rx, ry, rz], "scale": s or [sx, sy, sz]}` on any object,
//! each key optional. A point of the shape is scaled first, then rotated
//! about the world x, then y, then z axis (right-handed, degrees), then
//! translated. Every backend draws it; each key is a free parameter
//! (`objects.NAME.transform.translate|rotate_deg|scale`, scene/field.rs).

use crate::math::Vec3;
use crate::math::V3;
use serde::{Deserialize, Serialize};

/// Where an object's shape is placed; absent keys are the identity.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Transform {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub translate: Option<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotate_deg: Option<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<Scale>,
}

/// One factor for every axis, or one per axis.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
#[serde(untagged)]
pub enum Scale {
    Uniform(f64),
    Axes(Vec3),
}

impl Scale {
    /// The factor along each axis.
    pub fn axes(self) -> Vec3 {
        match self {
            Scale::Uniform(s) => [s; 3],
            Scale::Axes(v) => v,
        }
    }

    /// The one factor of every axis, when they are all the same.
    pub fn uniform(self) -> Option<f64> {
        let [x, y, z] = self.axes();
        (x == y && y == z).then_some(x)
    }
}

// By hand rather than untagged: the message then says what a scale is.
impl<'de> Deserialize<'de> for Scale {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Scale, D::Error> {
        struct Visit;
        impl<'de> serde::de::Visitor<'de> for Visit {
            type Value = Scale;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or an array of three numbers")
            }
            fn visit_f64<E>(self, x: f64) -> Result<Scale, E> {
                Ok(Scale::Uniform(x))
            }
            fn visit_u64<E>(self, x: u64) -> Result<Scale, E> {
                Ok(Scale::Uniform(x as f64))
            }
            fn visit_i64<E>(self, x: i64) -> Result<Scale, E> {
                Ok(Scale::Uniform(x as f64))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<Scale, A::Error> {
                let v: Vec3 =
                    Deserialize::deserialize(serde::de::value::SeqAccessDeserializer::new(seq))?;
                Ok(Scale::Axes(v))
            }
        }
        d.deserialize_any(Visit)
    }
}

/// A transform as a matrix and a translation: x -> m x + t.
#[derive(Clone, Copy, Debug)]
pub struct Affine {
    /// Rows of R S.
    m: [V3; 3],
    /// Rows of R S^-1, which carries normals.
    n: [V3; 3],
    t: V3,
}

impl Affine {
    pub fn new(tr: &Transform) -> Affine {
        let s = V3::from(tr.scale.map_or([1.0; 3], Scale::axes));
        let [rx, ry, rz] = tr.rotate_deg.unwrap_or_default().map(f64::to_radians);
        // Rz Ry Rx: about x first, then y, then z.
        let r = mul(rot(2, rz), mul(rot(1, ry), rot(0, rx)));
        let scale_cols = |f: &dyn Fn(f64) -> f64| {
            r.map(|row| V3::new(row.x * f(s.x), row.y * f(s.y), row.z * f(s.z)))
        };
        Affine {
            m: scale_cols(&|k| k),
            n: scale_cols(&|k| 1.0 / k),
            t: V3::from(tr.translate.unwrap_or_default()),
        }
    }

    pub fn point(&self, p: V3) -> V3 {
        self.vector(p) + self.t
    }

    /// A direction or an edge: scaled and rotated, not moved.
    pub fn vector(&self, v: V3) -> V3 {
        V3::new(self.m[0].dot(v), self.m[1].dot(v), self.m[2].dot(v))
    }

    /// A surface normal (not unit): the inverse transpose keeps it
    /// perpendicular to the transformed surface.
    pub fn normal(&self, n: V3) -> V3 {
        V3::new(self.n[0].dot(n), self.n[1].dot(n), self.n[2].dot(n))
    }

    /// The object-frame normal that [`Affine::normal`] carries to the
    /// direction of `n` (M^T n): for a renderer that transforms normals
    /// itself but must show one worked out in the world.
    pub fn normal_back(&self, n: V3) -> V3 {
        self.m[0] * n.x + self.m[1] * n.y + self.m[2] * n.z
    }
}

/// The rotation by `a` radians about world axis `axis`, as rows.
fn rot(axis: usize, a: f64) -> [V3; 3] {
    let (s, c) = a.sin_cos();
    match axis {
        0 => [
            V3::new(1.0, 0.0, 0.0),
            V3::new(0.0, c, -s),
            V3::new(0.0, s, c),
        ],
        1 => [
            V3::new(c, 0.0, s),
            V3::new(0.0, 1.0, 0.0),
            V3::new(-s, 0.0, c),
        ],
        _ => [
            V3::new(c, -s, 0.0),
            V3::new(s, c, 0.0),
            V3::new(0.0, 0.0, 1.0),
        ],
    }
}

fn mul(a: [V3; 3], b: [V3; 3]) -> [V3; 3] {
    let col = |j: usize| V3::new(b[0].get(j), b[1].get(j), b[2].get(j));
    a.map(|row| V3::new(row.dot(col(0)), row.dot(col(1)), row.dot(col(2))))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: V3, b: V3) -> bool {
        (a - b).length() < 1e-12
    }

    fn tr(json: &str) -> Transform {
        serde_json::from_str(json).unwrap()
    }

    #[test]
    fn scale_then_x_then_y_then_z_then_translate() {
        let a = Affine::new(&tr(
            r#"{"translate": [1, 2, 3], "rotate_deg": [90, 90, 0], "scale": [2, 1, 1]}"#,
        ));
        // x: scaled to 2, x-rotation keeps it, y-rotation by 90 turns +x to -z.
        assert!(close(
            a.point(V3::new(1.0, 0.0, 0.0)),
            V3::new(1.0, 2.0, 1.0)
        ));
        // y: x-rotation by 90 turns +y to +z, y-rotation turns +z to +x.
        assert!(close(
            a.vector(V3::new(0.0, 1.0, 0.0)),
            V3::new(1.0, 0.0, 0.0)
        ));
        let z = Affine::new(&tr(r#"{"rotate_deg": [0, 0, 90]}"#));
        assert!(close(
            z.vector(V3::new(1.0, 0.0, 0.0)),
            V3::new(0.0, 1.0, 0.0)
        ));
    }

    /// A transformed normal stays perpendicular to the transformed surface
    /// under a non-uniform scale.
    #[test]
    fn normals_stay_perpendicular() {
        let a = Affine::new(&tr(
            r#"{"rotate_deg": [30, -20, 75], "scale": [3, 0.5, 2]}"#,
        ));
        let (u, v) = (V3::new(1.0, 1.0, 0.0), V3::new(0.0, 1.0, 1.0));
        let n = a.normal(u.cross(v));
        assert!(n.dot(a.vector(u)).abs() < 1e-12 && n.dot(a.vector(v)).abs() < 1e-12);
    }

    /// The ball test scene with `transform` on its sphere, loaded.
    fn ball_with(transform: serde_json::Value) -> Result<(), String> {
        let scene = crate::scene::test_scene::ball(r#""color": [0.5, 0.5, 0.5]"#, "");
        let mut v = serde_json::to_value(&scene).unwrap();
        v["objects"][0]["transform"] = transform;
        crate::scene::load::from_value(v, "t.json")
            .map(|_| ())
            .map_err(|e| e.to_string())
    }

    #[test]
    fn a_stretched_sphere_and_a_flat_scale_are_refused_naming_the_key() {
        assert!(ball_with(serde_json::json!({"scale": 2, "rotate_deg": [0, 45, 0]})).is_ok());
        let e = ball_with(serde_json::json!({"scale": [1, 2, 1]})).unwrap_err();
        assert!(
            e.contains("t.json") && e.contains("objects[0].transform.scale"),
            "{e}"
        );
        assert!(e.contains("a sphere takes one scale"), "{e}");
        let e = ball_with(serde_json::json!({"scale": 0})).unwrap_err();
        assert!(
            e.contains("objects[0].transform.scale") && e.contains("positive"),
            "{e}"
        );
        let e = ball_with(serde_json::json!({"turn": [0, 1, 0]})).unwrap_err();
        assert!(
            e.contains("objects[0].transform") && e.contains("unknown field"),
            "{e}"
        );
    }

    /// A transform's keys resolve as free fields on an object without one
    /// (the identity's values), and writing one creates the transform.
    #[test]
    fn transform_keys_are_fields_even_before_the_object_has_one() {
        use crate::scene::field::{Field, Value};
        let mut scene = crate::scene::test_scene::ball(r#""color": [0.5, 0.5, 0.5]"#, "");
        assert!(scene.objects[0].transform.is_none());
        let turn = Field::resolve(&scene, "objects.ball.transform.rotate_deg").unwrap();
        let scale = Field::resolve(&scene, "objects.ball.transform.scale").unwrap();
        assert_eq!(turn.get(&scene), Some(Value::Vector([0.0; 3])));
        assert_eq!(scale.get(&scene), Some(Value::Scalar(1.0)));
        assert!(turn.moves_geometry() && scale.moves_geometry());
        turn.set(&mut scene, Value::Vector([0.0, 30.0, 0.0]));
        scale.set(&mut scene, Value::Scalar(2.0));
        let t = scene.objects[0].transform.as_ref().unwrap();
        assert_eq!(t.rotate_deg, Some([0.0, 30.0, 0.0]));
        assert_eq!(t.scale, Some(Scale::Uniform(2.0)));
        assert_eq!(turn.path(&scene), "objects.ball.transform.rotate_deg");
        let e = Field::resolve(&scene, "objects.ball.transform.turn").unwrap_err();
        assert!(e.contains("translate, rotate_deg or scale"), "{e}");
    }

    #[test]
    fn a_scale_is_a_number_or_three_and_is_written_back_as_read() {
        for json in [
            r#"{"scale":2.0}"#,
            r#"{"translate":[1.0,0.0,0.0],"scale":[1.0,2.0,3.0]}"#,
        ] {
            let t = tr(json);
            assert_eq!(serde_json::to_string(&t).unwrap(), json);
        }
        assert_eq!(tr(r#"{"scale": 2}"#).scale.unwrap().uniform(), Some(2.0));
        assert_eq!(tr(r#"{"scale": [1, 2, 3]}"#).scale.unwrap().uniform(), None);
        let e = serde_json::from_str::<Transform>(r#"{"scale": "big"}"#).unwrap_err();
        assert!(
            e.to_string()
                .contains("a number or an array of three numbers"),
            "{e}"
        );
        assert!(serde_json::from_str::<Transform>(r#"{"move": [1, 2, 3]}"#).is_err());
    }
}
