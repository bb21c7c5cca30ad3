//! A bounding volume hierarchy over boxes: binned surface-area-heuristic
//! build (`bvh_build.rs`), front-to-back walk. Our own rather than a
//! crate: the tracer works in f64 with its own vector type and hit rules
//! (`Intersect`), and the crates that fit (`bvh`, `obvhs`) bring f32
//! nalgebra/glam types and their own ray and shape traits; this is a few
//! hundred lines, deterministic (the same tree for the same input on any
//! number of threads) and its cost is measured in `benches/mesh.rs`.
//!
//! Items are addressed by their position in [`Bvh::order`]: the caller
//! stores them in that order, so that a leaf's items are contiguous.
//!
//! The walk reads nodes of 32 bytes: boxes in f32, rounded outwards from
//! the build's f64 ones, so that a box holds everything the exact one
//! holds (a ray may enter a few more leaves, never fewer) in half the
//! memory. The slab test itself is in f64.

use super::accel::Aabb;
use super::bvh_build::{self, Item, SAH_DEPTH};
use super::bvh_node::Node32;
use crate::math::V3;
use rayon::prelude::*;

/// The walk's stack: deep enough for any tree the build makes
/// (`bvh_build::SAH_DEPTH`).
const STACK: usize = SAH_DEPTH + 66;

/// Subtrees `nearest_to` shares among threads: enough for a few per
/// thread on a small machine, few enough that each prunes on its own.
const NEAREST_SPLIT: usize = 16;

/// The hierarchy; `order[k]` is the input index of the item at position k.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node32>,
    pub order: Vec<u32>,
}

impl Bvh {
    /// The hierarchy over `boxes` (finite boxes; an empty list gives an
    /// empty tree that nothing hits). The same tree whatever the number
    /// of threads (`bvh_build.rs`).
    pub fn build(boxes: &[Aabb]) -> Bvh {
        let mut items: Vec<Item> = boxes
            .iter()
            .enumerate()
            .map(|(i, b)| Item {
                lo: b.lo.to_array(),
                hi: b.hi.to_array(),
                index: i as u32,
            })
            .collect();
        let mut nodes = bvh_build::tree(&mut items);
        if boxes.is_empty() {
            nodes[0].lo = [f64::INFINITY; 3];
            nodes[0].hi = [f64::NEG_INFINITY; 3];
        }
        Bvh {
            nodes: nodes.iter().map(Node32::of).collect(),
            order: items.iter().map(|it| it.index).collect(),
        }
    }

    /// The nearest item hit within (…, t_max): `hit(k, t_best)` tests the
    /// item at position k and gives its distance when it is nearer than
    /// t_best. Returns the position and distance.
    #[inline]
    pub fn nearest(
        &self,
        o: V3,
        d: V3,
        t_max: f64,
        mut hit: impl FnMut(usize, f64) -> Option<f64>,
    ) -> Option<(usize, f64)> {
        let mut best = None;
        let mut t_best = t_max;
        self.walk(o, d, t_max, |k| {
            if let Some(t) = hit(k, t_best) {
                t_best = t;
                best = Some((k, t));
            }
            Some(t_best)
        });
        best
    }

    /// True when `hit(k)` holds for any item whose box the ray meets
    /// before t_max.
    #[inline]
    pub fn any(&self, o: V3, d: V3, t_max: f64, mut hit: impl FnMut(usize) -> bool) -> bool {
        let mut found = false;
        self.walk(o, d, t_max, |k| {
            found = hit(k);
            (!found).then_some(t_max)
        });
        found
    }

    /// True when `item(k)` holds for an item of a leaf reached through
    /// boxes that `enter(lo, hi)` accepts (a query that is not a ray).
    pub fn any_box(
        &self,
        enter: impl Fn(&[f64; 3], &[f64; 3]) -> bool,
        mut item: impl FnMut(usize) -> bool,
    ) -> bool {
        if self.order.is_empty() {
            return false;
        }
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let n = &self.nodes[i];
            if !enter(&n.lo.map(f64::from), &n.hi.map(f64::from)) {
                continue;
            }
            if n.count > 0 {
                let items = n.first as usize..(n.first + n.count) as usize;
                if items.into_iter().any(&mut item) {
                    return true;
                }
            } else {
                stack.push(n.first as usize + 1);
                stack.push(n.first as usize);
            }
        }
        false
    }

    /// The least of `item(k)` over every item, where `item` is a distance
    /// from `p` that is never less than the distance from `p` to the
    /// item's box: boxes nearer than the best so far are opened, nearer
    /// first, so a mesh's nearest triangle costs a walk, not a pass over
    /// every triangle. The tree's top levels are split among the rayon
    /// pool's threads (a point as far from every item, a sphere's centre,
    /// opens every box); the least of exact values is the same for any
    /// number of threads. Infinity for an empty tree.
    pub fn nearest_to(&self, p: V3, item: impl Fn(usize) -> f64 + Sync) -> f64 {
        if self.order.is_empty() {
            return f64::INFINITY;
        }
        let mut roots = vec![0usize];
        while roots.len() < NEAREST_SPLIT && roots.iter().any(|&i| self.nodes[i].count == 0) {
            roots = roots
                .iter()
                .flat_map(|&i| match self.nodes[i].count {
                    0 => vec![
                        self.nodes[i].first as usize,
                        self.nodes[i].first as usize + 1,
                    ],
                    _ => vec![i],
                })
                .collect();
        }
        roots
            .par_iter()
            .map(|&root| self.nearest_below(root, p.to_array(), &item))
            .reduce(|| f64::INFINITY, f64::min)
    }

    /// `nearest_to` within the subtree at `root`, on one thread.
    fn nearest_below(&self, root: usize, p: [f64; 3], item: &impl Fn(usize) -> f64) -> f64 {
        let gap = |n: &Node32| -> f64 {
            (0..3)
                .map(|a| {
                    let d = (f64::from(n.lo[a]) - p[a]).max(p[a] - f64::from(n.hi[a]));
                    d.max(0.0).powi(2)
                })
                .sum::<f64>()
                .sqrt()
        };
        let mut best = f64::INFINITY;
        let mut stack = vec![(root, gap(&self.nodes[root]))];
        while let Some((i, g)) = stack.pop() {
            if g >= best {
                continue;
            }
            let n = &self.nodes[i];
            if n.count > 0 {
                for k in n.first as usize..(n.first + n.count) as usize {
                    best = best.min(item(k));
                }
                continue;
            }
            let (l, r) = (n.first as usize, n.first as usize + 1);
            let (gl, gr) = (gap(&self.nodes[l]), gap(&self.nodes[r]));
            // the nearer child is popped first
            if gl <= gr {
                stack.extend([(r, gr), (l, gl)]);
            } else {
                stack.extend([(l, gl), (r, gr)]);
            }
        }
        best
    }

    /// Visits the items of the leaves whose boxes the ray meets before the
    /// reach, nearer boxes first; `visit` gives the new reach, or `None`
    /// to stop. A box left behind is kept with the distance the ray enters
    /// it at, and skipped without a second test once the reach has shrunk
    /// below that.
    #[inline(always)]
    fn walk(&self, o: V3, d: V3, t_max: f64, mut visit: impl FnMut(usize) -> Option<f64>) {
        let ray = Slab::new(o, d);
        let mut reach = t_max;
        let mut stack = [(0u32, 0f64); STACK];
        let mut top = 0;
        let mut node = 0usize;
        if self.order.is_empty() || ray.enter(&self.nodes[0], reach).is_infinite() {
            return;
        }
        loop {
            let n = &self.nodes[node];
            if n.count > 0 {
                for k in n.first as usize..(n.first + n.count) as usize {
                    match visit(k) {
                        Some(r) => reach = r,
                        None => return,
                    }
                }
            } else {
                let (l, r) = (n.first as usize, n.first as usize + 1);
                let (tl, tr) = (
                    ray.enter(&self.nodes[l], reach),
                    ray.enter(&self.nodes[r], reach),
                );
                let (near, far, tn, tf) = if tl <= tr {
                    (l, r, tl, tr)
                } else {
                    (r, l, tr, tl)
                };
                if tn.is_finite() {
                    if tf.is_finite() {
                        // the build keeps the depth below STACK
                        stack[top] = (far as u32, tf);
                        top += 1;
                    }
                    node = near;
                    continue;
                }
            }
            // next: a farther box left behind, if still in reach
            loop {
                if top == 0 {
                    return;
                }
                top -= 1;
                let (k, t) = stack[top];
                if t <= reach {
                    node = k as usize;
                    break;
                }
            }
        }
    }
}

/// A ray as the slab test reads it: its origin and the inverse of its
/// direction, and which of each axis' planes it meets first.
struct Slab {
    o: [f64; 3],
    inv: [f64; 3],
    neg: [bool; 3],
}

impl Slab {
    #[inline(always)]
    fn new(o: V3, d: V3) -> Slab {
        let inv = [1.0 / d.x, 1.0 / d.y, 1.0 / d.z];
        Slab {
            o: o.to_array(),
            inv,
            neg: inv.map(|i| i < 0.0),
        }
    }

    /// The distance the ray enters the box of `n` at (0 when it starts
    /// inside), or infinity when it misses it within `reach`.
    #[inline(always)]
    fn enter(&self, n: &Node32, reach: f64) -> f64 {
        let mut t0: f64 = 0.0;
        let mut t1 = reach;
        for a in 0..3 {
            let (near, far) = if self.neg[a] {
                (n.hi[a], n.lo[a])
            } else {
                (n.lo[a], n.hi[a])
            };
            let ta = (f64::from(near) - self.o[a]) * self.inv[a];
            let tb = (f64::from(far) - self.o[a]) * self.inv[a];
            // max/min keep a NaN (0 * inf, a ray in a box's plane) out
            t0 = t0.max(ta);
            t1 = t1.min(tb);
        }
        if t0 <= t1 {
            t0
        } else {
            f64::INFINITY
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(c: V3, r: f64) -> Aabb {
        let r = V3::new(r, r, r);
        Aabb {
            lo: c - r,
            hi: c + r,
        }
    }

    /// Every ray finds through the tree what testing every item finds:
    /// a grid of small boxes, rays in many directions.
    #[test]
    fn the_walk_finds_what_testing_every_item_finds() {
        let mut boxes = Vec::new();
        for i in 0..500 {
            let f = i as f64;
            boxes.push(cube(
                V3::new(
                    (f * 0.37).sin() * 5.0,
                    (f * 0.91).cos() * 5.0,
                    (f * 0.13).sin() * 5.0,
                ),
                0.2,
            ));
        }
        let bvh = Bvh::build(&boxes);
        let mut seen = bvh.order.clone();
        seen.sort();
        assert_eq!(seen, (0..500).collect::<Vec<u32>>());
        // the item's "hit": entering its box
        let t_box = |b: &Aabb, o: V3, d: V3| -> Option<f64> {
            let (mut t0, mut t1) = (1e-9f64, f64::INFINITY);
            for a in 0..3 {
                let (ta, tb) = (
                    (b.lo.get(a) - o.get(a)) / d.get(a),
                    (b.hi.get(a) - o.get(a)) / d.get(a),
                );
                t0 = t0.max(ta.min(tb));
                t1 = t1.min(ta.max(tb));
            }
            (t0 <= t1).then_some(t0)
        };
        let mut hits = 0;
        for r in 0..400 {
            let f = r as f64;
            let o = V3::new(0.1 + (f * 0.7).sin() * 8.0, (f * 1.3).cos() * 8.0, 9.0);
            let d = (V3::new((f * 0.29).cos(), (f * 0.53).sin(), 0.0) * 3.0 - o).normalized();
            let brute = (0..500)
                .filter_map(|i| t_box(&boxes[i], o, d).map(|t| (i, t)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            let walked = bvh.nearest(o, d, f64::INFINITY, |k, tb| {
                t_box(&boxes[bvh.order[k] as usize], o, d).filter(|&t| t < tb)
            });
            assert_eq!(brute.map(|b| b.1), walked.map(|w| w.1), "ray {r}");
            let any = bvh.any(o, d, f64::INFINITY, |k| {
                t_box(&boxes[bvh.order[k] as usize], o, d).is_some()
            });
            assert_eq!(any, brute.is_some());
            hits += brute.is_some() as usize;
        }
        assert!(hits > 50, "{hits}");
    }

    /// Thousands of identical boxes (no cut separates them) still give
    /// small leaves and a shallow tree, and the build is the same twice.
    #[test]
    fn identical_items_are_split_by_count_and_the_build_is_deterministic() {
        let boxes = vec![cube(V3::new(0.0, 0.0, 0.0), 1.0); 5000];
        let bvh = Bvh::build(&boxes);
        assert!(bvh
            .nodes
            .iter()
            .all(|n| n.count as usize <= bvh_build::MAX_LEAF));
        // the f32 boxes hold the f64 ones: every item's box in its leaf's
        for n in bvh.nodes.iter().filter(|n| n.count > 0) {
            for k in n.first..n.first + n.count {
                let b = &boxes[bvh.order[k as usize] as usize];
                for a in 0..3 {
                    assert!(f64::from(n.lo[a]) <= b.lo.get(a) && f64::from(n.hi[a]) >= b.hi.get(a));
                }
            }
        }
        assert_eq!(bvh.order, Bvh::build(&boxes).order);
        assert!(Bvh::build(&[])
            .nearest(
                V3::new(0.0, 0.0, 0.0),
                V3::new(0.0, 0.0, 1.0),
                1.0,
                |_, _| Some(0.5)
            )
            .is_none());
    }

    /// The build on two threads makes the tree it makes on one: boxes
    /// enough for the parallel build (more than `PARALLEL_MIN`).
    #[test]
    fn the_tree_does_not_depend_on_the_thread_count() {
        let boxes: Vec<Aabb> = (0..40_000)
            .map(|i| {
                let f = i as f64;
                cube(
                    V3::new((f * 0.37).sin(), (f * 0.91).cos(), (f * 0.13).sin()) * 5.0,
                    0.01 + 0.01 * (f * 0.7).sin().abs(),
                )
            })
            .collect();
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| Bvh::build(&boxes))
        };
        let (one, two) = (on(1), on(2));
        assert_eq!(one.order, two.order);
        assert_eq!(one.nodes, two.nodes);
        assert!(one.nodes.len() > 40_000 / bvh_build::MAX_LEAF);
    }
}
