//! The tangent frame a normal map (`material.normal_map`) is read in:
//! the surface's derivatives along its texture coordinates (dP/du,
//! dP/dv) and its outward normal, in the object's own frame, following
//! the parametrisations of `uv.rs` (so that every backend perturbs the
//! same way): a plane's e_u and e_v, a quad's edges, a sphere's east and
//! north, a box face's axes, a mesh triangle's from its corners' (u, v).
//! On every primitive dP/du x dP/dv points outward. The map's `scale`
//! does not enter: Blender and Mitsuba take their tangents from the
//! surface's own coordinates too.

use super::uv::{box_face, plane_axes};
use crate::math::V3;
use crate::scene::mesh::Mesh;

/// dP/du, dP/dv (directions, any length; zero where undefined: a
/// sphere's poles, a triangle whose (u, v) are in a line) and the
/// outward normal (any length), object frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tangents {
    pub du: V3,
    pub dv: V3,
    pub n: V3,
}

/// The frame at `p` on a sphere about `center`: east (u grows) and north
/// (v grows), both times cos(latitude), and the outward direction.
pub fn sphere_tangents(center: V3, p: V3) -> Tangents {
    let d = (p - center).normalized();
    let east = V3::new(d.z, 0.0, -d.x);
    let north = V3::new(-d.x * d.y, 1.0 - d.y * d.y, -d.z * d.y);
    Tangents {
        du: east,
        dv: north,
        n: d,
    }
}

/// The frame of the plane with normal `n`: its texture axes.
pub fn plane_tangents(n: V3) -> Tangents {
    let (du, dv) = plane_axes(n);
    Tangents { du, dv, n }
}

/// The frame of the quad with edges `u`, `v`.
pub fn quad_tangents(u: V3, v: V3) -> Tangents {
    Tangents {
        du: u,
        dv: v,
        n: u.cross(v),
    }
}

/// The frame at `p` on a box between `lo` and `hi`: its nearest face's
/// axes, as `uv.rs` lays each face out.
pub fn box_tangents(lo: V3, hi: V3, p: V3) -> Tangents {
    let (x, y, z) = (
        V3::new(1.0, 0.0, 0.0),
        V3::new(0.0, 1.0, 0.0),
        V3::new(0.0, 0.0, 1.0),
    );
    let (du, dv) = match box_face(lo, hi, p) {
        0 => (z, y),
        1 => (-z, y),
        2 => (x, z),
        3 => (x, -z),
        4 => (-x, y),
        _ => (x, y),
    };
    Tangents {
        du,
        dv,
        n: du.cross(dv),
    }
}

/// The frame of triangle `tri` (the file's order) of `mesh` at
/// barycentric (b1, b2): dP/du and dP/dv solved from its corners'
/// positions and texture coordinates (zero when those are in a line),
/// the normal the file's per-vertex ones interpolated, else the face's
/// by its winding. None when the file has no texture coordinates.
pub fn mesh_tangents(mesh: &Mesh, tri: usize, b1: f64, b2: f64) -> Option<Tangents> {
    let t = mesh.triangles.get(tri)?;
    let uv = |k: usize| mesh.texcoords.get(t[k] as usize).copied();
    let (t0, t1, t2) = (uv(0)?, uv(1)?, uv(2)?);
    let p = |k: usize| mesh.positions.get(t[k] as usize).copied().map(V3::from);
    let (p0, p1, p2) = (p(0)?, p(1)?, p(2)?);
    let (e1, e2) = (p1 - p0, p2 - p0);
    let (a, b) = (
        [t1[0] - t0[0], t1[1] - t0[1]],
        [t2[0] - t0[0], t2[1] - t0[1]],
    );
    let det = a[0] * b[1] - b[0] * a[1];
    let size = (a[0].abs() + a[1].abs()) * (b[0].abs() + b[1].abs());
    let (du, dv) = if det.abs() > 1e-12 * size && det.is_finite() {
        ((e1 * b[1] - e2 * a[1]) / det, (e2 * a[0] - e1 * b[0]) / det)
    } else {
        (V3::new(0.0, 0.0, 0.0), V3::new(0.0, 0.0, 0.0))
    };
    let face = e1.cross(e2);
    let normal = |k: usize| mesh.normals.get(t[k] as usize).copied().map(V3::from);
    let n = match (normal(0), normal(1), normal(2)) {
        (Some(n0), Some(n1), Some(n2)) => {
            let n = n0 * (1.0 - b1 - b2) + n1 * b1 + n2 * b2;
            if n.dot(n) > 0.0 {
                n
            } else {
                face
            }
        }
        _ => face,
    };
    Some(Tangents { du, dv, n })
}

/// The shading normal a normal map's texel `rgb` (linear, in [0, 1])
/// gives at a hit of unit normal `hit_n` (turned towards the ray) in the
/// world frame `t`: 2 rgb - 1 as x T + y B + z N, renormalised; seen
/// from the back, the front's turned round. Every backend that bakes the
/// map itself (the built-in tracer per hit, POV-Ray per mesh vertex)
/// perturbs through this.
pub fn perturbed(hit_n: V3, t: &Tangents, rgb: [f32; 3]) -> V3 {
    let back = hit_n.dot(t.n) < 0.0;
    let n = if back { -hit_n } else { hit_n };
    let (tu, tv) = orthonormal(n, t.du, t.dv);
    let [x, y, z] = rgb.map(|c| 2.0 * c as f64 - 1.0);
    let p = tu * x + tv * y + n * z;
    let len = p.length();
    let p = if len > 1e-12 && len.is_finite() {
        p / len
    } else {
        n
    };
    if back {
        -p
    } else {
        p
    }
}

/// (T, B): dP/du made perpendicular to the unit `n` (Gram-Schmidt), or
/// the plane axes of `n` when it has no such part; B = n x T, turned
/// round when dP/dv points the other way (mirrored coordinates).
fn orthonormal(n: V3, du: V3, dv: V3) -> (V3, V3) {
    let t = du - n * n.dot(du);
    let len = t.length();
    let t = if len > 1e-9 * du.length() && len.is_finite() && len > 0.0 {
        t / len
    } else {
        plane_axes(n).0
    };
    let b = n.cross(t);
    if b.dot(dv) < 0.0 {
        (t, -b)
    } else {
        (t, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::shape::Shape;

    fn shape(json: &str) -> Shape {
        serde_json::from_str(json).unwrap()
    }

    fn parallel(a: V3, b: V3) -> bool {
        a.normalized().dot(b.normalized()) > 1.0 - 1e-9
    }

    /// dP/du and dP/dv are the directions in which uv.rs's coordinates
    /// grow, checked by finite differences on each primitive, and
    /// dP/du x dP/dv points outward.
    #[test]
    fn the_tangents_follow_the_texture_coordinates_and_face_out() {
        let b = r#"{"type":"box","min":[0,0,0],"max":[1,2,4]}"#;
        let shapes = [
            (
                r#"{"type":"sphere","center":[0,1,0],"radius":2}"#,
                V3::new(1.2, 2.0, 1.2),
            ),
            (
                r#"{"type":"plane","point":[0,0,0],"normal":[0,1,0]}"#,
                V3::new(0.3, 0.0, 0.2),
            ),
            (
                r#"{"type":"plane","point":[0,0,0],"normal":[1,1,1]}"#,
                V3::new(0.0, 0.0, 0.0),
            ),
            (
                r#"{"type":"quad","corner":[1,0,0],"edge_u":[2,0,0],"edge_v":[0,0,-3]}"#,
                V3::new(2.0, 0.0, -1.0),
            ),
            (b, V3::new(0.3, 2.0, 1.0)),
            (b, V3::new(1.0, 0.5, 1.0)),
            (b, V3::new(0.5, 0.5, 0.0)),
        ];
        for (json, p) in shapes {
            let s = shape(json);
            let f = s.tangents(p).unwrap();
            let uv = |q: V3| s.uv(q).unwrap();
            let h = 1e-6;
            let (u0, du) = (uv(p), uv(p + f.du.normalized() * h));
            assert!(
                du[0] - u0[0] > 0.0 && (du[1] - u0[1]).abs() < 1e-9,
                "{json}: u"
            );
            let dv = uv(p + f.dv.normalized() * h);
            assert!(
                dv[1] - u0[1] > 0.0 && (dv[0] - u0[0]).abs() < 1e-9,
                "{json}: v"
            );
            assert!(parallel(f.du.cross(f.dv), f.n), "{json}: outward");
        }
    }

    #[test]
    fn a_mesh_triangle_solves_its_tangents_and_a_degenerate_one_has_none() {
        let m = Mesh {
            positions: vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0]],
            normals: vec![],
            texcoords: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            triangles: vec![[0, 1, 2]],
        };
        let f = mesh_tangents(&m, 0, 0.2, 0.3).unwrap();
        assert_eq!(
            (f.du, f.dv),
            (V3::new(2.0, 0.0, 0.0), V3::new(0.0, 3.0, 0.0))
        );
        assert!(parallel(f.n, V3::new(0.0, 0.0, 1.0)));
        let flat = Mesh {
            texcoords: vec![[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]],
            ..m
        };
        let f = mesh_tangents(&flat, 0, 0.2, 0.3).unwrap();
        assert_eq!(f.du, V3::new(0.0, 0.0, 0.0));
        assert!(f.n.z > 0.0);
    }

    fn close(a: V3, b: V3) -> bool {
        (a - b).length() < 1e-6
    }

    fn flat(du: V3, dv: V3) -> Tangents {
        Tangents {
            du,
            dv,
            n: V3::new(0.0, 0.0, 1.0),
        }
    }

    #[test]
    fn a_flat_texel_keeps_the_normal_and_red_and_green_tilt_it_along_u_and_v() {
        let z = V3::new(0.0, 0.0, 1.0);
        let t = flat(V3::new(2.0, 0.0, 0.0), V3::new(0.0, 3.0, 0.0));
        assert!(close(perturbed(z, &t, [0.5, 0.5, 1.0]), z));
        let s = 0.5f64.sqrt();
        // +x in the map is +u (red), +y is +v (green: OpenGL, +Y up)
        assert!(close(perturbed(z, &t, [1.0, 0.5, 1.0]), V3::new(s, 0.0, s)));
        assert!(close(perturbed(z, &t, [0.5, 1.0, 1.0]), V3::new(0.0, s, s)));
        // mirrored v: green tilts towards dP/dv, wherever it points
        let m = flat(V3::new(1.0, 0.0, 0.0), V3::new(0.0, -1.0, 0.0));
        assert!(close(
            perturbed(z, &m, [0.5, 1.0, 1.0]),
            V3::new(0.0, -s, s)
        ));
        // seen from the back, the whole normal turns round
        assert!(close(
            perturbed(-z, &t, [1.0, 0.5, 1.0]),
            V3::new(-s, 0.0, -s)
        ));
    }

    #[test]
    fn a_degenerate_frame_or_texel_gives_a_unit_normal_not_nan() {
        let z = V3::new(0.0, 0.0, 1.0);
        let zero = V3::new(0.0, 0.0, 0.0);
        for t in [
            flat(zero, zero),
            flat(z, z),
            flat(V3::new(f64::NAN, 0.0, 0.0), zero),
        ] {
            for rgb in [[0.5, 0.5, 0.5], [1.0, 0.0, 1.0], [0.3, 0.8, 0.9]] {
                let n = perturbed(z, &t, rgb);
                assert!((n.length() - 1.0).abs() < 1e-9, "{t:?} {rgb:?}: {n:?}");
            }
        }
    }
}
