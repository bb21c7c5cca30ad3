//! The shapes of the scene format as types: one enum variant per shape,
//! holding exactly that shape's fields, selected by the JSON `"type"`.
//! A new shape is a new variant here; the compiler then points at every
//! `match` that must handle it (validation, the built-in tracer's
//! geometry, the POV-Ray writer). Free parameters reach a shape's numbers
//! by field name through [`Shape::fields`] and [`Shape::fields_mut`].

use super::checks::{finite3, nonzero3, positive};
use super::texture::tangent::Tangents;
use crate::error::{Error, Result};
use crate::math::{Vec3, V3};
use serde::{Deserialize, Serialize};

/// A surface. Every field is required; unknown fields are refused.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum Shape {
    Sphere {
        center: Vec3,
        radius: f64,
    },
    /// The infinite plane through `point` with normal `normal`.
    Plane {
        point: Vec3,
        normal: Vec3,
    },
    /// The parallelogram corner + s·edge_u + t·edge_v, s and t in [0, 1].
    Quad {
        corner: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
    },
    /// Axis-aligned, between its `min` and `max` corners.
    Box {
        min: Vec3,
        max: Vec3,
    },
    /// A triangle mesh read from a PLY or OBJ file (`scene/mesh/`): the
    /// path relative to the scene file, absolute once the scene is read.
    Mesh {
        file: String,
    },
}

/// The arms of [`Shape::fields`] and [`Shape::fields_mut`], written once:
/// `$one` makes one number a slice of one (`from_ref` or `from_mut`).
macro_rules! numeric_fields {
    ($shape:expr, $one:path) => {
        match $shape {
            Shape::Sphere { center, radius } => vec![("center", center), ("radius", $one(radius))],
            Shape::Plane { point, normal } => vec![("point", point), ("normal", normal)],
            Shape::Quad {
                corner,
                edge_u,
                edge_v,
            } => vec![("corner", corner), ("edge_u", edge_u), ("edge_v", edge_v)],
            Shape::Box { min, max } => vec![("min", min), ("max", max)],
            // placed by the object's transform, which holds its numbers
            Shape::Mesh { .. } => vec![],
        }
    };
}

impl Shape {
    /// The JSON `"type"` of the shape.
    pub fn type_name(&self) -> &'static str {
        match self {
            Shape::Sphere { .. } => "sphere",
            Shape::Plane { .. } => "plane",
            Shape::Quad { .. } => "quad",
            Shape::Box { .. } => "box",
            Shape::Mesh { .. } => "mesh",
        }
    }

    /// The shape's numeric fields, by name, in the file's order: one
    /// number (a slice of one) or a 3-vector.
    pub fn fields(&self) -> Vec<(&'static str, &[f64])> {
        numeric_fields!(self, std::slice::from_ref)
    }

    /// [`Shape::fields`], writable.
    pub fn fields_mut(&mut self) -> Vec<(&'static str, &mut [f64])> {
        numeric_fields!(self, std::slice::from_mut)
    }

    /// Texture coordinates (u, v) of the point `p` (object frame) on the
    /// shape, by its rule in `texture::uv`; None for a mesh (its
    /// coordinates come from its triangles: `texture::uv::mesh_uv`).
    pub fn uv(&self, p: V3) -> Option<[f64; 2]> {
        use super::texture::uv;
        let v = V3::from;
        match *self {
            Shape::Sphere { center, .. } => Some(uv::sphere_uv(v(center), p)),
            Shape::Plane { point, normal } => Some(uv::plane_uv(v(point), v(normal), p)),
            Shape::Quad {
                corner,
                edge_u,
                edge_v,
            } => Some(uv::quad_uv(v(corner), v(edge_u), v(edge_v), p)),
            Shape::Box { min, max } => Some(uv::box_uv(v(min), v(max), p)),
            Shape::Mesh { .. } => None,
        }
    }

    /// The surfaces a map is laid on one by one: a box's six faces, each
    /// a quad laid out as the box lays that face (`texture::uv::box_faces`),
    /// for a backend whose box has no per-face coordinates; any other shape
    /// itself.
    pub fn faces(&self) -> Vec<Shape> {
        let Shape::Box { min, max } = *self else {
            return vec![self.clone()];
        };
        super::texture::uv::box_faces(V3::from(min), V3::from(max))
            .into_iter()
            .map(|(c, u, v)| Shape::Quad {
                corner: c.to_array(),
                edge_u: u.to_array(),
                edge_v: v.to_array(),
            })
            .collect()
    }

    /// The tangent frame a normal map is read in at the point `p` (object
    /// frame), by the shape's rule in `texture::tangent`, following its
    /// `uv`; None for a mesh (`texture::tangent::mesh_tangents`).
    pub fn tangents(&self, p: V3) -> Option<Tangents> {
        use super::texture::tangent as t;
        let v = V3::from;
        match *self {
            Shape::Sphere { center, .. } => Some(t::sphere_tangents(v(center), p)),
            Shape::Plane { normal, .. } => Some(t::plane_tangents(v(normal))),
            Shape::Quad { edge_u, edge_v, .. } => Some(t::quad_tangents(v(edge_u), v(edge_v))),
            Shape::Box { min, max } => Some(t::box_tangents(v(min), v(max), p)),
            Shape::Mesh { .. } => None,
        }
    }

    /// Refuses values the types cannot rule out (a negative radius, a
    /// zero normal), naming `file` and the key under `at`.
    pub fn check(&self, file: &str, at: &str) -> Result<()> {
        let key = |k: &str| format!("{at}.{k}");
        let finite = |k: &str, v: Vec3| -> Result<()> {
            if !finite3(v) {
                return Err(Error::invalid(file, key(k), "expected finite numbers"));
            }
            Ok(())
        };
        match self {
            Shape::Mesh { file: path } => {
                // the file itself is read and checked with the scene
                // (`validate.rs`, `mesh::check`)
                if path.trim().is_empty() {
                    return Err(Error::invalid(
                        file,
                        key("file"),
                        "expected a PLY or OBJ file's path",
                    ));
                }
                Ok(())
            }
            &Shape::Sphere { center, radius } => {
                finite("center", center)?;
                positive(file, &key("radius"), radius)
            }
            &Shape::Plane { point, normal } => {
                finite("point", point)?;
                nonzero3(file, &key("normal"), normal)
            }
            &Shape::Quad {
                corner,
                edge_u,
                edge_v,
            } => {
                finite("corner", corner)?;
                nonzero3(file, &key("edge_u"), edge_u)?;
                nonzero3(file, &key("edge_v"), edge_v)?;
                if V3::from(edge_u).cross(V3::from(edge_v)).length() < 1e-12 {
                    return Err(Error::invalid(
                        file,
                        key("edge_v"),
                        "is parallel to edge_u; expected two edges that span a parallelogram",
                    ));
                }
                Ok(())
            }
            &Shape::Box { min, max } => {
                finite("min", min)?;
                finite("max", max)?;
                if (0..3).any(|a| min[a] >= max[a]) {
                    return Err(Error::invalid(
                        file,
                        key("max"),
                        format!("expected every component above min {min:?}, got {max:?}"),
                    ));
                }
                Ok(())
            }
        }
    }

    /// True when the shape stays itself under a scale per axis (a sphere
    /// would become an ellipsoid, which is not drawn).
    pub fn takes_axis_scales(&self) -> bool {
        match self {
            Shape::Sphere { .. } => false,
            Shape::Plane { .. } | Shape::Quad { .. } | Shape::Box { .. } | Shape::Mesh { .. } => {
                true
            }
        }
    }

    /// The numeric field `name`, if this shape has one.
    pub fn field(&self, name: &str) -> Option<&[f64]> {
        self.fields()
            .into_iter()
            .find_map(|(k, v)| (k == name).then_some(v))
    }

    /// The numeric field `name`, writable, if this shape has one.
    pub fn field_mut(&mut self, name: &str) -> Option<&mut [f64]> {
        self.fields_mut()
            .into_iter()
            .find_map(|(k, v)| (k == name).then_some(v))
    }

    /// The names of the shape's numeric fields.
    pub fn field_names(&self) -> Vec<&'static str> {
        self.fields().into_iter().map(|(k, _)| k).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(json: &str) -> Result<Shape, String> {
        serde_json::from_str(json).map_err(|e| e.to_string())
    }

    /// Every variant reads from and writes back to the same JSON, the
    /// `"type"` first (the format scene files and outside scripts use).
    #[test]
    fn every_shape_round_trips_through_its_json() {
        for json in [
            r#"{"type":"sphere","center":[0.0,0.5,0.0],"radius":0.5}"#,
            r#"{"type":"plane","point":[0.0,0.0,0.0],"normal":[0.0,1.0,0.0]}"#,
            r#"{"type":"quad","corner":[0.0,0.0,0.0],"edge_u":[1.0,0.0,0.0],"edge_v":[0.0,0.0,1.0]}"#,
            r#"{"type":"box","min":[0.0,0.0,0.0],"max":[1.0,2.0,3.0]}"#,
            r#"{"type":"mesh","file":"model.ply"}"#,
        ] {
            let shape = parse(json).unwrap();
            assert_eq!(serde_json::to_string(&shape).unwrap(), json);
            assert_eq!(shape.type_name(), json.split('"').nth(3).unwrap(), "{json}");
        }
    }

    #[test]
    fn a_missing_or_foreign_field_and_an_unknown_type_are_refused_by_name() {
        let e = parse(r#"{"type":"sphere","center":[0,0,0]}"#).unwrap_err();
        assert!(e.contains("missing field `radius`"), "{e}");
        let e =
            parse(r#"{"type":"sphere","center":[0,0,0],"radius":1,"normal":[0,1,0]}"#).unwrap_err();
        assert!(e.contains("unknown field `normal`"), "{e}");
        let e = parse(r#"{"type":"cone","center":[0,0,0]}"#).unwrap_err();
        assert!(e.contains("unknown variant `cone`"), "{e}");
    }

    /// Numbers as f64, so that a file's `0` equals a written `0.0`.
    fn numbers_as_f64(v: &serde_json::Value) -> serde_json::Value {
        use serde_json::Value;
        match v {
            Value::Number(n) => serde_json::json!(n.as_f64()),
            Value::Array(a) => Value::Array(a.iter().map(numbers_as_f64).collect()),
            Value::Object(o) => Value::Object(
                o.iter()
                    .map(|(k, x)| (k.clone(), numbers_as_f64(x)))
                    .collect(),
            ),
            other => other.clone(),
        }
    }

    fn json_files(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
        for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                json_files(&p, out);
            } else if p.extension().is_some_and(|x| x == "json") {
                out.push(p);
            }
        }
    }

    /// The shipped scenes' shapes read into the enum and are written back
    /// as the files hold them.
    #[test]
    fn every_shipped_scene_shape_is_written_back_as_read() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut files = Vec::new();
        for dir in ["scenes", "examples", "tests/data", "tests/effects_data"] {
            json_files(&root.join(dir), &mut files);
        }
        let mut shapes = 0;
        for f in files {
            let Ok(v) =
                serde_json::from_str::<serde_json::Value>(&std::fs::read_to_string(&f).unwrap())
            else {
                continue;
            };
            for o in v["objects"].as_array().into_iter().flatten() {
                let read: Shape = serde_json::from_value(o["shape"].clone())
                    .unwrap_or_else(|e| panic!("{}: {e}", f.display()));
                let written = serde_json::to_value(&read).unwrap();
                assert_eq!(written, numbers_as_f64(&o["shape"]), "{}", f.display());
                shapes += 1;
            }
        }
        assert!(shapes >= 10, "{shapes} shapes found");
    }

    #[test]
    fn fields_are_read_and_written_by_name() {
        let mut s = parse(r#"{"type":"sphere","center":[1,2,3],"radius":0.5}"#).unwrap();
        assert_eq!(s.field_names(), ["center", "radius"]);
        assert_eq!(s.field("radius"), Some(&[0.5][..]));
        assert_eq!(s.field("normal"), None);
        s.field_mut("center").unwrap()[1] = 7.0;
        s.field_mut("radius").unwrap()[0] = 2.0;
        assert_eq!(
            s,
            Shape::Sphere {
                center: [1.0, 7.0, 3.0],
                radius: 2.0
            }
        );
    }
}
