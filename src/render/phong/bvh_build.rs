//! The build of a bounding volume hierarchy (`bvh.rs`): binned surface-area
//! heuristic, the items' boxes moved with them (contiguous, read in order)
//! and each node's bins filled for the three axes in one pass. Subtrees of
//! many items are built on two threads (`rayon::join`) and joined in a
//! fixed order, so that the tree is the same whatever the thread count.

/// Items per leaf below which a node is never split.
const LEAF: usize = 2;
/// Items per leaf above which a node is always split (by the median when
/// the heuristic finds no better cut), so that no leaf holds thousands of
/// identical triangles.
pub const MAX_LEAF: usize = 8;
/// Bins per axis of the binned build.
const BINS: usize = 12;
/// Depth below which the heuristic chooses cuts; deeper, every cut is a
/// median split, which halves the count: so no path is longer than
/// SAH_DEPTH + 64 and the walk's stack never overflows.
pub const SAH_DEPTH: usize = 32;
/// Subtrees of fewer items are built on one thread: below this, handing
/// the work over costs more than it saves.
const PARALLEL_MIN: usize = 1 << 14;

/// A node of the tree: its box; a leaf's items or an interior node's
/// children.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    /// Leaf: the first item; interior: the left child (the right is next).
    pub first: u32,
    /// Items of a leaf; 0 for an interior node.
    pub count: u32,
}

impl Node {
    pub const EMPTY: Node = Node {
        lo: [0.0; 3],
        hi: [0.0; 3],
        first: 0,
        count: 0,
    };
}

/// An item's box and its input index.
#[derive(Clone, Copy, Debug)]
pub struct Item {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    pub index: u32,
}

impl Item {
    #[inline(always)]
    fn centre(&self, a: usize) -> f64 {
        0.5 * (self.lo[a] + self.hi[a])
    }
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
    #[inline(always)]
    fn add(&mut self, lo: [f64; 3], hi: [f64; 3], n: usize) {
        self.n += n;
        for a in 0..3 {
            self.lo[a] = self.lo[a].min(lo[a]);
            self.hi[a] = self.hi[a].max(hi[a]);
        }
    }
}

/// The tree over `items` (reordered: a leaf's items are contiguous), its
/// root first; a node's children are a pair, the left at `first`.
pub fn tree(items: &mut [Item]) -> Vec<Node> {
    subtree(items, 0, 0)
}

/// The subtree over `items`, which sit at positions `offset..` of the
/// whole list; its root first, its interior nodes' `first` counted
/// within the returned list.
fn subtree(items: &mut [Item], offset: usize, depth: usize) -> Vec<Node> {
    if items.len() < PARALLEL_MIN {
        return sequential(items, offset, depth);
    }
    let (node, cut) = cut(items, depth);
    let Some(m) = cut else {
        return sequential(items, offset, depth);
    };
    let (l, r) = items.split_at_mut(m);
    let (ln, rn) = rayon::join(
        || subtree(l, offset, depth + 1),
        || subtree(r, offset + m, depth + 1),
    );
    // [root, left root, right root, rest of left, rest of right]
    let (base_l, base_r) = (3, 3 + ln.len() - 1);
    let moved = |n: Node, base: usize| -> Node {
        if n.count > 0 {
            n
        } else {
            Node {
                first: (base + n.first as usize - 1) as u32,
                ..n
            }
        }
    };
    let mut out = Vec::with_capacity(1 + ln.len() + rn.len());
    out.push(Node {
        first: 1,
        count: 0,
        ..node
    });
    out.push(moved(ln[0], base_l));
    out.push(moved(rn[0], base_r));
    out.extend(ln[1..].iter().map(|&n| moved(n, base_l)));
    out.extend(rn[1..].iter().map(|&n| moved(n, base_r)));
    out
}

/// The subtree over `items` on this thread, node pairs in the order of
/// a stack of pending ranges.
fn sequential(items: &mut [Item], offset: usize, depth: usize) -> Vec<Node> {
    let mut nodes = vec![Node::EMPTY];
    let mut todo = vec![(0usize, 0usize, items.len(), depth)];
    while let Some((ni, s, e, depth)) = todo.pop() {
        let (node, cut) = cut(&mut items[s..e], depth);
        nodes[ni] = node;
        match cut {
            Some(m) => {
                let left = nodes.len();
                nodes.push(Node::EMPTY);
                nodes.push(Node::EMPTY);
                nodes[ni].first = left as u32;
                nodes[ni].count = 0;
                todo.push((left, s, s + m, depth + 1));
                todo.push((left + 1, s + m, e, depth + 1));
            }
            None => {
                nodes[ni].first = (offset + s) as u32;
                nodes[ni].count = (e - s) as u32;
            }
        }
    }
    nodes
}

/// The node over `items` (its bounds) and where they are cut, after
/// reordering them: the count that goes left, or `None` for a leaf.
fn cut(items: &mut [Item], depth: usize) -> (Node, Option<usize>) {
    let mut all = EMPTY;
    let mut cb = EMPTY;
    for it in items.iter() {
        all.add(it.lo, it.hi, 1);
        let c = [0, 1, 2].map(|a| it.centre(a));
        cb.add(c, c, 0);
    }
    let node = Node {
        lo: all.lo,
        hi: all.hi,
        first: 0,
        count: 0,
    };
    let n = items.len();
    let mid = if n <= LEAF {
        None
    } else if depth >= SAH_DEPTH {
        (n > MAX_LEAF).then(|| median(items, &cb))
    } else {
        split(items, &cb, area(all.lo, all.hi))
            .or_else(|| (n > MAX_LEAF).then(|| median(items, &cb)))
    };
    (node, mid)
}

/// The bin of centre coordinate `c` along an axis starting at `lo`.
#[inline(always)]
fn bin_of(c: f64, lo: f64, scale: f64) -> usize {
    (((c - lo) * scale) as usize).min(BINS - 1)
}

/// The binned surface-area split of `items`: the count that goes left,
/// after partitioning them, or `None` when no split beats a leaf.
fn split(items: &mut [Item], cb: &Bin, parent_area: f64) -> Option<usize> {
    let n = items.len();
    let scale = [0, 1, 2].map(|a| {
        let extent = cb.hi[a] - cb.lo[a];
        if extent > 0.0 {
            BINS as f64 / extent
        } else {
            0.0 // a flat axis: every centre in bin 0, no cut found on it
        }
    });
    let mut bins = [[EMPTY; BINS]; 3];
    for it in items.iter() {
        for a in 0..3 {
            bins[a][bin_of(it.centre(a), cb.lo[a], scale[a])].add(it.lo, it.hi, 1);
        }
    }
    let mut best: Option<(f64, usize, usize)> = None; // cost, axis, bins on the left
    for (a, bins) in bins.iter().enumerate() {
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
    let (lo, s) = (cb.lo[a], scale[a]);
    Some(partition(items, |it| bin_of(it.centre(a), lo, s) < b))
}

/// Half the items on each side of the median centre along the longest
/// axis of the centres' box (ties by input index: the same cut always).
fn median(items: &mut [Item], cb: &Bin) -> usize {
    let a = (0..3)
        .max_by(|&x, &y| (cb.hi[x] - cb.lo[x]).total_cmp(&(cb.hi[y] - cb.lo[y])))
        .unwrap_or(0);
    let m = items.len() / 2;
    items.select_nth_unstable_by(m, |x, y| {
        x.centre(a)
            .total_cmp(&y.centre(a))
            .then(x.index.cmp(&y.index))
    });
    m
}

/// Moves the items `left` accepts to the front; returns their count.
fn partition(items: &mut [Item], left: impl Fn(&Item) -> bool) -> usize {
    let mut k = 0;
    for j in 0..items.len() {
        if left(&items[j]) {
            items.swap(k, j);
            k += 1;
        }
    }
    k
}
