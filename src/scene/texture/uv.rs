//! Texture coordinates (u, v) of a surface point, in the object's own
//! frame (the shape as written, before its `transform`), so that a map
//! moves with its object. Every backend follows these exactly
//! (docs/scene-format.md, "Textures"):
//!
//! - quad: (s, t) of corner + s edge_u + t edge_v, each in [0, 1];
//! - plane: metres from `point` along e_u and e_v, where e_u = the unit
//!   y x n, or the unit part of x across n when n is within 2.6 degrees
//!   of ±y (|n_y| > 0.999), and e_v = n x e_u (a floor: u along +x,
//!   v along -z; a wall facing +z: u along +x, v along +y);
//! - sphere: longitude and latitude about +y: u = atan2(-d_z, d_x) / 2 pi
//!   (in [0, 1)), v = 1/2 + asin(d_y) / pi, d the unit direction from the
//!   centre (v = 1 at the +y pole);
//! - box: each face its own [0, 1]^2, upright and unmirrored seen from
//!   outside: +z face u along +x, -z face -x, +x face -z, -x face +z,
//!   all with v along +y; top (+y) u along +x, v along -z; bottom (-y) u
//!   along +x, v along +z;
//! - mesh: the file's per-vertex texture coordinates, interpolated by the
//!   barycentric coordinates of the point in its triangle.
//!
//! The map's `scale` then multiplies u and v. Each shape picks its own
//! rule in `Shape::uv` (`scene/shape.rs`), beside its other arms.

use crate::math::V3;
use crate::scene::mesh::Mesh;

/// A plane's texture axes (e_u, e_v) for its normal `n` (any length).
pub fn plane_axes(n: V3) -> (V3, V3) {
    let n = n.normalized();
    let eu = if n.y.abs() > 0.999 {
        let x = V3::new(1.0, 0.0, 0.0);
        (x - n * n.dot(x)).normalized()
    } else {
        V3::new(0.0, 1.0, 0.0).cross(n).normalized()
    };
    (eu, n.cross(eu))
}

/// (u, v) of the point `p` on a sphere about `center`: longitude and
/// latitude about +y.
pub fn sphere_uv(center: V3, p: V3) -> [f64; 2] {
    let d = (p - center).normalized();
    let u = (-d.z).atan2(d.x) / (2.0 * std::f64::consts::PI);
    [
        u.rem_euclid(1.0),
        0.5 + d.y.clamp(-1.0, 1.0).asin() / std::f64::consts::PI,
    ]
}

/// (u, v) of the point `p` on the plane through `point` with normal `n`:
/// metres along its axes ([`plane_axes`]).
pub fn plane_uv(point: V3, n: V3, p: V3) -> [f64; 2] {
    let (eu, ev) = plane_axes(n);
    let q = p - point;
    [q.dot(eu), q.dot(ev)]
}

/// (u, v) of the point `p` on the quad corner + s u + t v: (s, t).
pub fn quad_uv(corner: V3, u: V3, v: V3, p: V3) -> [f64; 2] {
    let c = u.cross(v);
    let w = c / c.dot(c);
    let q = p - corner;
    [w.dot(q.cross(v)), w.dot(u.cross(q))]
}

/// (u, v) on the face of a box nearest `p`.
pub fn box_uv(lo: V3, hi: V3, p: V3) -> [f64; 2] {
    let d = hi - lo;
    let f = |a: usize| (p.get(a) - lo.get(a)) / d.get(a); // 0 at min, 1 at max
    let (x, y, z) = (f(0), f(1), f(2));
    match box_face(lo, hi, p) {
        0 => [z, y],       // -x: u along +z
        1 => [1.0 - z, y], // +x: u along -z
        2 => [x, z],       // -y: v along +z
        3 => [x, 1.0 - z], // +y: v along -z
        4 => [1.0 - x, y], // -z: u along -x
        _ => [x, y],       // +z
    }
}

/// A box's six faces as quads (corner, edge_u, edge_v) laid out as
/// `box_uv` lays each face, in `box_face`'s order: a backend whose box has
/// no per-face coordinates of its own draws a mapped box as these.
pub fn box_faces(lo: V3, hi: V3) -> [(V3, V3, V3); 6] {
    let d = hi - lo;
    let (x, y, z) = (
        V3::new(d.x, 0.0, 0.0),
        V3::new(0.0, d.y, 0.0),
        V3::new(0.0, 0.0, d.z),
    );
    let at = |a: f64, b: f64, c: f64| V3::new(a, b, c);
    [
        (lo, z, y),                    // -x: u along +z
        (at(hi.x, lo.y, hi.z), -z, y), // +x: u along -z
        (lo, x, z),                    // -y: v along +z
        (at(lo.x, hi.y, hi.z), x, -z), // +y: v along -z
        (at(hi.x, lo.y, lo.z), -x, y), // -z: u along -x
        (at(lo.x, lo.y, hi.z), x, y),  // +z
    ]
}

/// The face of a box whose plane is nearest `p`, in metres: 0 -x, 1 +x,
/// 2 -y, 3 +y, 4 -z, 5 +z.
pub fn box_face(lo: V3, hi: V3, p: V3) -> usize {
    let gaps = [
        (p.x - lo.x).abs(),
        (hi.x - p.x).abs(),
        (p.y - lo.y).abs(),
        (hi.y - p.y).abs(),
        (p.z - lo.z).abs(),
        (hi.z - p.z).abs(),
    ];
    (0..6)
        .min_by(|&a, &b| gaps[a].total_cmp(&gaps[b]))
        .unwrap_or(5)
}

/// (u, v) at barycentric (b1, b2) of triangle `tri` (the file's order) of
/// `mesh`: (1 - b1 - b2) t0 + b1 t1 + b2 t2; None when the file has no
/// texture coordinates.
pub fn mesh_uv(mesh: &Mesh, tri: usize, b1: f64, b2: f64) -> Option<[f64; 2]> {
    let t = mesh.triangles.get(tri)?;
    let c = |k: usize| mesh.texcoords.get(t[k] as usize).copied();
    let (t0, t1, t2) = (c(0)?, c(1)?, c(2)?);
    let b0 = 1.0 - b1 - b2;
    Some([
        b0 * t0[0] + b1 * t1[0] + b2 * t2[0],
        b0 * t0[1] + b1 * t1[1] + b2 * t2[1],
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::shape::Shape;

    fn shape(json: &str) -> Shape {
        serde_json::from_str(json).unwrap()
    }

    fn close(a: [f64; 2], b: [f64; 2]) -> bool {
        (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12
    }

    #[test]
    fn a_box_face_as_a_quad_has_the_box_coordinates_and_tangents() {
        let (lo, hi) = (V3::new(-1.0, 0.5, -3.0), V3::new(2.0, 1.5, -1.0));
        for (k, (c, eu, ev)) in box_faces(lo, hi).into_iter().enumerate() {
            // outward, as the box's face
            let centre = c + (eu + ev) * 0.5;
            let n = eu.cross(ev);
            assert!(
                n.dot(centre - (lo + hi) * 0.5) > 0.0,
                "face {k} faces inward"
            );
            for (s, t) in [(0.1, 0.2), (0.5, 0.5), (0.9, 0.7), (0.3, 0.95)] {
                let p = c + eu * s + ev * t;
                assert_eq!(box_face(lo, hi, p), k, "face {k} at ({s}, {t})");
                assert!(close(box_uv(lo, hi, p), [s, t]), "face {k} at ({s}, {t})");
                let tb = super::super::tangent::box_tangents(lo, hi, p);
                assert!(
                    (tb.du.normalized() - eu.normalized()).length() < 1e-12,
                    "face {k}"
                );
                assert!(
                    (tb.dv.normalized() - ev.normalized()).length() < 1e-12,
                    "face {k}"
                );
            }
        }
    }

    #[test]
    fn a_quad_maps_its_corners_to_the_unit_square() {
        let q = shape(r#"{"type":"quad","corner":[1,0,0],"edge_u":[2,0,0],"edge_v":[0,0,-3]}"#);
        let at = |x, y, z| q.uv(V3::new(x, y, z)).unwrap();
        assert!(close(at(1.0, 0.0, 0.0), [0.0, 0.0]));
        assert!(close(at(3.0, 0.0, 0.0), [1.0, 0.0]));
        assert!(close(at(2.0, 0.0, -1.5), [0.5, 0.5]));
    }

    #[test]
    fn a_floor_runs_u_along_x_and_v_away_from_a_camera_on_z_and_a_wall_upright() {
        let floor = shape(r#"{"type":"plane","point":[0,0,0],"normal":[0,1,0]}"#);
        let uv = floor.uv(V3::new(0.5, 0.0, -2.0)).unwrap();
        assert!(close(uv, [0.5, 2.0]), "{uv:?}");
        let wall = shape(r#"{"type":"plane","point":[0,0,-1],"normal":[0,0,1]}"#);
        let uv = wall.uv(V3::new(0.5, 0.25, -1.0)).unwrap();
        assert!(close(uv, [0.5, 0.25]), "{uv:?}");
    }

    #[test]
    fn a_sphere_has_its_seam_at_plus_x_and_its_top_at_v_1() {
        let s = shape(r#"{"type":"sphere","center":[0,1,0],"radius":2}"#);
        let at = |x, y, z| s.uv(V3::new(x, y, z)).unwrap();
        assert!(close(at(0.0, 1.0, 2.0), [0.75, 0.5])); // facing +z
        assert!(close(at(0.0, 1.0, -2.0), [0.25, 0.5]));
        assert!((at(0.0, 3.0, 0.0)[1] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn every_box_face_is_upright_seen_from_outside() {
        let b = shape(r#"{"type":"box","min":[0,0,0],"max":[1,2,4]}"#);
        let at = |x, y, z| b.uv(V3::new(x, y, z)).unwrap();
        // from outside each side face, u grows to the right, v upwards
        assert!(close(at(0.25, 0.5, 4.0), [0.25, 0.25])); // +z, right is +x
        assert!(close(at(0.25, 0.5, 0.0), [0.75, 0.25])); // -z, right is -x
        assert!(close(at(1.0, 0.5, 1.0), [0.75, 0.25])); // +x, right is -z
        assert!(close(at(0.0, 0.5, 1.0), [0.25, 0.25])); // -x, right is +z
        assert!(close(at(0.25, 2.0, 1.0), [0.25, 0.75])); // top, up is -z
        assert!(close(at(0.25, 0.0, 1.0), [0.25, 0.25])); // bottom, up is +z
    }

    #[test]
    fn a_mesh_point_interpolates_its_vertices_coordinates() {
        let m = Mesh {
            positions: vec![[0.0; 3]; 3],
            normals: vec![],
            texcoords: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            triangles: vec![[0, 1, 2]],
        };
        assert!(close(mesh_uv(&m, 0, 0.25, 0.5).unwrap(), [0.25, 0.5]));
        let bare = Mesh {
            texcoords: vec![],
            ..m
        };
        assert!(mesh_uv(&bare, 0, 0.25, 0.5).is_none());
    }
}
