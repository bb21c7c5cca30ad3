//! Which of a mesh's triangles lie on its convex hull, found lazily, one
//! triangle at a time. A shadow ray that leaves such a face outwards (its
//! start above the face's plane, its direction not heading below it)
//! cannot meet the mesh, every vertex of which lies on or below that
//! plane: so the lit points of a convex mesh, and of the convex parts of
//! any mesh, cast their shadow rays without a walk of the BVH.
//!
//! A triangle's answer is asked of the mesh once per process, the first
//! time a shadow ray leaves it (a query through the BVH's boxes,
//! `TriMesh::reaches_above`), and kept. It depends on the mesh alone, so
//! which thread asks first changes nothing: the images do not depend on
//! the thread count. Nothing is asked of triangles no ray leaves, so a
//! large mesh's build pays nothing for this.

use crate::math::V3;
use std::sync::atomic::{AtomicU8, Ordering};

/// Not asked yet.
const UNKNOWN: u8 = 0;
/// The mesh lies below the plane, on the side its normal e1 x e2 points away from.
const OUT_ALONG: u8 = 1;
/// The mesh lies above it: the face is on the hull, wound inwards.
const OUT_AGAINST: u8 = 2;
/// The plane cuts the mesh.
const INSIDE: u8 = 3;

/// Per triangle (in the BVH's order): on the hull and which way out.
#[derive(Debug)]
pub struct HullFaces {
    side: Vec<AtomicU8>,
    /// Far above rounding error in the mesh's frame, far below the 1e-6
    /// that shadow rays start off their surface (`paths.rs`), per unit
    /// length of a face normal.
    margin: f64,
}

impl HullFaces {
    /// Nothing known yet about `n` triangles of a mesh whose bounding
    /// sphere has centre `c` and radius `r`.
    pub fn new(n: usize, c: V3, r: f64) -> HullFaces {
        HullFaces {
            side: (0..n).map(|_| AtomicU8::new(UNKNOWN)).collect(),
            margin: 1e-9 * (1.0 + r + c.length()),
        }
    }

    /// True when the ray from `o` along `d` leaves triangle `k` (corner
    /// `v0`, normal `ng` = e1 x e2, not unit) outwards from a hull face:
    /// then it meets no triangle of the mesh. `reaches_above(m, thr)`:
    /// does some vertex x have x . m > thr?
    #[inline]
    pub fn leaves(
        &self,
        k: usize,
        (v0, ng): (V3, V3),
        o: V3,
        d: V3,
        reaches_above: impl Fn(V3, f64) -> bool,
    ) -> bool {
        let mu = self.margin * ng.length();
        let m = match self.side[k].load(Ordering::Relaxed) {
            OUT_ALONG => ng,
            OUT_AGAINST => -ng,
            INSIDE => return false,
            _ => {
                // the whole mesh within mu of the plane's one side; a ray
                // must start 2 mu above it, so that no rounding of the
                // walk's triangle tests could meet a vertex on the plane
                let s = if !reaches_above(ng, v0.dot(ng) + mu) {
                    OUT_ALONG
                } else if !reaches_above(-ng, -v0.dot(ng) + mu) {
                    OUT_AGAINST
                } else {
                    INSIDE
                };
                self.side[k].store(s, Ordering::Relaxed);
                match s {
                    OUT_ALONG => ng,
                    OUT_AGAINST => -ng,
                    _ => return false,
                }
            }
        };
        o.dot(m) > v0.dot(m) + 2.0 * mu && d.dot(m) >= 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tetrahedron's vertices: every face is on the hull; the query
    /// answers from the vertices themselves.
    #[test]
    fn a_ray_leaving_a_hull_face_outwards_is_clear_and_no_other() {
        let v = [
            V3::new(0.0, 0.0, 0.0),
            V3::new(1.0, 0.0, 0.0),
            V3::new(0.0, 1.0, 0.0),
            V3::new(0.0, 0.0, 1.0),
        ];
        let above = |m: V3, thr: f64| v.iter().any(|x| x.dot(m) > thr);
        let h = HullFaces::new(2, V3::new(0.3, 0.3, 0.3), 1.0);
        // the face z = 0 wound with e1 x e2 = +z (into the solid), and a
        // plane through the solid (x = y), not on the hull
        let base = (v[0], (v[1] - v[0]).cross(v[2] - v[0]));
        let cut = (v[0], V3::new(1.0, -1.0, 0.0));
        let below = V3::new(0.2, 0.2, -1e-6);
        let out = V3::new(0.3, -0.2, -0.5).normalized();
        assert!(h.leaves(0, base, below, out, above));
        assert!(h.leaves(0, base, below, V3::new(1.0, 0.0, 0.0), above));
        assert!(!h.leaves(0, base, below, -out, above), "heading in");
        assert!(!h.leaves(0, base, V3::new(0.2, 0.2, 1e-6), out, above));
        assert!(!h.leaves(1, cut, V3::new(0.2, 0.1, 0.1), out, above));
        assert!(!h.leaves(1, cut, V3::new(0.2, 0.1, 0.1), -out, above));
    }
}
