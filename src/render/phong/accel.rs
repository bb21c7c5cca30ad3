//! The seam between the built-in tracer and what it intersects: what any
//! primitive answers about a ray ([`Intersect`]), and the structure that
//! decides which primitives of a list a ray is tested against ([`Accel`]).
//!
//! Today `Accel` is the plain list (every primitive tested, in order):
//! scenes hold a handful of primitives and the camera rays are already
//! culled per primitive by their image rectangle (`geometry.rs`). A
//! bounding volume hierarchy goes here, in one place: built in
//! [`Accel::new`] from [`Intersect::bounds`], walked in [`Accel::nearest`]
//! and [`Accel::any`]. It serves the scene's primitive list and, being
//! generic, a mesh's triangle list alike.

use crate::math::V3;

/// Rays start this far off a surface so that they do not hit it again:
/// hits count in (EPS, t_max).
pub const EPS: f64 = 1e-7;

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub lo: V3,
    pub hi: V3,
}

impl Aabb {
    /// The smallest box holding `p` and the box [lo, hi].
    pub fn hull(p: V3, lo: V3, hi: V3) -> Aabb {
        Aabb {
            lo: V3::new(p.x.min(lo.x), p.y.min(lo.y), p.z.min(lo.z)),
            hi: V3::new(p.x.max(hi.x), p.y.max(hi.y), p.z.max(hi.z)),
        }
    }

    /// True when the two boxes share a point (touching counts).
    pub fn overlaps(&self, o: &Aabb) -> bool {
        (0..3).all(|a| self.hi.get(a) >= o.lo.get(a) && self.lo.get(a) <= o.hi.get(a))
    }

    /// The eight corners.
    pub fn corners(&self) -> [V3; 8] {
        let (lo, hi) = (self.lo, self.hi);
        let mut out = [lo; 8];
        for (i, k) in out.iter_mut().enumerate() {
            *k = V3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
        }
        out
    }
}

/// Where on a mesh a hit lies: its triangle, numbered as in the file,
/// and the barycentric (u, v) of the hit on it (weights of the second and
/// third corners), from the walk that found the hit: what a texture is
/// looked up by (`texture.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriPoint {
    pub tri: u32,
    pub u: f64,
    pub v: f64,
}

/// The nearest hit of a ray on one primitive: distance, unit normal (the
/// shading one), unit face normal and, on a mesh, where on it.
#[derive(Clone, Copy, Debug)]
pub struct FaceHit {
    pub t: f64,
    pub n: V3,
    pub face: V3,
    pub tri: Option<TriPoint>,
}

/// What the tracer asks of a primitive. Rays are o + t d with d unit;
/// hits count in (EPS, t_max) (`geometry::EPS`).
pub trait Intersect {
    /// Distance and unit geometric normal of the nearest hit.
    fn hit(&self, o: V3, d: V3, t_max: f64) -> Option<(f64, V3)>;

    /// The nearest hit with the face's own normal besides (`FaceHit`).
    /// The same normal twice and no triangle by default: only a mesh's
    /// two normals differ, and only a mesh has triangles.
    #[inline(always)]
    fn hit_face(&self, o: V3, d: V3, t_max: f64) -> Option<FaceHit> {
        self.hit(o, d, t_max).map(|(t, n)| FaceHit {
            t,
            n,
            face: n,
            tri: None,
        })
    }

    /// A shadow ray's test: any hit at all?
    fn hits_before(&self, o: V3, d: V3, t_max: f64) -> bool {
        self.hit(o, d, t_max).is_some()
    }

    /// A box holding the primitive; `None` when it is unbounded (a plane).
    fn bounds(&self) -> Option<Aabb>;

    /// A conservative test: could the primitive block any segment from
    /// `p` to a point of the box [lo, hi]? False only when it certainly
    /// cannot. By default: when its bounds meet the box the segments lie in.
    fn may_block(&self, p: V3, lo: V3, hi: V3) -> bool {
        self.bounds()
            .is_none_or(|b| b.overlaps(&Aabb::hull(p, lo, hi)))
    }
}

/// Which primitives of a list a ray is tested against: today all of them.
#[derive(Clone, Debug, Default)]
pub struct Accel;

impl Accel {
    /// The structure over `items` (the list itself needs none).
    pub fn new<T: Intersect>(_items: &[T]) -> Accel {
        Accel
    }

    /// The nearest hit within (EPS, t_max) among the items `keep` accepts:
    /// its index and the hit. Of two hits at the same distance the first
    /// item's is kept.
    #[inline(always)]
    pub fn nearest<T: Intersect>(
        &self,
        items: &[T],
        o: V3,
        d: V3,
        t_max: f64,
        keep: impl Fn(usize) -> bool,
    ) -> Option<(usize, FaceHit)> {
        let mut best = None;
        let mut t_best = t_max;
        for (i, item) in items.iter().enumerate() {
            if !keep(i) {
                continue;
            }
            if let Some(h) = item.hit_face(o, d, t_best) {
                t_best = h.t;
                best = Some((i, h));
            }
        }
        best
    }

    /// True when any item `keep` accepts is hit within (EPS, t_max).
    #[inline(always)]
    pub fn any<T: Intersect>(
        &self,
        items: &[T],
        o: V3,
        d: V3,
        t_max: f64,
        keep: impl Fn(usize) -> bool,
    ) -> bool {
        items
            .iter()
            .enumerate()
            .any(|(i, item)| keep(i) && item.hits_before(o, d, t_max))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit ball around a centre, for the list tests.
    struct Ball(V3);

    impl Intersect for Ball {
        fn hit(&self, o: V3, d: V3, t_max: f64) -> Option<(f64, V3)> {
            let oc = o - self.0;
            let b = oc.dot(d);
            let disc = b * b - (oc.dot(oc) - 1.0);
            let t = -b - disc.max(0.0).sqrt();
            (disc >= 0.0 && t > 1e-7 && t < t_max).then(|| (t, o + d * t - self.0))
        }
        fn bounds(&self) -> Option<Aabb> {
            let r = V3::new(1.0, 1.0, 1.0);
            Some(Aabb {
                lo: self.0 - r,
                hi: self.0 + r,
            })
        }
    }

    #[test]
    fn the_nearest_kept_item_is_found_within_reach() {
        let balls = [
            Ball(V3::new(0.0, 0.0, 10.0)),
            Ball(V3::new(0.0, 0.0, 5.0)),
            Ball(V3::new(5.0, 0.0, 5.0)),
        ];
        let accel = Accel::new(&balls);
        let (o, d) = (V3::new(0.0, 0.0, 0.0), V3::new(0.0, 0.0, 1.0));
        let hit = accel.nearest(&balls, o, d, f64::INFINITY, |_| true);
        assert_eq!(hit.map(|h| (h.0, h.1.t)), Some((1, 4.0)));
        let hit = accel.nearest(&balls, o, d, f64::INFINITY, |i| i != 1);
        assert_eq!(hit.map(|h| (h.0, h.1.t)), Some((0, 9.0)));
        assert!(accel.nearest(&balls, o, d, 3.0, |_| true).is_none());
        assert!(accel.any(&balls, o, d, 4.5, |_| true));
        assert!(!accel.any(&balls, o, d, 4.5, |i| i != 1));
    }

    #[test]
    fn blocking_is_ruled_out_only_where_the_bounds_miss_the_segments() {
        let ball = Ball(V3::new(0.0, 5.0, 0.0));
        let p = V3::new(0.0, 0.0, 0.0);
        let light = |y: f64| (V3::new(-1.0, y, -1.0), V3::new(1.0, y + 0.5, 1.0));
        let (lo, hi) = light(10.0);
        assert!(ball.may_block(p, lo, hi), "the ball lies between");
        let (lo, hi) = light(-10.0);
        assert!(!ball.may_block(p, lo, hi), "the light is on the other side");
    }
}
