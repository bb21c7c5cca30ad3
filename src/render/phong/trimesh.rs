//! A mesh shape as the tracer sees it: its triangles in the file's frame
//! under a BVH (`bvh.rs`), built once per process and mesh file and shared
//! by every candidate, and a placement (the object's transform) that
//! carries rays into that frame and normals out of it — so that a free
//! pose costs no rebuild.

use super::accel::{Aabb, FaceHit, TriPoint, EPS};
use super::bvh::Bvh;
use super::hull_faces::HullFaces;
use super::inner_ball::{self, Ball};
use crate::math::V3;
use crate::scene::mesh::{self, Mesh};
use crate::scene::transform::Affine;
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::Path;
use std::sync::{Arc, Mutex, OnceLock};

/// A triangle as a corner and two edges (Möller–Trumbore's form).
#[derive(Clone, Copy, Debug)]
struct Tri {
    v0: V3,
    e1: V3,
    e2: V3,
}

impl Tri {
    /// Distance and barycentric (u, v) of the hit within (EPS, t_max).
    #[inline(always)]
    fn hit(&self, o: V3, d: V3, t_max: f64) -> Option<(f64, f64, f64)> {
        let p = d.cross(self.e2);
        let det = self.e1.dot(p);
        if det == 0.0 {
            return None;
        }
        let inv = 1.0 / det;
        let s = o - self.v0;
        let u = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let q = s.cross(self.e1);
        let v = d.dot(q) * inv;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        let t = self.e2.dot(q) * inv;
        (t > EPS && t < t_max).then_some((t, u, v))
    }
}

/// A mesh's triangles, in BVH order, with their vertex normals if any.
#[derive(Debug)]
pub struct TriMesh {
    tris: Vec<Tri>,
    normals: Vec<[V3; 3]>,
    bvh: Bvh,
    pub bounds: Aabb,
    /// A sphere holding every vertex: centre and radius.
    sphere: (V3, f64),
    /// For a closed mesh, a ball inside it (`inner_ball.rs`).
    ball: Option<Ball>,
    /// Which triangles lie on the convex hull (`hull_faces.rs`).
    hull: HullFaces,
    /// The BVH position of each triangle as numbered in the file.
    position: Vec<u32>,
}

impl TriMesh {
    pub fn new(m: &Mesh) -> TriMesh {
        let p = |i: u32| V3::from(m.positions[i as usize]);
        let bvh = Bvh::build(&boxes(m));
        let tri = |t: &[u32; 3]| Tri {
            v0: p(t[0]),
            e1: p(t[1]) - p(t[0]),
            e2: p(t[2]) - p(t[0]),
        };
        // gathers of a million triangles each: on the pool's threads
        let sorted = || bvh.order.par_iter().map(|&i| &m.triangles[i as usize]);
        let tris = sorted().map(tri).collect();
        let normals = if m.normals.is_empty() {
            Vec::new()
        } else {
            sorted()
                .map(|t| t.map(|i| V3::from(m.normals[i as usize])))
                .collect()
        };
        let (lo, hi) = m.bounds();
        let centre = (V3::from(lo) + V3::from(hi)) * 0.5;
        let radius = m
            .positions
            .iter()
            .map(|&v| (V3::from(v) - centre).length())
            .fold(0.0, f64::max);
        let mut position = vec![0u32; bvh.order.len()];
        for (k, &i) in bvh.order.iter().enumerate() {
            position[i as usize] = k as u32;
        }
        let mut t = TriMesh {
            hull: HullFaces::new(bvh.order.len(), centre, radius),
            position,
            tris,
            normals,
            bvh,
            bounds: Aabb {
                lo: V3::from(lo),
                hi: V3::from(hi),
            },
            sphere: (centre, radius),
            ball: None,
        };
        let bounds = (t.bounds.lo, t.bounds.hi);
        t.ball = inner_ball::find(
            &m.positions,
            &m.triangles,
            bounds,
            |o, d| t.crossings(o, d),
            |c| t.distance(c),
        );
        t
    }

    /// True when the mesh is closed and holds an inner ball.
    pub fn has_inner_ball(&self) -> bool {
        self.ball.is_some()
    }

    /// The distance from `c` to the nearest triangle, through the BVH.
    fn distance(&self, c: V3) -> f64 {
        self.bvh.nearest_to(c, |k| {
            let t = &self.tris[k];
            inner_ball::triangle_distance(c, t.v0, t.v0 + t.e1, t.v0 + t.e2)
        })
    }

    /// The number of triangles the ray o + t d meets (t > EPS).
    fn crossings(&self, o: V3, d: V3) -> usize {
        let mut n = 0;
        self.bvh.any(o, d, f64::INFINITY, |k| {
            n += self.tris[k].hit(o, d, f64::INFINITY).is_some() as usize;
            false
        });
        n
    }

    /// True when the ray starts outside the bounding sphere by more than
    /// rounding error and EPS along it: it is then outside the mesh, and
    /// any crossing of the surface lies at t > EPS.
    #[inline]
    fn starts_outside(&self, o: V3, d: V3) -> bool {
        let (c, r) = self.sphere;
        let margin = 2.0 * EPS * d.length() + 1e-9 * (1.0 + r + c.length());
        (o - c).length() > r + margin
    }

    /// True when some vertex x has x . m > thr: the mesh reaches above
    /// that plane. Boxes wholly below it are skipped, so near a convex
    /// part only the few leaves the plane cuts are read.
    pub fn reaches_above(&self, m: V3, thr: f64) -> bool {
        let m = m.to_array();
        let top = |lo: &[f64; 3], hi: &[f64; 3]| -> f64 {
            (0..3).map(|a| (m[a] * lo[a]).max(m[a] * hi[a])).sum()
        };
        let m = V3::from(m);
        self.bvh.any_box(
            |lo, hi| top(lo, hi) > thr,
            |k| {
                let t = &self.tris[k];
                [t.v0, t.v0 + t.e1, t.v0 + t.e2]
                    .iter()
                    .any(|v| v.dot(m) > thr)
            },
        )
    }

    /// True when the ray from `o` along `d` (a point on triangle `tri`,
    /// numbered as in the file, and just off it) leaves the mesh outwards
    /// through a face on its convex hull, and so meets no triangle
    /// (`hull_faces.rs`).
    #[inline]
    pub fn leaves_outward(&self, tri: u32, o: V3, d: V3) -> bool {
        let Some(&k) = self.position.get(tri as usize) else {
            return false;
        };
        let t = &self.tris[k as usize];
        let plane = (t.v0, t.e1.cross(t.e2));
        self.hull
            .leaves(k as usize, plane, o, d, |m, thr| self.reaches_above(m, thr))
    }

    /// The nearest hit: distance, the shading normal (not unit): the
    /// vertex normals interpolated, or the face normal, on the side of the
    /// face the ray meets, so that the tracer's front and back agree with
    /// the geometry; the face normal (not unit); and the triangle and
    /// barycentrics the walk found it at (what a texture is looked up by).
    #[inline]
    pub fn hit(&self, o: V3, d: V3, t_max: f64) -> Option<(f64, V3, V3, TriPoint)> {
        let mut uv = (0.0, 0.0);
        let (k, t) = self.bvh.nearest(o, d, t_max, |k, tb| {
            let (t, u, v) = self.tris[k].hit(o, d, tb)?;
            uv = (u, v);
            Some(t)
        })?;
        // uv is the last accepted hit's, which is the nearest
        let (u, v) = uv;
        let at = TriPoint {
            tri: self.bvh.order[k],
            u,
            v,
        };
        let tri = &self.tris[k];
        let ng = tri.e1.cross(tri.e2);
        let Some(n) = self.normals.get(k) else {
            return Some((t, ng, ng, at));
        };
        let ns = n[0] * (1.0 - u - v) + n[1] * u + n[2] * v;
        let ns = if ns.dot(ng) < 0.0 { -ns } else { ns };
        // a shading normal turned past the ray (or zero) would flip the
        // side the tracer shades: keep the face's there
        let same_side = (ns.dot(d) < 0.0) == (ng.dot(d) < 0.0) && ns.dot(ns) > 0.0;
        Some((t, if same_side { ns } else { ng }, ng, at))
    }

    /// True when any triangle is hit within (EPS, t_max). A ray from
    /// outside that reaches the inner ball crosses the surface before it
    /// (`inner_ball.rs`): blocked without a walk.
    #[inline]
    pub fn any(&self, o: V3, d: V3, t_max: f64) -> bool {
        if let Some(ball) = &self.ball {
            if inner_ball::reaches(ball, o, d, t_max) && self.starts_outside(o, d) {
                return true;
            }
        }
        self.bvh
            .any(o, d, t_max, |k| self.tris[k].hit(o, d, t_max).is_some())
    }
}

/// Each triangle's bounding box, as numbered in the file.
pub fn boxes(m: &Mesh) -> Vec<Aabb> {
    let p = |i: u32| V3::from(m.positions[i as usize]);
    m.triangles
        .iter()
        .map(|t| {
            let b = Aabb {
                lo: p(t[0]),
                hi: p(t[0]),
            };
            let b = Aabb::hull(p(t[1]), b.lo, b.hi);
            Aabb::hull(p(t[2]), b.lo, b.hi)
        })
        .collect()
}

type Cache = Mutex<HashMap<String, Arc<TriMesh>>>;

/// The traced form of the mesh file `path`, built once per process.
pub fn get(path: &str) -> crate::error::Result<Arc<TriMesh>> {
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    if let Some(t) = cache.lock().expect("mesh cache").get(path) {
        return Ok(t.clone());
    }
    let t = Arc::new(TriMesh::new(&*mesh::get(Path::new(path))?));
    cache
        .lock()
        .expect("mesh cache")
        .insert(path.to_string(), t.clone());
    Ok(t)
}

/// A mesh placed in the scene: world rays go into the mesh's frame by
/// the inverse of the object's transform (distances along them kept, as
/// the direction is not renormalised), normals come out by the transform.
#[derive(Debug)]
pub struct Placed {
    pub mesh: Arc<TriMesh>,
    place: Place,
    pub bounds: Aabb,
    /// A world sphere holding the placed mesh, grown far beyond rounding
    /// error: centre and squared radius (`may_meet`).
    reach: (V3, f64),
}

#[derive(Debug)]
enum Place {
    AsRead,
    Moved(Box<(Affine, Inverse)>),
    /// A transform that flattens the mesh (a zero scale): nothing to hit.
    Flat,
}

/// x -> m (x - t): the inverse of an affine map.
#[derive(Clone, Copy, Debug)]
struct Inverse {
    m: [V3; 3],
    t: V3,
}

impl Inverse {
    fn of(a: &Affine) -> Option<Inverse> {
        let axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let c = axes.map(|e| a.vector(V3::from(e)));
        // rows of the inverse: the cross products of the columns over the determinant
        let det = c[0].dot(c[1].cross(c[2]));
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let m = [
            c[1].cross(c[2]) / det,
            c[2].cross(c[0]) / det,
            c[0].cross(c[1]) / det,
        ];
        Some(Inverse {
            m,
            t: a.point(V3::new(0.0, 0.0, 0.0)),
        })
    }

    fn vector(&self, v: V3) -> V3 {
        V3::new(self.m[0].dot(v), self.m[1].dot(v), self.m[2].dot(v))
    }
}

impl Placed {
    pub fn new(mesh: Arc<TriMesh>, a: Option<&Affine>) -> Placed {
        let place = match a {
            None => Place::AsRead,
            Some(a) => Inverse::of(a).map_or(Place::Flat, |inv| Place::Moved(Box::new((*a, inv)))),
        };
        let bounds = match &place {
            Place::AsRead | Place::Flat => mesh.bounds,
            Place::Moved(m) => {
                let a = &m.0;
                let c = mesh.bounds.corners().map(|k| a.point(k));
                c.iter().fold(Aabb { lo: c[0], hi: c[0] }, |b, &k| {
                    Aabb::hull(k, b.lo, b.hi)
                })
            }
        };
        let mut placed = Placed {
            mesh,
            place,
            bounds,
            reach: (V3::new(0.0, 0.0, 0.0), 0.0),
        };
        let (c, r) = placed.sphere();
        let r = r * (1.0 + 1e-6) + 1e-9 * (1.0 + c.length());
        placed.reach = (c, r * r);
        placed
    }

    /// False when the ray o + t d certainly meets no triangle within
    /// (0, t_max): it misses the grown bounding sphere there. Asked
    /// before the ray is carried into the mesh's frame, so that the many
    /// rays that pass a small mesh by cost one sphere test. A ray that
    /// starts a million radii away is not ruled out: its transformed
    /// start may be rounded by more than the sphere was grown.
    #[inline(always)]
    fn may_meet(&self, o: V3, d: V3, t_max: f64) -> bool {
        let (c, r2) = self.reach;
        let oc = o - c;
        let (a, b, cc) = (d.dot(d), oc.dot(d), oc.dot(oc));
        if cc > 1e12 * r2 {
            return true;
        }
        let disc = b * b - a * (cc - r2);
        if disc < 0.0 {
            return false;
        }
        // the roots are (-b -+ sq) / a, a > 0
        let sq = disc.sqrt();
        -b + sq >= 0.0 && -b - sq <= t_max * a
    }

    /// The ray in the mesh's frame; `None` when there is nothing to hit.
    #[inline]
    fn local(&self, o: V3, d: V3) -> Option<(V3, V3)> {
        match &self.place {
            Place::AsRead => Some((o, d)),
            Place::Moved(m) => Some((m.1.vector(o - m.1.t), m.1.vector(d))),
            Place::Flat => None,
        }
    }

    /// The nearest hit: distance, unit shading normal, unit face normal
    /// and where on the mesh.
    #[inline]
    pub fn hit(&self, o: V3, d: V3, t_max: f64) -> Option<FaceHit> {
        if !self.may_meet(o, d, t_max) {
            return None;
        }
        let (ol, dl) = self.local(o, d)?;
        let (t, n, ng, at) = self.mesh.hit(ol, dl, t_max)?;
        let (n, ng) = match &self.place {
            Place::Moved(m) => (m.0.normal(n), m.0.normal(ng)),
            _ => (n, ng),
        };
        Some(FaceHit {
            t,
            n: n.normalized(),
            face: ng.normalized(),
            tri: Some(at),
        })
    }

    /// A sphere holding the placed mesh: centre and radius. The transform
    /// is a rotation of a scale (`Affine`), whose largest stretch is its
    /// longest column.
    pub fn sphere(&self) -> (V3, f64) {
        let (c, r) = self.mesh.sphere;
        match &self.place {
            Place::AsRead | Place::Flat => (c, r),
            Place::Moved(m) => {
                let axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
                let stretch = axes
                    .iter()
                    .map(|&e| m.0.vector(V3::from(e)).length())
                    .fold(0.0, f64::max);
                (m.0.point(c), r * stretch)
            }
        }
    }

    /// True when some point of the placed mesh has x . m > thr (world).
    pub fn reaches_above(&self, m: V3, thr: f64) -> bool {
        match &self.place {
            Place::AsRead => self.mesh.reaches_above(m, thr),
            Place::Flat => false,
            // world x = A v + b: x . m = v . (A^T m) + b . m
            Place::Moved(p) => {
                let a = &p.0;
                let axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
                let [x, y, z] = axes.map(|e| a.vector(V3::from(e)).dot(m));
                let b = a.point(V3::new(0.0, 0.0, 0.0));
                self.mesh.reaches_above(V3::new(x, y, z), thr - b.dot(m))
            }
        }
    }

    #[inline]
    pub fn any(&self, o: V3, d: V3, t_max: f64) -> bool {
        self.may_meet(o, d, t_max)
            && self
                .local(o, d)
                .is_some_and(|(ol, dl)| self.mesh.any(ol, dl, t_max))
    }

    /// True when the ray from `o` along `d`, which starts just off
    /// triangle `tri` of this mesh, leaves it outwards through a face on
    /// its convex hull: it then meets none of the mesh's triangles.
    #[inline]
    pub fn leaves_outward(&self, tri: u32, o: V3, d: V3) -> bool {
        self.local(o, d)
            .is_some_and(|(ol, dl)| self.mesh.leaves_outward(tri, ol, dl))
    }
}

#[cfg(test)]
/// The twelve triangles of a closed box whose corner k has coordinate
/// a at +1 when bit a of k is set (outward winding).
pub(super) fn cube_triangles() -> Vec<[u32; 3]> {
    let mut t = Vec::new();
    for f in [
        [0, 1, 3, 2],
        [4, 6, 7, 5],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 5, 7, 3],
    ] {
        t.push([f[0], f[1], f[2]]);
        t.push([f[0], f[2], f[3]]);
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed box of twelve triangles, stretched, as a mesh.
    fn cube() -> Mesh {
        let positions = (0..8)
            .map(|k| {
                [0, 1, 2].map(|a| (if k >> a & 1 == 0 { -1.0 } else { 1.0 }) * [1.0, 0.6, 0.3][a])
            })
            .collect();
        let triangles = cube_triangles();
        Mesh {
            positions,
            normals: Vec::new(),
            texcoords: Vec::new(),
            triangles,
        }
    }

    /// The BVH's nearest-triangle walk finds what a pass over every
    /// triangle finds, from points inside, among and far from a soup of
    /// 3,000 small triangles (a tree many levels deep).
    #[test]
    fn the_nearest_triangle_through_the_tree_is_the_nearest_of_all() {
        let w = |f: f64| (f.sin() * 43758.5453).fract();
        let mut positions = Vec::new();
        for i in 0..9000 {
            let f = i as f64;
            let centre = [w(f * 1.1), w(f * 2.3 + 0.5), w(f * 3.7 + 0.2)].map(|x| x * 4.0);
            let k = (i / 3) as f64;
            let corner = [w(k * 1.9), w(k * 0.7 + 0.3), w(k * 5.1)].map(|x| x * 4.0);
            positions.push([0, 1, 2].map(|a| corner[a] + 0.05 * centre[a]));
        }
        let triangles = (0..3000).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
        let m = Mesh {
            positions,
            normals: Vec::new(),
            texcoords: Vec::new(),
            triangles,
        };
        let t = TriMesh::new(&m);
        for i in 0..300 {
            let f = i as f64 + 0.5;
            let c = V3::new(w(f * 0.31), w(f * 0.77), w(f * 1.13)) * 12.0 - V3::new(4.0, 4.0, 4.0);
            let all = m.triangles.iter().fold(f64::INFINITY, |best, tri| {
                let [a, b, d] = tri.map(|v| V3::from(m.positions[v as usize]));
                best.min(inner_ball::triangle_distance(c, a, b, d))
            });
            let walk = t.distance(c);
            assert!(
                (walk - all).abs() <= 1e-9 * (1.0 + all),
                "point {i}: {walk} against {all}"
            );
        }
    }

    /// The inner ball's shortcut answers every shadow ray as the walk
    /// does: from points outside, inside and on the box, towards ends
    /// inside, outside and beyond it; and it does answer many of them.
    #[test]
    fn the_inner_ball_blocks_exactly_what_the_walk_blocks() {
        let t = TriMesh::new(&cube());
        let ball = t.ball.expect("a closed box holds a ball");
        assert!(ball.r > 0.29 && ball.r < 0.3, "{ball:?}");
        let walk = |o: V3, d: V3, t_max: f64| {
            t.bvh
                .any(o, d, t_max, |k| t.tris[k].hit(o, d, t_max).is_some())
        };
        let mut short = 0;
        for i in 0..2000 {
            let f = i as f64;
            let s = 0.3 + 2.0 * ((f * 0.37).sin() * 0.5 + 0.5);
            let o = V3::new((f * 1.3).sin(), (f * 0.7).cos(), (f * 0.11).sin()) * s;
            let to = V3::new((f * 0.53).cos(), (f * 0.91).sin(), (f * 0.29).cos()) * 0.4;
            let d = (to - o).normalized();
            for t_max in [0.2, (to - o).length(), 1e9] {
                let shortcut = inner_ball::reaches(&ball, o, d, t_max) && t.starts_outside(o, d);
                short += shortcut as usize;
                assert_eq!(t.any(o, d, t_max), walk(o, d, t_max), "ray {i} {t_max}");
            }
        }
        assert!(short > 500, "{short}");
    }

    /// Two boxes side by side (one mesh, not convex): a shadow ray that
    /// the hull test rules out, from just off any triangle in any
    /// direction, meets no triangle on the walk; the test rules out many
    /// rays, and none from the faces that look at the other box.
    #[test]
    fn a_ray_leaving_a_hull_face_meets_nothing() {
        let mut m = cube();
        let n = m.positions.len() as u32;
        let far: Vec<[f64; 3]> = m
            .positions
            .iter()
            .map(|p| [p[0] + 3.0, p[1], p[2]])
            .collect();
        m.positions.extend(far);
        let more: Vec<[u32; 3]> = m.triangles.iter().map(|t| t.map(|i| i + n)).collect();
        m.triangles.extend(more);
        let t = TriMesh::new(&m);
        let (mut clear, mut facing) = (0, 0);
        for (i, tri) in m.triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|k| V3::from(m.positions[k as usize]));
            // away from the box's centre, whichever way the triangle winds
            let centre = V3::new(if i < 12 { 0.0 } else { 3.0 }, 0.0, 0.0);
            let out = (b - a).cross(c - a).normalized();
            let out = if out.dot(a - centre) < 0.0 { -out } else { out };
            for (w, off) in [(0.2, 1e-6), (0.45, 1e-6), (0.3, -1e-6)] {
                let p = a * (1.0 - 2.0 * w) + b * w + c * w + out * off;
                for k in 0..100 {
                    let z = 1.0 - (k as f64 + 0.5) / 50.0;
                    let r = (1.0 - z * z).sqrt();
                    let d = V3::new(r * (k as f64 * 2.4).cos(), z, r * (k as f64 * 2.4).sin());
                    if t.leaves_outward(i as u32, p, d) {
                        assert!(!t.any(p, d, 1e9), "triangle {i} {p:?} {d:?}");
                        clear += 1;
                        // the first box's +x faces look at the second box
                        facing += (i < 12 && out.x > 0.5) as usize;
                    }
                }
            }
        }
        assert!(clear > 2000, "{clear}");
        assert_eq!(facing, 0);
    }
}
