//! The built-in tracer's primitives, made from the scene's shapes: spheres,
//! infinite planes and parallelograms (quads); a box is six quads. Every
//! primitive remembers the scene object it belongs to. How a ray meets
//! each is its `Intersect` implementation; which ones a ray is tested
//! against is the `Accel`'s business (`accel.rs`).

pub use super::accel::Intersect;
pub use super::accel::TriPoint;
use super::accel::{Aabb, Accel, FaceHit};
use super::camera::CameraRays;
use super::trimesh::{self, Placed};
use crate::math::V3;
use crate::scene::transform::Affine;
use crate::scene::{Scene, Shape};
use std::ops::Range;
use std::sync::Arc;

/// An axis-aligned rectangle of image points, in pixels.
#[derive(Clone, Copy, Debug)]
pub struct Rect {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
}

impl Rect {
    const EMPTY: Rect = Rect {
        x0: f64::INFINITY,
        x1: f64::NEG_INFINITY,
        y0: f64::INFINITY,
        y1: f64::NEG_INFINITY,
    };

    /// Grown to hold (x, y), with a margin far above rounding error.
    fn with(self, x: f64, y: f64) -> Rect {
        const MARGIN: f64 = 1e-3;
        Rect {
            x0: self.x0.min(x - MARGIN),
            x1: self.x1.max(x + MARGIN),
            y0: self.y0.min(y - MARGIN),
            y1: self.y1.max(y + MARGIN),
        }
    }

    #[inline]
    fn contains(&self, x: f64, y: f64) -> bool {
        x >= self.x0 && x <= self.x1 && y >= self.y0 && y <= self.y1
    }
}

pub use super::accel::EPS;

#[derive(Clone, Debug)]
pub enum Prim {
    Sphere {
        c: V3,
        r2: f64,
    },
    Plane {
        p: V3,
        n: V3,
    },
    /// Corner `o`, edges `u`, `v`, unit normal `n`; `w` = (u x v)/|u x v|^2
    /// turns a point into its (alpha, beta) coordinates on the quad.
    Quad {
        o: V3,
        u: V3,
        v: V3,
        n: V3,
        w: V3,
    },
    /// A triangle mesh under its own BVH (`trimesh.rs`); the one shape
    /// that is not convex, so it may shadow itself.
    Mesh(Arc<Placed>),
}

impl Prim {
    /// True when no point of the primitive can shadow another of it.
    pub fn convex(&self) -> bool {
        !matches!(self, Prim::Mesh(_))
    }
}

/// A ray hit: distance along the ray, normal (unit, not yet turned
/// towards the ray: on a mesh the shading one), the face's own normal
/// (unit, the same but on a mesh), the object hit and, on a mesh, the
/// triangle and barycentrics where.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub t: f64,
    pub n: V3,
    pub face: V3,
    pub object: u32,
    pub tri: Option<TriPoint>,
}

/// A primitive that may block light from a given point.
#[derive(Clone, Copy, Debug)]
pub enum Occluder {
    /// A sphere, as the cone of directions it covers from the point.
    Cone {
        axis: V3,
        cos_max: f64,
        center_dist: f64,
        prim: u32,
    },
    /// A mesh, with two tests that rule most rays out before its BVH is
    /// walked: the cone of directions its bounding sphere covers from the
    /// point (`cos_max` below -1 when the point is inside it), and a plane
    /// the whole mesh lies below (`m` . x <= `thr`; `m` zero when there is
    /// none): a ray starting above it and not heading down misses the mesh.
    Mesh {
        axis: V3,
        cos_max: f64,
        m: V3,
        thr: f64,
        prim: u32,
    },
    Prim(u32),
}

/// The scene's surfaces.
pub struct Geometry {
    pub prims: Vec<Prim>,
    pub owner: Vec<u32>,
    accel: Accel,
}

impl Geometry {
    pub fn new(scene: &Scene) -> Geometry {
        let mut prims = Vec::new();
        let mut owner = Vec::new();
        for (i, obj) in scene.objects.iter().enumerate() {
            let first = prims.len();
            let mut add = |p: Prim| {
                prims.push(p);
                owner.push(i as u32);
            };
            match obj.shape {
                Shape::Sphere { center, radius } => add(Prim::Sphere {
                    c: V3::from(center),
                    r2: radius * radius,
                }),
                Shape::Plane { point, normal } => add(Prim::Plane {
                    p: V3::from(point),
                    n: V3::from(normal).normalized(),
                }),
                Shape::Quad {
                    corner,
                    edge_u,
                    edge_v,
                } => add(quad(V3::from(corner), V3::from(edge_u), V3::from(edge_v))),
                Shape::Box { min, max } => {
                    let lo = V3::from(min);
                    let d = V3::from(max) - lo;
                    let (ex, ey, ez) = (
                        V3::new(d.x, 0.0, 0.0),
                        V3::new(0.0, d.y, 0.0),
                        V3::new(0.0, 0.0, d.z),
                    );
                    add(quad(lo, ex, ey));
                    add(quad(lo + ez, ex, ey));
                    add(quad(lo, ey, ez));
                    add(quad(lo + ex, ey, ez));
                    add(quad(lo, ez, ex));
                    add(quad(lo + ey, ez, ex));
                }
                // read and checked with the scene; the render refuses a
                // file gone since (`mod.rs`), so here it is always found
                Shape::Mesh { ref file } => {
                    if let Ok(m) = trimesh::get(file) {
                        add(Prim::Mesh(Arc::new(Placed::new(m, None))))
                    }
                }
            }
            if let Some(t) = &obj.transform {
                let a = Affine::new(t);
                for p in &mut prims[first..] {
                    *p = placed(p, &a);
                }
            }
        }
        let accel = Accel::new(&prims);
        Geometry {
            prims,
            owner,
            accel,
        }
    }

    /// The nearest hit along the ray within (EPS, t_max).
    pub fn intersect(&self, o: V3, d: V3, t_max: f64) -> Option<Hit> {
        self.nearest(o, d, t_max, |_| true)
    }

    /// The nearest hit within (EPS, t_max) among the primitives `tested` keeps.
    #[inline(always)]
    fn nearest(&self, o: V3, d: V3, t_max: f64, tested: impl Fn(usize) -> bool) -> Option<Hit> {
        let (i, h) = self.accel.nearest(&self.prims, o, d, t_max, tested)?;
        Some(Hit {
            t: h.t,
            n: h.n,
            face: h.face,
            object: self.owner[i],
            tri: h.tri,
        })
    }

    /// True when a primitive that may shadow `object` lies on the
    /// segment from `o` along `d` within (EPS, t_max). `from`: the mesh
    /// triangle the segment starts just off, if any; a segment leaving a
    /// face of the mesh's convex hull outwards is not tested against that
    /// mesh (`hull_faces.rs`).
    pub fn blocked_by_others(
        &self,
        o: V3,
        d: V3,
        t_max: f64,
        object: u32,
        from: Option<TriPoint>,
    ) -> bool {
        self.accel.any(&self.prims, o, d, t_max, |i| {
            self.may_shadow(i, object) && !self.leaves_own_hull(i, object, from, o, d)
        })
    }

    /// True when primitive `i` is the mesh of `object` and the ray from
    /// `o` along `d` leaves its triangle `from` outwards through a hull face.
    #[inline]
    fn leaves_own_hull(&self, i: usize, object: u32, from: Option<TriPoint>, o: V3, d: V3) -> bool {
        match (&self.prims[i], from) {
            (Prim::Mesh(m), Some(at)) if self.owner[i] == object => m.leaves_outward(at.tri, o, d),
            _ => false,
        }
    }

    /// Whether primitive `i` may shadow a point of `object`: a convex
    /// shape never shadows itself, a mesh may.
    #[inline]
    pub fn may_shadow(&self, i: usize, object: u32) -> bool {
        self.owner[i] != object || !self.prims[i].convex()
    }

    /// For each primitive, the pixel rectangle its image lies in, when one
    /// can be bounded: a sphere by the corners of its bounding cube, a quad
    /// by its own, all in front of the camera (a perspective projection
    /// keeps a convex set inside the hull of its corners' images). `None`:
    /// it may be seen anywhere (a plane, or a corner behind a pinhole).
    pub fn screen_rects(&self, cam: &CameraRays) -> Vec<Option<Rect>> {
        self.prims
            .iter()
            .map(|prim| {
                let corners: Vec<V3> = match *prim {
                    Prim::Quad { o, u, v, .. } => vec![o, o + u, o + v, o + u + v],
                    Prim::Sphere { .. } | Prim::Plane { .. } | Prim::Mesh(_) => {
                        prim.bounds()?.corners().to_vec()
                    }
                };
                let mut rect = Rect::EMPTY;
                for k in corners {
                    let (x, y) = cam.pixel_of(k)?;
                    rect = rect.with(x, y);
                }
                Some(rect)
            })
            .collect()
    }

    /// The pixels of the image rows [y0, y1) whose camera rays may hit
    /// anything, from `rects` (all of them when some primitive is unbounded).
    pub fn row_span(rects: &[Option<Rect>], y0: f64, y1: f64, width: u32) -> Range<u32> {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for rect in rects {
            match rect {
                None => return 0..width,
                Some(r) if r.y1 >= y0 && r.y0 <= y1 => {
                    lo = lo.min(r.x0);
                    hi = hi.max(r.x1);
                }
                Some(_) => {}
            }
        }
        if lo > hi {
            return 0..0;
        }
        // Pixel x holds the image points [x, x + 1).
        let first = (lo.floor() - 1.0).clamp(0.0, width as f64) as u32;
        let end = (hi.ceil() + 1.0).clamp(0.0, width as f64) as u32;
        first..end
    }

    /// The nearest hit along a camera ray through image point (x, y), among
    /// the primitives `rects` does not rule out there.
    pub fn intersect_camera_ray(
        &self,
        o: V3,
        d: V3,
        (x, y): (f64, f64),
        rects: &[Option<Rect>],
    ) -> Option<Hit> {
        self.nearest(o, d, f64::INFINITY, |i| {
            rects[i].is_none_or(|r| r.contains(x, y))
        })
    }

    /// A possible occluder of point `p` (`face`: the unit normal of the
    /// face `p` lies on, turned towards the ray that found it), in the
    /// form fastest to test from there.
    pub fn occluder(&self, prim: u32, p: V3, face: V3) -> Occluder {
        if let Prim::Mesh(ref mesh) = self.prims[prim as usize] {
            return mesh_occluder(mesh, prim, p, face);
        }
        if let Prim::Sphere { c, r2 } = self.prims[prim as usize] {
            let to = c - p;
            let d2 = to.dot(to);
            if d2 > r2 * (1.0 + 1e-9) {
                let dist = d2.sqrt();
                return Occluder::Cone {
                    axis: to / dist,
                    cos_max: (1.0 - r2 / d2).sqrt(),
                    center_dist: dist,
                    prim,
                };
            }
        }
        Occluder::Prim(prim)
    }

    /// True when any of `occluders` blocks the segment from `o` along unit
    /// `d` before `t_max`.
    #[inline]
    pub fn occluded(&self, o: V3, d: V3, t_max: f64, occluders: &[Occluder]) -> bool {
        occluders.iter().any(|occ| match *occ {
            Occluder::Cone {
                axis,
                cos_max,
                center_dist,
                prim,
            } => {
                // Inside the cone the sphere sees, the ray hits it; the hit
                // lies before the centre's distance, so a farther light is
                // certainly blocked, a nearer one needs the exact test.
                d.dot(axis) > cos_max
                    && (t_max >= center_dist || self.prims[prim as usize].hits_before(o, d, t_max))
            }
            Occluder::Mesh {
                axis,
                cos_max,
                m,
                thr,
                prim,
            } => {
                let clear = (o.dot(m) > thr && d.dot(m) >= 0.0) || d.dot(axis) <= cos_max;
                !clear && self.prims[prim as usize].hits_before(o, d, t_max)
            }
            Occluder::Prim(i) => self.prims[i as usize].hits_before(o, d, t_max),
        })
    }
}

/// A mesh as a possible occluder of `p` (on a face of normal `face`).
/// Both tests are exact, with margins: the plane through `p` is raised by
/// 1e-9 of the scene's scale (far above rounding error, far below the
/// 1e-6 that shadow rays start off their surface, `shade.rs`, and the
/// test takes the ray's own start); the cone is seen from `p`, not from
/// where the ray starts, so the sphere is grown by 1e-5 besides: a ray
/// parallel to one that misses it by that much, starting 1e-6 away,
/// misses the sphere too.
fn mesh_occluder(mesh: &Placed, prim: u32, p: V3, face: V3) -> Occluder {
    let (c, r) = mesh.sphere();
    let margin = 1e-9 * (1.0 + r + c.length() + p.length());
    let r = r + margin + 1e-5;
    let to = c - p;
    let d2 = to.dot(to);
    let (axis, cos_max) = if d2 > r * r {
        let dist = d2.sqrt();
        (to / dist, (1.0 - r * r / d2).sqrt())
    } else {
        (V3::new(0.0, 0.0, 1.0), -2.0)
    };
    // Below the plane of p's own face lies all of a convex mesh: the
    // question is asked once per hit and light, through the BVH's boxes.
    let thr = p.dot(face) + margin;
    let (m, thr) = if face.dot(face) > 0.0 && !mesh.reaches_above(face, thr) {
        (face, thr)
    } else {
        (V3::new(0.0, 0.0, 0.0), 0.0)
    };
    Occluder::Mesh {
        axis,
        cos_max,
        m,
        thr,
        prim,
    }
}

/// `p` moved by `a`, exactly: an affine map takes a parallelogram to a
/// parallelogram and a plane to a plane, and a sphere (whose scale is
/// uniform, `validate.rs`) to a sphere.
fn placed(p: &Prim, a: &Affine) -> Prim {
    match *p {
        Prim::Sphere { c, r2 } => {
            // |m x| / |x| for any x: the one scale factor.
            let s = a.vector(V3::new(1.0, 0.0, 0.0)).length();
            Prim::Sphere {
                c: a.point(c),
                r2: r2 * s * s,
            }
        }
        Prim::Plane { p, n } => Prim::Plane {
            p: a.point(p),
            n: a.normal(n).normalized(),
        },
        Prim::Quad { o, u, v, .. } => quad(a.point(o), a.vector(u), a.vector(v)),
        Prim::Mesh(ref m) => Prim::Mesh(Arc::new(Placed::new(m.mesh.clone(), Some(a)))),
    }
}

fn quad(o: V3, u: V3, v: V3) -> Prim {
    let c = u.cross(v);
    Prim::Quad {
        o,
        u,
        v,
        n: c.normalized(),
        w: c / c.dot(c),
    }
}

/// Ray parameters (near, far) where the ray o + t d (d unit) meets the
/// sphere of centre `c` and squared radius `r2`, if it does.
#[inline(always)]
fn sphere_roots(o: V3, d: V3, c: V3, r2: f64) -> Option<(f64, f64)> {
    let oc = o - c;
    let b = oc.dot(d);
    let disc = b * b - (oc.dot(oc) - r2);
    if disc < 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    Some((-b - sq, -b + sq))
}

impl Intersect for Prim {
    #[inline]
    fn hit(&self, o: V3, d: V3, t_max: f64) -> Option<(f64, V3)> {
        match *self {
            Prim::Sphere { c, r2 } => {
                let (t0, t1) = sphere_roots(o, d, c, r2)?;
                let t = if t0 <= EPS { t1 } else { t0 };
                if t <= EPS || t >= t_max {
                    return None;
                }
                let n = (o + d * t - c) / r2.sqrt();
                Some((t, n))
            }
            Prim::Plane { p, n } => {
                let denom = n.dot(d);
                if denom.abs() < 1e-12 {
                    return None;
                }
                let t = (p - o).dot(n) / denom;
                (t > EPS && t < t_max).then_some((t, n))
            }
            Prim::Quad { o: q0, u, v, n, w } => {
                let denom = n.dot(d);
                if denom.abs() < 1e-12 {
                    return None;
                }
                let t = (q0 - o).dot(n) / denom;
                if t <= EPS || t >= t_max {
                    return None;
                }
                let q = o + d * t - q0;
                let a = w.dot(q.cross(v));
                let b = w.dot(u.cross(q));
                ((0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b)).then_some((t, n))
            }
            Prim::Mesh(ref m) => m.hit(o, d, t_max).map(|h| (h.t, h.n)),
        }
    }

    #[inline]
    fn hit_face(&self, o: V3, d: V3, t_max: f64) -> Option<FaceHit> {
        match *self {
            Prim::Mesh(ref m) => m.hit(o, d, t_max),
            _ => self.hit(o, d, t_max).map(|(t, n)| FaceHit {
                t,
                n,
                face: n,
                tri: None,
            }),
        }
    }

    #[inline]
    fn hits_before(&self, o: V3, d: V3, t_max: f64) -> bool {
        match *self {
            Prim::Sphere { c, r2 } => sphere_roots(o, d, c, r2)
                .is_some_and(|(t0, t1)| (t0 > EPS && t0 < t_max) || (t1 > EPS && t1 < t_max)),
            Prim::Plane { .. } | Prim::Quad { .. } => self.hit(o, d, t_max).is_some(),
            Prim::Mesh(ref m) => m.any(o, d, t_max),
        }
    }

    fn bounds(&self) -> Option<Aabb> {
        match *self {
            Prim::Sphere { c, r2 } => {
                let r = r2.sqrt();
                let r = V3::new(r, r, r);
                Some(Aabb {
                    lo: c - r,
                    hi: c + r,
                })
            }
            Prim::Quad { o, u, v, .. } => {
                let mut b = Aabb { lo: o, hi: o };
                for k in [o + u, o + v, o + u + v] {
                    b = Aabb::hull(k, b.lo, b.hi);
                }
                Some(b)
            }
            Prim::Plane { .. } => None,
            Prim::Mesh(ref m) => Some(m.bounds),
        }
    }

    fn may_block(&self, p: V3, lo: V3, hi: V3) -> bool {
        match *self {
            // The segments lie in the bounding box of p and [lo, hi].
            Prim::Sphere { .. } | Prim::Mesh(_) => self
                .bounds()
                .is_none_or(|b| b.overlaps(&Aabb::hull(p, lo, hi))),
            Prim::Plane { p: q, n } | Prim::Quad { o: q, n, .. } => {
                // A segment crosses the plane only if its ends are on opposite sides.
                let side_p = (p - q).dot(n);
                if side_p.abs() < 1e-9 {
                    return false; // p lies on the plane: the segment leaves it at once
                }
                Aabb { lo, hi }
                    .corners()
                    .iter()
                    .any(|&k| (k - q).dot(n) * side_p <= 0.0)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ball scene with one object: `shape` (JSON) placed by
    /// `transform` (JSON, or "" for none).
    fn one(shape: &str, transform: &str) -> Geometry {
        let mut scene = crate::scene::test_scene::ball(r#""color": [0.5, 0.5, 0.5]"#, "");
        scene.objects[0].shape = serde_json::from_str(shape).unwrap();
        scene.objects[0].transform =
            (!transform.is_empty()).then(|| serde_json::from_str(transform).unwrap());
        Geometry::new(&scene)
    }

    /// A shape placed by a transform is hit where the same shape written
    /// in place is: every ray of a grid through the scene meets both or
    /// neither, at the same distance.
    #[test]
    fn a_placed_shape_is_hit_where_it_is_written() {
        let cases = [
            (
                r#"{"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5}"#,
                r#"{"type": "sphere", "center": [0, 0, 0], "radius": 0.25}"#,
                r#"{"scale": 2, "rotate_deg": [10, 20, 30], "translate": [0, 0.5, 0]}"#,
            ),
            (
                r#"{"type": "box", "min": [-1, 0, -0.25], "max": [1, 1, 0.25]}"#,
                r#"{"type": "box", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]}"#,
                r#"{"scale": [2, 1, 0.5], "translate": [0, 0.5, 0]}"#,
            ),
            (
                // about y by 90: +x goes to -z, +z to +x
                r#"{"type": "quad", "corner": [0.2, 0, 0], "edge_u": [0, 0, -1], "edge_v": [0.5, 0.7, 0]}"#,
                r#"{"type": "quad", "corner": [0, 0, 0], "edge_u": [1, 0, 0], "edge_v": [0, 0.7, 0.5]}"#,
                r#"{"rotate_deg": [0, 90, 0], "translate": [0.2, 0, 0]}"#,
            ),
            (
                // a stretched tilted plane: its normal by the inverse scale
                r#"{"type": "plane", "point": [0, 0.2, 0], "normal": [0.5, 1, 0]}"#,
                r#"{"type": "plane", "point": [0, 0.2, 0], "normal": [1, 1, 0]}"#,
                r#"{"scale": [2, 1, 1]}"#,
            ),
        ];
        for (written, shape, transform) in cases {
            let (a, b) = (one(written, ""), one(shape, transform));
            let hits = agree(&a, &b, &format!("{shape} {transform}"), |_, _, _, _| {});
            assert!(hits > 5, "{shape}: {hits} hits");
        }
    }

    /// Casts a 20x20 grid of rays at `a` and `b`: each must hit both or
    /// neither, at the same distance with the same normal line; `each`
    /// sees every ray that hits (origin, direction, `b`'s hit, its
    /// number). Returns the hits. Off-grid steps, so that no ray grazes
    /// an edge, where the last bit decides.
    fn agree(
        a: &Geometry,
        b: &Geometry,
        what: &str,
        mut each: impl FnMut(V3, V3, &Hit, usize),
    ) -> usize {
        let mut hits = 0;
        for i in 0..400 {
            let (x, y) = (
                (i % 20) as f64 * 0.1037 - 1.01,
                (i / 20) as f64 * 0.0971 - 0.49,
            );
            let o = V3::new(0.313, 1.517, 5.0);
            let d = (V3::new(x, y, 0.0) - o).normalized();
            let (ha, hb) = (a.intersect(o, d, 1e9), b.intersect(o, d, 1e9));
            assert_eq!(ha.is_some(), hb.is_some(), "{what}: ray {i}");
            if let (Some(ha), Some(hb)) = (ha, hb) {
                assert!((ha.t - hb.t).abs() < 1e-9, "{what}: {} vs {}", ha.t, hb.t);
                assert!((ha.n.dot(hb.n).abs() - 1.0).abs() < 1e-9, "{what}");
                each(o, d, &hb, i);
                hits += 1;
            }
        }
        hits
    }

    /// A box's twelve triangles as an ASCII PLY file in `dir`.
    fn box_ply(dir: &std::path::Path, lo: [f64; 3], hi: [f64; 3]) -> String {
        let mut ply = "ply\nformat ascii 1.0\nelement vertex 8\nproperty double x\nproperty double y\nproperty double z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n".to_string();
        for k in 0..8 {
            let c = |a: usize| if k >> a & 1 == 0 { lo[a] } else { hi[a] };
            ply += &format!("{} {} {}\n", c(0), c(1), c(2));
        }
        // the six faces as quads (fanned on reading)
        for f in [
            "0 1 3 2", "4 6 7 5", "0 4 5 1", "2 3 7 6", "0 2 6 4", "1 5 7 3",
        ] {
            ply += &format!("4 {f}\n");
        }
        let p = dir.join("box.ply");
        std::fs::write(&p, ply).unwrap();
        p.display().to_string()
    }

    /// A box written as a mesh is hit where the box shape is, at the same
    /// distance with the same normal, as it is and placed by a transform
    /// (the mesh's rays carried into its frame, its normals out).
    #[test]
    fn a_mesh_box_is_hit_where_the_box_is() {
        let d = tempfile::tempdir().unwrap();
        let file = box_ply(d.path(), [-0.5, -0.5, -0.5], [0.5, 0.5, 0.5]);
        let mesh = format!(r#"{{"type": "mesh", "file": {file:?}}}"#);
        let cube = r#"{"type": "box", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]}"#;
        for transform in [
            "",
            r#"{"scale": [2, 1, 0.5], "rotate_deg": [10, 35, -20], "translate": [0, 0.5, 0]}"#,
        ] {
            let (a, b) = (one(cube, transform), one(&mesh, transform));
            assert!(!b.prims[0].convex());
            let hits = agree(&a, &b, transform, |o, d, hb, i| {
                // from the far side of the hit, back through the mesh: it shadows itself
                let p = o + d * (hb.t + 1e-3);
                assert!(
                    b.blocked_by_others(p, -d, 1.0, 0, None),
                    "{transform}: ray {i}"
                );
            });
            assert!(hits > 50, "{transform}: {hits} hits");
        }
    }

    /// The tests that rule shadow rays out before a mesh's BVH is walked
    /// (its bounding sphere's cone, the plane of the face a point lies
    /// on) never change the answer: from points on a placed mesh box and
    /// on the floor round it, in directions all round and to near and far
    /// lights, the occluder blocks exactly the rays the mesh blocks; and
    /// they do rule most rays out.
    #[test]
    fn a_mesh_occluder_blocks_what_the_mesh_blocks() {
        let d = tempfile::tempdir().unwrap();
        let file = box_ply(d.path(), [-0.5, -0.5, -0.5], [0.5, 0.5, 0.5]);
        let mesh = format!(r#"{{"type": "mesh", "file": {file:?}}}"#);
        let placed =
            r#"{"scale": [1, 0.8, 0.6], "rotate_deg": [5, 30, 0], "translate": [0, 0.45, 0]}"#;
        let g = one(&mesh, placed);
        let mut points = Vec::new();
        agree(&g, &g, "mesh", |o, d, hb, _| {
            let face = if hb.face.dot(d) < 0.0 {
                hb.face
            } else {
                -hb.face
            };
            points.push((o + d * hb.t, face));
        });
        for i in 0..100 {
            let (x, z) = ((i % 10) as f64 * 0.4 - 1.8, (i / 10) as f64 * 0.4 - 1.8);
            points.push((V3::new(x, 0.0, z), V3::new(0.0, 1.0, 0.0)));
        }
        let (mut tested, mut ruled_out) = (0, 0);
        for &(p, face) in &points {
            let occ = g.occluder(0, p, face);
            let o = p + face * 1e-6;
            for k in 0..200 {
                // directions spread over the sphere (a Fibonacci spiral)
                let z = 1.0 - (k as f64 + 0.5) / 100.0;
                let a = k as f64 * 2.399963;
                let r = (1.0 - z * z).sqrt();
                let dir = V3::new(r * a.cos(), z, r * a.sin());
                for dist in [0.3, 1e9] {
                    let exact = g.prims[0].hits_before(o, dir, dist);
                    assert_eq!(g.occluded(o, dir, dist, &[occ]), exact, "{p:?} {dir:?}");
                    if let Occluder::Mesh {
                        axis,
                        cos_max,
                        m,
                        thr,
                        ..
                    } = occ
                    {
                        let clear =
                            (o.dot(m) > thr && dir.dot(m) >= 0.0) || dir.dot(axis) <= cos_max;
                        ruled_out += clear as usize;
                    }
                    tested += 1;
                }
            }
        }
        assert!(points.len() > 150, "{}", points.len());
        assert!(ruled_out * 2 > tested, "{ruled_out} of {tested}");
    }
}
