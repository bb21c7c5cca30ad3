//! A bounding volume hierarchy over boxes: binned surface-area-heuristic
//! build, front-to-back walk. Our own rather than a crate: the tracer works
//! in f64 with its own vector type and hit rules (`Intersect`), and the
//! crates that fit (`bvh`, `obvhs`) bring f32 nalgebra/glam types and
//! their own ray and shape traits; this is ~200 lines, deterministic
//! (sequential build, same tree for the same input) and its cost is
//! measured in `benches/render.rs`.
//!
//! Items are addressed by their position in [`Bvh::order`]: the caller
//! stores them in that order, so that a leaf's items are contiguous.

use super::accel::Aabb;
use crate::math::V3;

/// Items per leaf below which a node is never split.
const LEAF: usize = 2;
/// Items per leaf above which a node is always split (by the median when
/// the heuristic finds no better cut), so that no leaf holds thousands of
/// identical triangles.
const MAX_LEAF: usize = 8;
/// Bins per axis of the binned build.
const BINS: usize = 12;
/// Depth below which the heuristic chooses cuts; deeper, every cut is a
/// median split, which halves the count: so no path is longer than
/// SAH_DEPTH + 64 and the walk's stack of STACK entries never overflows.
const SAH_DEPTH: usize = 32;
const STACK: usize = SAH_DEPTH + 66;

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: [f64; 3],
    hi: [f64; 3],
    /// Leaf: the first item; interior: the left child (the right is next).
    first: u32,
    /// Items of a leaf; 0 for an interior node.
    count: u32,
}

/// The hierarchy; `order[k]` is the input index of the item at position k.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    pub order: Vec<u32>,
}

fn area(lo: [f64; 3], hi: [f64; 3]) -> f64 {
    let d = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    2.0 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0])
}

#[derive(Clone, Copy)]
struct Bin {
    n: usize,
    lo: [f64; 3],
    hi: [f64; 3],
}

const EMPTY: Bin = Bin {
    n: 0,
    lo: [f64::INFINITY; 3],
    hi: [f64::NEG_INFINITY; 3],
};

impl Bin {
    fn add(&mut self, lo: [f64; 3], hi: [f64; 3], n: usize) {
        self.n += n;
        for a in 0..3 {
            self.lo[a] = self.lo[a].min(lo[a]);
            self.hi[a] = self.hi[a].max(hi[a]);
        }
    }
}

impl Bvh {
    /// The hierarchy over `boxes` (finite boxes; an empty list gives an
    /// empty tree that nothing hits).
    pub fn build(boxes: &[Aabb]) -> Bvh {
        let lo: Vec<[f64; 3]> = boxes.iter().map(|b| b.lo.to_array()).collect();
        let hi: Vec<[f64; 3]> = boxes.iter().map(|b| b.hi.to_array()).collect();
        let cent: Vec<[f64; 3]> = (0..boxes.len())
            .map(|i| [0, 1, 2].map(|a| 0.5 * (lo[i][a] + hi[i][a])))
            .collect();
        let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
        let mut nodes = vec![Node {
            lo: [0.0; 3],
            hi: [0.0; 3],
            first: 0,
            count: 0,
        }];
        let mut todo = vec![(0usize, 0usize, boxes.len(), 0usize)];
        while let Some((ni, s, e, depth)) = todo.pop() {
            let mut all = EMPTY;
            let mut cb = EMPTY;
            for &i in &order[s..e] {
                let i = i as usize;
                all.add(lo[i], hi[i], 1);
                cb.add(cent[i], cent[i], 0);
            }
            nodes[ni].lo = all.lo;
            nodes[ni].hi = all.hi;
            let items = &mut order[s..e];
            let mid = if e - s <= LEAF {
                None
            } else if depth >= SAH_DEPTH {
                (e - s > MAX_LEAF).then(|| median(items, &cent, &cb))
            } else {
                let sah = split(items, &lo, &hi, &cent, &cb, area(all.lo, all.hi));
                sah.or_else(|| (e - s > MAX_LEAF).then(|| median(items, &cent, &cb)))
            };
            match mid {
                Some(m) => {
                    let left = nodes.len();
                    nodes.push(nodes[ni]);
                    nodes.push(nodes[ni]);
                    nodes[ni].first = left as u32;
                    nodes[ni].count = 0;
                    todo.push((left, s, s + m, depth + 1));
                    todo.push((left + 1, s + m, e, depth + 1));
                }
                None => {
                    nodes[ni].first = s as u32;
                    nodes[ni].count = (e - s) as u32;
                }
            }
        }
        if boxes.is_empty() {
            nodes[0].lo = [f64::INFINITY; 3];
            nodes[0].hi = [f64::NEG_INFINITY; 3];
        }
        Bvh { nodes, order }
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

    /// Visits the items of the leaves whose boxes the ray meets before the
    /// reach, nearer boxes first; `visit` gives the new reach, or `None`
    /// to stop.
    #[inline(always)]
    fn walk(&self, o: V3, d: V3, t_max: f64, mut visit: impl FnMut(usize) -> Option<f64>) {
        let o = o.to_array();
        let inv = [1.0 / d.x, 1.0 / d.y, 1.0 / d.z];
        let mut reach = t_max;
        let enter = |n: &Node, reach: f64| -> f64 {
            let mut t0: f64 = 0.0;
            let mut t1 = reach;
            for a in 0..3 {
                let ta = (n.lo[a] - o[a]) * inv[a];
                let tb = (n.hi[a] - o[a]) * inv[a];
                t0 = t0.max(ta.min(tb));
                t1 = t1.min(ta.max(tb));
            }
            if t0 <= t1 {
                t0
            } else {
                f64::INFINITY
            }
        };
        let mut stack = [0u32; STACK];
        let mut top = 0;
        let mut node = 0usize;
        if self.order.is_empty() || enter(&self.nodes[0], reach).is_infinite() {
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
                let (tl, tr) = (enter(&self.nodes[l], reach), enter(&self.nodes[r], reach));
                let (near, far, tn, tf) = if tl <= tr {
                    (l, r, tl, tr)
                } else {
                    (r, l, tr, tl)
                };
                if tn.is_finite() {
                    if tf.is_finite() {
                        // the build keeps the depth below STACK
                        stack[top] = far as u32;
                        top += 1;
                    }
                    node = near;
                    continue;
                }
            }
            // next: a farther child left behind, if still in reach
            loop {
                if top == 0 {
                    return;
                }
                top -= 1;
                let k = stack[top] as usize;
                if enter(&self.nodes[k], reach).is_finite() {
                    node = k;
                    break;
                }
            }
        }
    }
}

/// The binned surface-area split of `items`: the count that goes left,
/// after partitioning them, or `None` when no split beats a leaf.
fn split(
    items: &mut [u32],
    lo: &[[f64; 3]],
    hi: &[[f64; 3]],
    cent: &[[f64; 3]],
    cb: &Bin,
    parent_area: f64,
) -> Option<usize> {
    #![allow(clippy::needless_range_loop)] // `a` indexes every point's coordinates
    let n = items.len();
    let mut best: Option<(f64, usize, usize)> = None; // cost, axis, bins on the left
    for a in 0..3 {
        let extent = cb.hi[a] - cb.lo[a];
        if extent.is_nan() || extent <= 0.0 {
            continue;
        }
        let scale = BINS as f64 / extent;
        let bin_of = |i: usize| (((cent[i][a] - cb.lo[a]) * scale) as usize).min(BINS - 1);
        let mut bins = [EMPTY; BINS];
        for &i in items.iter() {
            let i = i as usize;
            bins[bin_of(i)].add(lo[i], hi[i], 1);
        }
        let mut right = [0.0; BINS];
        let mut acc = EMPTY;
        for b in (1..BINS).rev() {
            acc.add(bins[b].lo, bins[b].hi, bins[b].n);
            right[b] = acc.n as f64 * if acc.n > 0 { area(acc.lo, acc.hi) } else { 0.0 };
        }
        let mut left = EMPTY;
        for b in 1..BINS {
            left.add(bins[b - 1].lo, bins[b - 1].hi, bins[b - 1].n);
            if left.n == 0 || left.n == n {
                continue;
            }
            let cost = left.n as f64 * area(left.lo, left.hi) + right[b];
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, a, b));
            }
        }
    }
    let (cost, a, b) = best?;
    // a leaf costs one test per item; a split one box test more per side
    if n <= MAX_LEAF && cost >= (n as f64 - 1.0) * parent_area {
        return None;
    }
    let scale = BINS as f64 / (cb.hi[a] - cb.lo[a]);
    let goes_left =
        |i: u32| ((((cent[i as usize][a] - cb.lo[a]) * scale) as usize).min(BINS - 1)) < b;
    Some(partition(items, goes_left))
}

/// Half the items on each side of the median centroid along the longest
/// axis of the centroids' box.
fn median(items: &mut [u32], cent: &[[f64; 3]], cb: &Bin) -> usize {
    let a = (0..3)
        .max_by(|&x, &y| (cb.hi[x] - cb.lo[x]).total_cmp(&(cb.hi[y] - cb.lo[y])))
        .unwrap_or(0);
    let m = items.len() / 2;
    items.select_nth_unstable_by(m, |&x, &y| {
        cent[x as usize][a]
            .total_cmp(&cent[y as usize][a])
            .then(x.cmp(&y))
    });
    m
}

/// Moves the items `left` accepts to the front; returns their count.
fn partition(items: &mut [u32], left: impl Fn(u32) -> bool) -> usize {
    let mut k = 0;
    for j in 0..items.len() {
        if left(items[j]) {
            items.swap(k, j);
            k += 1;
        }
    }
    k
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
        assert!(bvh.nodes.iter().all(|n| n.count as usize <= MAX_LEAF));
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
}
