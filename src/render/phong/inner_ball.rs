//! A ball inside a closed mesh, found once per mesh (`trimesh.rs`): a
//! shadow ray that starts outside the mesh's bounding sphere and reaches
//! into the ball must cross the mesh's surface on the way, so it is
//! blocked without a walk of the BVH. Most shadow rays that a solid object
//! casts on the floor go through its middle, and this answers them at the
//! price of one sphere test.
//!
//! The ball is kept only when that is certain: the mesh is closed (every
//! edge, its ends welded by position, is shared by an even number of
//! triangles, so the surface divides space into an inside and an outside,
//! as a parity of crossings), the centre is inside (an odd number of
//! crossings along each of three rays) and no triangle comes nearer the
//! centre than the radius. Otherwise there is no ball, and every shadow
//! ray walks the tree as before.

use crate::math::V3;
use rayon::prelude::*;

/// The ball: centre and radius, in the mesh's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ball {
    pub c: V3,
    pub r: f64,
}

/// Rays along which the centre's crossings are counted: three
/// directions in no special relation to the axes or to each other, so
/// that a mesh aligned with the axes is not grazed along an edge by all
/// three.
const PROBES: [[f64; 3]; 3] = [
    [0.5727, 0.6181, -0.5385],
    [-0.3119, 0.8464, 0.4317],
    [0.7013, -0.2958, 0.6421],
];

/// The largest ball, of two candidate centres (the bounding box's and the
/// vertices' mean), inside the closed mesh of `positions` and `triangles`;
/// `crossings(o, d)` counts the triangles the ray o + t d (t > 0) meets and
/// `distance(c)` is the distance from c to the nearest triangle (both
/// asked of the caller's BVH).
/// `None` when the mesh is not closed or neither centre is inside.
pub fn find(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    bounds: (V3, V3),
    crossings: impl Fn(V3, V3) -> usize,
    distance: impl Fn(V3) -> f64,
) -> Option<Ball> {
    if !closed(positions, triangles) {
        return None;
    }
    let n = positions.len().max(1) as f64;
    let mean = positions
        .iter()
        .fold(V3::new(0.0, 0.0, 0.0), |s, &p| s + V3::from(p))
        / n;
    let size = (bounds.1 - bounds.0).length();
    [(bounds.0 + bounds.1) * 0.5, mean]
        .into_iter()
        .filter(|&c| PROBES.iter().all(|&d| crossings(c, V3::from(d)) % 2 == 1))
        .filter_map(|c| {
            // shrunk far beyond rounding error, so that the ball stays off
            // the surface in whatever frame the test is made
            let r = distance(c) * (1.0 - 1e-6) - 1e-9 * size;
            (r > 1e-6 * size).then_some(Ball { c, r })
        })
        .max_by(|a, b| a.r.total_cmp(&b.r))
}

/// True when every edge of the mesh, its ends welded by position, is
/// shared by an even number of triangles (a closed surface, mod 2). Asked
/// of the vertices as numbered first: a well-made closed mesh passes
/// there, and only one that does not has its vertices welded (seams).
fn closed(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> bool {
    let n = positions.len();
    if even_edges(n, triangles, |i| i) {
        return true;
    }
    // vertices at the same point get one id: the first of them in an order
    // by position (-0 and +0 alike)
    let key = |i: u32| positions[i as usize].map(|x| (x + 0.0).to_bits());
    let mut by_pos: Vec<u32> = (0..positions.len() as u32).collect();
    by_pos.par_sort_unstable_by_key(|&i| (key(i), i));
    let mut id = vec![0u32; positions.len()];
    for (k, &i) in by_pos.iter().enumerate() {
        let same = k > 0 && key(by_pos[k - 1]) == key(i);
        id[i as usize] = if same { id[by_pos[k - 1] as usize] } else { i };
    }
    even_edges(n, triangles, |i| id[i as usize])
}

/// True when every edge, its ends numbered by `id` (each below `n`), is
/// shared by an even number of triangles. The edges are bucketed by
/// their lower end (a counting sort, linear in the edges), then each
/// vertex's few are sorted and counted. Side by side with the comparison
/// sort it replaced, the build of a 1.3 M-triangle mesh was not
/// measurably faster (docs/benchmarks.md).
fn even_edges(n: usize, triangles: &[[u32; 3]], id: impl Fn(u32) -> u32) -> bool {
    let edges = |t: &[u32; 3]| {
        let v = t.map(&id);
        [(v[0], v[1]), (v[1], v[2]), (v[2], v[0])]
            .into_iter()
            .filter(|(a, b)| a != b)
            .map(|(a, b)| (a.min(b) as usize, a.max(b)))
    };
    let mut start = vec![0usize; n + 1];
    for (a, _) in triangles.iter().flat_map(edges) {
        start[a + 1] += 1;
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    let mut fill = start.clone();
    let mut upper = vec![0u32; start[n]];
    for (a, b) in triangles.iter().flat_map(edges) {
        upper[fill[a]] = b;
        fill[a] += 1;
    }
    (0..n).all(|a| {
        let ends = &mut upper[start[a]..start[a + 1]];
        ends.sort_unstable();
        ends.chunk_by(|x, y| x == y).all(|run| run.len() % 2 == 0)
    })
}

/// The distance from `p` to the triangle abc.
pub fn triangle_distance(p: V3, a: V3, b: V3, c: V3) -> f64 {
    (closest_on_triangle(p, a, b, c) - p).length()
}

/// The point of triangle abc nearest p: by which of its seven regions
/// (inside, three edges, three corners) p projects into.
fn closest_on_triangle(p: V3, a: V3, b: V3, c: V3) -> V3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom == 0.0 {
        // a degenerate triangle: its corners are as near as it gets here
        return [a, b, c]
            .into_iter()
            .min_by(|x, y| (*x - p).length().total_cmp(&(*y - p).length()))
            .unwrap_or(a);
    }
    a + ab * (vb / denom) + ac * (vc / denom)
}

/// True when the segment from `o` along `d` (not unit) over (0, t_max)
/// reaches into `ball`, for a start outside it.
#[inline]
pub fn reaches(ball: &Ball, o: V3, d: V3, t_max: f64) -> bool {
    let oc = o - ball.c;
    let b = oc.dot(d);
    if b >= 0.0 {
        return false; // heading away
    }
    let a = d.dot(d);
    let disc = b * b - a * (oc.dot(oc) - ball.r * ball.r);
    disc > 0.0 && (-b - disc.sqrt()) < t_max * a
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed box of twelve triangles, and the same with one missing.
    fn cube() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let p = (0..8)
            .map(|k| [0, 1, 2].map(|a| if k >> a & 1 == 0 { -1.0 } else { 1.0 }))
            .collect();
        (p, super::super::trimesh::cube_triangles())
    }

    /// Crossings by brute force, Möller–Trumbore over every triangle.
    fn count(p: &[[f64; 3]], t: &[[u32; 3]], o: V3, d: V3) -> usize {
        t.iter()
            .filter(|t| {
                let [a, b, c] = t.map(|i| V3::from(p[i as usize]));
                let (e1, e2) = (b - a, c - a);
                let q = d.cross(e2);
                let det = e1.dot(q);
                let s = o - a;
                let u = s.dot(q) / det;
                let r = s.cross(e1);
                let v = d.dot(r) / det;
                u >= 0.0 && v >= 0.0 && u + v <= 1.0 && e2.dot(r) / det > 0.0
            })
            .count()
    }

    /// The distance to the nearest triangle by brute force.
    fn near(p: &[[f64; 3]], t: &[[u32; 3]], c: V3) -> f64 {
        t.iter()
            .map(|t| {
                let [a, b, d] = t.map(|i| V3::from(p[i as usize]));
                triangle_distance(c, a, b, d)
            })
            .fold(f64::INFINITY, f64::min)
    }

    fn bounds() -> (V3, V3) {
        (V3::new(-1.0, -1.0, -1.0), V3::new(1.0, 1.0, 1.0))
    }

    #[test]
    fn a_closed_box_holds_a_ball_as_wide_as_the_box_and_an_open_one_none() {
        let (p, t) = cube();
        let ball = find(
            &p,
            &t,
            bounds(),
            |o, d| count(&p, &t, o, d),
            |c| near(&p, &t, c),
        )
        .expect("a closed box");
        assert!(
            ball.c.length() < 1e-12 && ball.r > 0.999 && ball.r < 1.0,
            "{ball:?}"
        );
        let open = &t[1..];
        assert!(find(
            &p,
            open,
            bounds(),
            |o, d| count(&p, open, o, d),
            |c| near(&p, open, c)
        )
        .is_none());
    }

    /// Vertices repeated at the same point (a seam) still close the
    /// surface; a centre outside the surface (two boxes apart) gives none.
    #[test]
    fn seams_are_welded_and_a_centre_outside_gives_no_ball() {
        let (mut p, mut t) = cube();
        let n = p.len() as u32;
        p.extend_from_within(..);
        for tri in t.iter_mut().skip(6) {
            *tri = tri.map(|i| i + n);
        }
        assert!(find(
            &p,
            &t,
            bounds(),
            |o, d| count(&p, &t, o, d),
            |c| near(&p, &t, c)
        )
        .is_some());
        let (mut p, mut t) = cube();
        let moved: Vec<[f64; 3]> = p.iter().map(|v| [v[0] + 3.0, v[1], v[2]]).collect();
        p.iter_mut().for_each(|v| v[0] -= 3.0);
        t.extend(t.clone().iter().map(|x| x.map(|i| i + 8)));
        p.extend(moved);
        let b = (V3::new(-4.0, -1.0, -1.0), V3::new(4.0, 1.0, 1.0));
        assert!(find(&p, &t, b, |o, d| count(&p, &t, o, d), |c| near(&p, &t, c)).is_none());
    }

    #[test]
    fn the_nearest_point_is_found_in_every_region_of_a_triangle() {
        let (a, b, c) = (
            V3::new(0.0, 0.0, 0.0),
            V3::new(2.0, 0.0, 0.0),
            V3::new(0.0, 2.0, 0.0),
        );
        let near = |x: f64, y: f64| closest_on_triangle(V3::new(x, y, 1.0), a, b, c);
        assert_eq!(near(0.5, 0.5), V3::new(0.5, 0.5, 0.0));
        assert_eq!(near(-1.0, -1.0), a);
        assert_eq!(near(3.0, -1.0), b);
        assert_eq!(near(-1.0, 3.0), c);
        assert_eq!(near(1.0, -1.0), V3::new(1.0, 0.0, 0.0));
        assert_eq!(near(-1.0, 1.0), V3::new(0.0, 1.0, 0.0));
        assert_eq!(near(2.0, 2.0), V3::new(1.0, 1.0, 0.0));
    }

    #[test]
    fn a_segment_reaches_the_ball_only_when_it_gets_there() {
        let ball = Ball {
            c: V3::new(0.0, 0.0, 0.0),
            r: 1.0,
        };
        let o = V3::new(0.0, 0.0, 5.0);
        let d = V3::new(0.0, 0.0, -2.0); // not unit: t counts in 2s
        assert!(reaches(&ball, o, d, 2.1));
        assert!(!reaches(&ball, o, d, 1.9));
        assert!(!reaches(&ball, o, -d, 100.0));
        assert!(!reaches(&ball, o, V3::new(1.0, 0.0, -2.0), 100.0));
    }
}
