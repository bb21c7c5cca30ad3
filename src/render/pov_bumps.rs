//! A tangent-space normal map as POV-Ray can draw it on a planar map or
//! a sphere: a height field whose slopes are the map's. POV-Ray's
//! `normal` takes a pattern's gradient (four samples `accuracy` apart),
//! adds it to the surface normal and renormalises; the built-in tracer
//! turns the map's vector (x, y, z) into x T + y B + z N
//! (`render/phong/normal_map.rs`). The two agree when the gradient is
//! G = (x/z) T + (y/z) B, so the height's slope along each map direction
//! is fixed by each texel, and the height itself is their least-squares
//! integral: over the repeating tile (`heights`: a periodic Poisson
//! equation, solved exactly by the discrete Fourier transform), or over
//! the sphere's longitude and latitude (`sphere_heights`), which POV-Ray
//! reads as a spherical image of the point's direction. A map that is a
//! height field's (bumps, grain, a scan's relief) is drawn as given; the
//! part of another that no height field has (a twist of the normals, a
//! tilt of the whole tile, a flat tile's map wrapped on a sphere, whose
//! east steps shrink towards the poles) is lost, which the solve reports;
//! such a map is then baked into a mesh (`pov_mesh_bumps`), but on a plane.
//! A sphere's other maps are laid over it the same way (`over_sphere`), so
//! that all its patterns are one spherical image and nest.
//!
//! The height is laid out `FINE` times finer than the map: POV-Ray's
//! bilinear pattern has a slope that is constant across each cell, where
//! the built-in tracer interpolates the vectors themselves. At most
//! `MAX_SIDE` texels a side, which bounds the solve's memory (about 100
//! bytes a texel: 100 MB for 1024 x 1024).

use super::recent::Recent;
use crate::math::V3;
use crate::scene::texture::{self, MapKind, Texels, TextureRef};
use crate::scene::Shape;
use rustfft::num_complex::Complex;
use rustfft::FftPlanner;
use std::sync::Arc;

/// The height field is laid out this many times finer than the map, at
/// most `MAX_SIDE` texels a side.
const FINE: u32 = 4;
const MAX_SIDE: u32 = 1024;

/// Below this the map's z is taken as this: a vector in or under the
/// tangent plane has no slope a height field can take.
const MIN_Z: f64 = 0.02;

/// The largest share of a normal map's slopes (root mean square) that
/// its height field may miss for POV-Ray to draw it: on the test scenes
/// a map a height field's within 0.6 % agreed with the built-in tracer
/// as a flat surface does, one stretched unevenly (20-45 % missed) was
/// 1-4 % off over the image. A map is refused above it.
pub const MAX_MISSED: f64 = 0.05;

/// A misfit of at most this slope (root mean square, about 0.6 degrees:
/// less than one 8-bit level of a map's x or y) is drawn whatever its
/// share: a flat map written at 16 bits is a tilt of 1e-5 everywhere,
/// all of which no height has.
pub const MIN_SLOPE: f64 = 0.01;

/// Whether a normal map is refused: a share `h.missed` above
/// `MAX_MISSED` that is more than `MIN_SLOPE` of slope.
pub fn refused(h: &Heights) -> bool {
    h.missed > MAX_MISSED && h.missed * h.slope > MIN_SLOPE
}

/// Why a normal map is refused whose slopes are `missed` away from any
/// height field's on its surface (the caller names the field).
pub fn not_a_height_field(missed: f64) -> String {
    format!(
        "{:.0} % of its slopes are not a height field's on this surface (at most {:.0} %: a map stretched unevenly by `scale` or the shape, a flat tile's map on a sphere, or twisted), and POV-Ray draws a plane's normal map as a height's gradient (a quad's, box's, sphere's or mesh's it bakes into triangles, but a plane has no end); use phong, blender or mitsuba, a map made for this scale, or a quad",
        100.0 * missed,
        100.0 * MAX_MISSED
    )
}

/// How a normal map lies on its shape: a planar map's frame, or a
/// sphere's radius and the map's `scale` (the map repeated that many
/// times around and up the sphere's longitude and latitude).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lay {
    Planar(Frame),
    Sphere { radius: f64, scale: [f64; 2] },
}

impl Lay {
    /// The numbers that decide a height field, as bits (a cache key).
    pub fn bits(&self) -> [u64; 5] {
        let b = f64::to_bits;
        match *self {
            Lay::Planar([a, c, d, e]) => [0, b(a), b(c), b(d), b(e)],
            Lay::Sphere { radius, scale } => [1, b(radius), b(scale[0]), b(scale[1]), 0],
        }
    }
}

/// How a map at `scale` lies on `shape` for its height field: a plane,
/// a quad or a sphere; None on a box (laid face by face, `Shape::faces`)
/// or a mesh (refused).
pub fn laid(shape: &Shape, scale: [f64; 2]) -> Option<Lay> {
    match *shape {
        Shape::Sphere { radius, .. } => Some(Lay::Sphere { radius, scale }),
        _ => planar_frame(shape, scale).map(Lay::Planar),
    }
}

/// What a normal map's height field is kept by: its file, `range` and
/// lay.
type Key = (String, [u64; 2], [u64; 5]);

fn key(t: &TextureRef, lay: Lay) -> Key {
    (
        t.file().to_string(),
        t.range().map(f64::to_bits),
        lay.bits(),
    )
}

/// The height field of the normal map `t` (read as the scene reads it,
/// its `range` applied) as it lies (`lay`). The last few are kept for
/// the map's writer (`PovMaps`) and the refusal check; each is solved
/// once. At most 4 x 8 MB (`MAX_SIDE` squared values).
pub fn solved(t: &TextureRef, lay: Lay) -> Result<Arc<Heights>, String> {
    static FIELDS: Recent<Key, Arc<Heights>> = Recent::new(4);
    FIELDS.get_or(key(t, lay), || {
        let texels = texture::get(std::path::Path::new(t.file()), t.encoding(MapKind::Normal))?;
        Ok(Arc::new(match lay {
            Lay::Planar(frame) => heights(&texels, t.range(), frame),
            Lay::Sphere { radius, scale } => sphere_heights(&texels, t.range(), radius, scale),
        }))
    })
}

/// The share of its slopes the height field of normal map `t` as it
/// lies misses when it is refused (`refused`), else None. The refusal check
/// (`maps::povray_refusals`) asks for every map on every render of a
/// fit: the answers are kept for more maps (16) than the fields are, so
/// a scene with many maps does not solve each again on each render.
pub fn missed(t: &TextureRef, lay: Lay) -> Result<Option<f64>, String> {
    static SHARES: Recent<Key, Option<f64>> = Recent::new(16);
    SHARES.get_or(key(t, lay), || {
        solved(t, lay).map(|h| refused(&h).then_some(h.missed))
    })
}

/// A planar map's frame (None on a sphere, box or mesh): from the world
/// vectors of the map's coordinates at its `scale` and the normal.
fn planar_frame(shape: &Shape, scale: [f64; 2]) -> Option<Frame> {
    let v = V3::from;
    let (eu, ev, n) = match *shape {
        Shape::Plane { normal, .. } => {
            let (eu, ev) = texture::uv::plane_axes(v(normal));
            (eu, ev, v(normal).normalized())
        }
        Shape::Quad { edge_u, edge_v, .. } => {
            let n = v(edge_u).cross(v(edge_v)).normalized();
            (v(edge_u), v(edge_v), n)
        }
        _ => return None,
    };
    let es = (eu / scale[0]).to_array();
    let et = (ev / scale[1]).to_array();
    frame(es, et, n.to_array())
}

/// A planar map's frame: the world vectors one unit of the map's
/// coordinates moves along its s (u x scale) and t (v x scale)
/// directions, dotted with the built-in tracer's T and B there:
/// `[T.Es, B.Es, T.Et, B.Et]`.
pub type Frame = [f64; 4];

/// The frame of a planar map with world vectors `es`, `et` per unit of
/// the map's coordinates and unit normal `n`, as the built-in tracer
/// takes it: T along es in the plane, B = n x T turned towards et.
pub fn frame(es: [f64; 3], et: [f64; 3], n: [f64; 3]) -> Option<Frame> {
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let len = dot(es, es).sqrt();
    if !(len > 0.0 && len.is_finite()) {
        return None;
    }
    let t = es.map(|x| x / len);
    let mut b = [
        n[1] * t[2] - n[2] * t[1],
        n[2] * t[0] - n[0] * t[2],
        n[0] * t[1] - n[1] * t[0],
    ];
    if dot(b, et) < 0.0 {
        b = b.map(|x| -x);
    }
    Some([dot(t, es), dot(b, es), dot(t, et), dot(b, et)])
}

/// A height field: `width` x `height` values, rows top to bottom (as the
/// map's), in world length; the share of the map's slopes it misses
/// (the root-mean-square misfit over the root-mean-square slope), and
/// that slope (rise over run on the surface).
pub struct Heights {
    pub width: u32,
    pub height: u32,
    pub values: Vec<f64>,
    pub missed: f64,
    pub slope: f64,
}

impl Heights {
    /// A solved field, from its weighed squared misfit and slopes
    /// (`misfit`, `total`) and its mean squared slope.
    fn of(
        width: u32,
        height: u32,
        values: Vec<f64>,
        (misfit, total): (f64, f64),
        slope2: f64,
    ) -> Heights {
        Heights {
            width,
            height,
            values,
            missed: if total > 0.0 {
                (misfit / total).sqrt()
            } else {
                0.0
            },
            slope: slope2.sqrt(),
        }
    }
}

/// The height field whose slopes best match the normal map `texels`,
/// each value read as `lo + v (hi - lo)` for `range` [lo, hi] as the
/// built-in tracer reads it, in `frame`, wrapped as the map repeats.
pub fn heights(texels: &Texels, range: [f64; 2], frame: Frame) -> Heights {
    // A map larger than `MAX_SIDE` is sampled at it: the memory stays
    // bounded whatever the file (up to `texture::read::MAX_TEXTURE_SIDE`).
    let f = FINE.min((MAX_SIDE / texels.width.max(texels.height).max(1)).max(1));
    let (w, h) = (
        (texels.width * f).min(MAX_SIDE),
        (texels.height * f).min(MAX_SIDE),
    );
    let (wn, hn) = (w as usize, h as usize);
    // Slopes along +s and along +t (per unit of the map's coordinates) at
    // (s, t), from the bilinear lookup as the built-in tracer reads it.
    let slope = |s: f64, t: f64| {
        let (gx, gy) = gradient(texels, range, s, t);
        let [ts, bs, tt, bt] = frame;
        (gx * ts + gy * bs, gx * tt + gy * bt, gx * gx + gy * gy)
    };
    let mut slope2 = 0.0;
    // Height differences wanted between neighbours: to the right, along
    // +s; and down a row, along -t. The surface's gradient is -G, so
    // each slope is taken with its sign turned.
    let mut dx = vec![0.0; wn * hn];
    let mut dy = vec![0.0; wn * hn];
    for r in 0..hn {
        for i in 0..wn {
            let s = (i as f64 + 0.5) / w as f64;
            let t = 1.0 - (r as f64 + 0.5) / h as f64;
            dx[r * wn + i] = -slope(s + 0.5 / w as f64, t).0 / w as f64;
            dy[r * wn + i] = slope(s, t - 0.5 / h as f64).1 / h as f64;
            slope2 += slope(s, t).2;
        }
    }
    // Each difference is weighed as the slope it stands for: over the
    // world length of its step (along s |Es|/w, along t |Et|/h), so a map
    // or a tile longer one way than the other counts both directions
    // alike. `beta`: the weight of a step along t over one along s.
    let [ts, bs, tt, bt] = frame;
    let step_s = (ts * ts + bs * bs).sqrt() / w as f64;
    let step_t = (tt * tt + bt * bt).sqrt() / h as f64;
    let beta = (step_s / step_t).powi(2);
    let steps = Steps {
        w: wn,
        dx,
        dy,
        ws: vec![1.0; hn],
        wt: vec![beta; hn],
    };
    let values = periodic_poisson(&steps.rhs(), wn, hn, beta);
    let fit = steps.misfit(&values);
    Heights::of(w, h, values, fit, slope2 / (wn * hn) as f64)
}

/// The built-in tracer's gradient G = (x/z, y/z) in its tangent frame
/// (T, B) for the normal map `texels` at (s, t), `range` applied.
fn gradient(texels: &Texels, [lo, hi]: [f64; 2], s: f64, t: f64) -> (f64, f64) {
    let [r, g, b] = texels
        .sample(s, t)
        .map(|c| 2.0 * (lo + c as f64 * (hi - lo)) - 1.0);
    let z = b.max(MIN_Z);
    (r / z, g / z)
}

/// Most texels a side of a map laid over a sphere (`over_sphere`): 200 MB
/// of colour at most, and `pov_maps::get` holds it again in f64 while it
/// writes the channels (400 MB more: 600 MB at the peak).
const MAX_LAID: u32 = 4096;

/// The map `texels` repeated `scale` times around and up a sphere, laid
/// out over its whole longitude (columns) and latitude (rows from the
/// north pole down) as the normal map's heights are (`sphere_heights`),
/// so that every map of a sphere with a normal map is one spherical
/// image about its centre: its patterns then sit in one space, the
/// point's, and nest in each other's textures, where `uv_mapping` hands
/// a nested pattern the surface's coordinates. At a whole `scale` it is
/// the texels repeated, so POV-Ray's bilinear lookup gives what it gives
/// on the map itself; otherwise sampled `FINE` times finer. At most
/// `MAX_LAID` a side (a larger one is sampled down to it).
pub fn over_sphere(texels: &Texels, scale: [f64; 2]) -> Arc<Texels> {
    let reps = scale.map(|x| x.abs().ceil().max(1.0) as u32);
    let (tw, th) = (texels.width * reps[0], texels.height * reps[1]);
    let whole = scale.iter().all(|x| x.abs().fract() == 0.0);
    let f = match whole {
        true => 1,
        false => FINE.min((MAX_LAID / tw.max(th).max(1)).max(1)),
    };
    let (w, h) = ((tw * f).min(MAX_LAID), (th * f).min(MAX_LAID));
    let mut values = Vec::with_capacity(3 * (w * h) as usize);
    for r in 0..h {
        let v = 1.0 - (r as f64 + 0.5) / h as f64;
        for i in 0..w {
            let u = (i as f64 + 0.5) / w as f64;
            values.extend(texels.sample(u * scale[0], v * scale[1]));
        }
    }
    Arc::new(Texels {
        width: w,
        height: h,
        values,
    })
}

/// The height field of the normal map `texels` on a sphere of `radius`,
/// the map repeated `scale` times around and up it, laid out over the
/// whole sphere by longitude (u, columns, wrapping) and latitude (v, rows
/// from the north pole down) as POV-Ray's spherical `map_type 1` reads
/// an image. The built-in tracer's frame there is T east (|dP/du| =
/// 2 pi r cos(lat)) and B north (|dP/dv| = pi r). Each difference is
/// weighed as the slope it stands for over the area it covers, so a row
/// near a pole, whose steps are short and its area small, neither
/// dominates nor vanishes; the solve is exact (`sphere_poisson`).
pub fn sphere_heights(texels: &Texels, range: [f64; 2], radius: f64, scale: [f64; 2]) -> Heights {
    let reps = scale.map(|x| x.abs().ceil().max(1.0) as u32);
    let (tw, th) = (texels.width * reps[0], texels.height * reps[1]);
    let f = FINE.min((MAX_SIDE / tw.max(th).max(1)).max(1));
    let (w, h) = ((tw * f).min(MAX_SIDE), (th * f).clamp(2, MAX_SIDE));
    let (wn, hn) = (w as usize, h as usize);
    let pi = std::f64::consts::PI;
    let cos_lat = |v: f64| (pi * (v - 0.5)).cos().max(0.0);
    let g = |u: f64, v: f64| gradient(texels, range, u * scale[0], v * scale[1]);
    // Row r's centre is at v = 1 - (r + 0.5) / h; the edge below it at
    // 1 - (r + 1) / h. Weights are those of slopes over area, in units
    // of a latitude step's: along a row (w / 2h)^2 / cos, down cos.
    let v_row = |r: usize| 1.0 - (r as f64 + 0.5) / h as f64;
    let v_edge = |r: usize| 1.0 - (r as f64 + 1.0) / h as f64;
    let ratio = (w as f64 / (2.0 * h as f64)).powi(2);
    let ws: Vec<f64> = (0..hn).map(|r| ratio / cos_lat(v_row(r))).collect();
    // The edges below the last row and above the first are the poles:
    // no difference crosses them.
    let wt: Vec<f64> = (0..hn)
        .map(|r| match r + 1 < hn {
            true => cos_lat(v_edge(r)),
            false => 0.0,
        })
        .collect();
    let (mut dx, mut dy) = (vec![0.0; wn * hn], vec![0.0; wn * hn]);
    let (mut slope2, mut area) = (0.0, 0.0);
    for r in 0..hn {
        for i in 0..wn {
            let u = (i as f64 + 0.5) / w as f64;
            let (v, ve) = (v_row(r), v_edge(r));
            // Heights in world length: east per column 2 pi r cos / w,
            // north per row pi r / h; down a row is south.
            let east = 2.0 * pi * radius * cos_lat(v) / w as f64;
            dx[r * wn + i] = -g(u + 0.5 / w as f64, v).0 * east;
            dy[r * wn + i] = g(u, ve).1 * pi * radius / h as f64;
            let (gx, gy) = g(u, v);
            slope2 += cos_lat(v) * (gx * gx + gy * gy);
            area += cos_lat(v);
        }
    }
    let steps = Steps {
        w: wn,
        dx,
        dy,
        ws,
        wt,
    };
    let values = sphere_poisson(&steps.rhs(), wn, &steps.ws, &steps.wt);
    let fit = steps.misfit(&values);
    Heights::of(w, h, values, fit, slope2 / area.max(1e-12))
}

/// The height differences wanted between neighbours on a grid of `w`
/// columns (rows top to bottom), and their weights: `dx` to the right
/// (columns wrap), weighed `ws[r]` in row r; `dy` down a row, weighed
/// `wt[r]` below row r, the last row's wrapping to the first (weight 0
/// where the rows do not wrap: a sphere's poles).
struct Steps {
    w: usize,
    dx: Vec<f64>,
    dy: Vec<f64>,
    ws: Vec<f64>,
    wt: Vec<f64>,
}

impl Steps {
    /// The right-hand side of the least squares' normal equations: per
    /// value, ws (2 x - left - right) + wt[up] (x - up) + wt (x - down).
    fn rhs(&self) -> Vec<f64> {
        let (w, h) = (self.w, self.ws.len());
        let mut b = vec![0.0; w * h];
        for r in 0..h {
            let up = (r + h - 1) % h;
            for i in 0..w {
                let left = r * w + (i + w - 1) % w;
                b[r * w + i] = self.ws[r] * (self.dx[left] - self.dx[r * w + i])
                    + self.wt[up] * self.dy[up * w + i]
                    - self.wt[r] * self.dy[r * w + i];
            }
        }
        b
    }

    /// The weighed squared misfit of the heights `x` to the differences,
    /// and the weighed squared differences themselves.
    fn misfit(&self, x: &[f64]) -> (f64, f64) {
        let (w, h) = (self.w, self.ws.len());
        let (mut misfit, mut total) = (0.0, 0.0);
        for r in 0..h {
            let down = (r + 1) % h;
            for i in 0..w {
                let at = r * w + i;
                let ex = x[r * w + (i + 1) % w] - x[at] - self.dx[at];
                let ey = x[down * w + i] - x[at] - self.dy[at];
                misfit += self.ws[r] * ex * ex + self.wt[r] * ey * ey;
                total += self.ws[r] * self.dx[at].powi(2) + self.wt[r] * self.dy[at].powi(2);
            }
        }
        (misfit, total)
    }
}

/// Solves the sphere's normal equations for heights x on `w` columns
/// that wrap and `ws.len()` rows that do not: per row r,
/// ws[r] (2 x - left - right) + wt[r-1] (x - up) + wt[r] (x - down) = b.
/// The rows' weights do not change along a row, so the discrete Fourier
/// transform along the rows makes each column's frequency its own
/// tridiagonal system down the rows, solved exactly (Thomas); the
/// constant is taken with mean 0.
fn sphere_poisson(b: &[f64], w: usize, ws: &[f64], wt: &[f64]) -> Vec<f64> {
    let h = ws.len();
    let mut planner = FftPlanner::<f64>::new();
    let mut rows: Vec<Complex<f64>> = b.iter().map(|&x| Complex::new(x, 0.0)).collect();
    planner.plan_fft_forward(w).process(&mut rows);
    let tau = std::f64::consts::TAU;
    // A constant is free at frequency 0: a nudge far below every weight
    // fixes it without moving the rest.
    let nudge = 1e-9 * ws.iter().chain(wt).fold(0.0f64, |m, &x| m.max(x));
    let (mut c, mut d) = (vec![0.0; h], vec![Complex::new(0.0, 0.0); h]);
    for k in 0..w {
        let lambda = 2.0 - 2.0 * (tau * k as f64 / w as f64).cos();
        // Forward sweep, leaving x_r = d_r - c_r x_{r+1}.
        for r in 0..h {
            let up = if r > 0 { wt[r - 1] } else { 0.0 };
            let diag = ws[r] * lambda + up + wt[r] + if k == 0 { nudge } else { 0.0 };
            let (c_up, d_up) = match r {
                0 => (0.0, Complex::new(0.0, 0.0)),
                _ => (c[r - 1], d[r - 1]),
            };
            let denom = diag + up * c_up;
            c[r] = -wt[r] / denom;
            d[r] = (rows[r * w + k] + d_up * up) / denom;
        }
        let mut next = Complex::new(0.0, 0.0);
        for r in (0..h).rev() {
            let x = d[r] - next * c[r];
            rows[r * w + k] = x;
            next = x;
        }
    }
    planner.plan_fft_inverse(w).process(&mut rows);
    let mut values: Vec<f64> = rows.iter().map(|c| c.re / w as f64).collect();
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    values.iter_mut().for_each(|v| *v -= mean);
    values
}

/// Solves L x = `b` on a `w` x `h` grid that wraps, L the five-point
/// Laplacian with the vertical differences weighed `beta` (2 x minus
/// its two neighbours in the row, plus `beta` times the same in the
/// column; `b` sums to zero, x is taken with mean 0): exactly, by the
/// discrete Fourier transform, which makes L diagonal
/// (2 - 2 cos(2 pi i / w) + beta (2 - 2 cos(2 pi j / h))). An iterative
/// solve needs about as many steps as the grid has rows: a minute for a
/// 1024-texel map, where this takes a fraction of a second.
fn periodic_poisson(b: &[f64], w: usize, h: usize, beta: f64) -> Vec<f64> {
    let mut planner = FftPlanner::<f64>::new();
    let mut rows: Vec<Complex<f64>> = b.iter().map(|&x| Complex::new(x, 0.0)).collect();
    planner.plan_fft_forward(w).process(&mut rows);
    let mut cols = transposed(&rows, w, h);
    planner.plan_fft_forward(h).process(&mut cols);
    let tau = std::f64::consts::TAU;
    for i in 0..w {
        for j in 0..h {
            let l = 2.0 - 2.0 * (tau * i as f64 / w as f64).cos()
                + beta * (2.0 - 2.0 * (tau * j as f64 / h as f64).cos());
            let c = &mut cols[i * h + j];
            *c = if l > 1e-12 {
                *c / l
            } else {
                Complex::new(0.0, 0.0)
            };
        }
    }
    planner.plan_fft_inverse(h).process(&mut cols);
    let mut rows = transposed(&cols, h, w);
    planner.plan_fft_inverse(w).process(&mut rows);
    let n = (w * h) as f64;
    rows.iter().map(|c| c.re / n).collect()
}

/// The `w` x `h` row-major grid `a` as `h` x `w`.
fn transposed(a: &[Complex<f64>], w: usize, h: usize) -> Vec<Complex<f64>> {
    let mut out = vec![Complex::new(0.0, 0.0); w * h];
    for r in 0..h {
        for c in 0..w {
            out[c * h + r] = a[r * w + c];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A normal map made from a known periodic height, H(s, t) =
    /// a sin(2 pi s) cos(2 pi t), on a frame with |Es| = 2, |Et| = 3.
    fn from_height(n: u32, a: f64) -> (Texels, Frame) {
        let frame = frame([2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 1.0]).unwrap();
        let tau = std::f64::consts::TAU;
        let mut values = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let s = (i as f64 + 0.5) / n as f64;
                let t = 1.0 - (j as f64 + 0.5) / n as f64;
                // world slopes: dH/ds / |Es|, dH/dt / |Et|; the normal
                // is (-gx, -gy, 1) normalised
                let gx = a * tau * (tau * s).cos() * (tau * t).cos() / 2.0;
                let gy = -a * tau * (tau * s).sin() * (tau * t).sin() / 3.0;
                let l = (gx * gx + gy * gy + 1.0).sqrt();
                for c in [-gx / l, -gy / l, 1.0 / l] {
                    values.push(((c + 1.0) / 2.0) as f32);
                }
            }
        }
        let t = Texels {
            width: n,
            height: n,
            values,
        };
        (t, frame)
    }

    #[test]
    fn a_height_fields_normal_map_gives_that_height_back() {
        let (texels, frame) = from_height(32, 0.05);
        let h = heights(&texels, [0.0, 1.0], frame);
        assert_eq!((h.width, h.height), (128, 128));
        let tau = std::f64::consts::TAU;
        let mean = h.values.iter().sum::<f64>() / h.values.len() as f64;
        let mut worst: f64 = 0.0;
        for r in 0..h.height as usize {
            for i in 0..h.width as usize {
                let s = (i as f64 + 0.5) / h.width as f64;
                let t = 1.0 - (r as f64 + 0.5) / h.height as f64;
                let truth = 0.05 * (tau * s).sin() * (tau * t).cos();
                worst = worst.max((h.values[r * h.width as usize + i] - mean - truth).abs());
            }
        }
        assert!(worst < 0.002, "worst {worst} of amplitude 0.05");
        assert!(h.missed < 0.05, "missed {}", h.missed);
    }

    /// A map wider than `MAX_SIDE` is laid out at it, not at its own size.
    #[test]
    fn a_large_map_is_laid_out_at_most_max_side() {
        let (w, h) = (2 * MAX_SIDE + 6, 3);
        let texels = Texels {
            width: w,
            height: h,
            values: [0.5, 0.5, 1.0].repeat((w * h) as usize),
        };
        let frame = frame([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]).unwrap();
        let hf = heights(&texels, [0.0, 1.0], frame);
        assert_eq!((hf.width, hf.height), (MAX_SIDE, 3));
        assert_eq!(hf.values.len(), (MAX_SIDE * 3) as usize);
    }

    #[test]
    fn a_twist_no_height_has_is_reported_missed() {
        // x = cos(2 pi t), y = 0: the slope along s changes along t, a
        // curl no height field has
        let n = 16;
        let mut values = Vec::new();
        for j in 0..n {
            for _ in 0..n {
                let t = 1.0 - (j as f64 + 0.5) / n as f64;
                let x = 0.3 * (std::f64::consts::TAU * t).cos();
                values.extend([((x + 1.0) / 2.0) as f32, 0.5, 1.0]);
            }
        }
        let texels = Texels {
            width: n,
            height: n,
            values,
        };
        let frame = frame([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]).unwrap();
        assert!(heights(&texels, [0.0, 1.0], frame).missed > 0.9);
    }

    /// A map stored with a `range`: its texels are read as
    /// lo + v (hi - lo) before they are vectors, so the same normals
    /// written into [lo, hi] give the same height.
    #[test]
    fn a_maps_range_is_applied_before_its_slopes() {
        let (plain, frame) = from_height(16, 0.05);
        let [lo, hi] = [0.3, 1.1];
        let stored = Texels {
            values: plain
                .values
                .iter()
                .map(|&v| ((v as f64 - lo) / (hi - lo)) as f32)
                .collect(),
            ..plain
        };
        let a = heights(&plain, [0.0, 1.0], frame);
        let b = heights(&stored, [lo, hi], frame);
        let worst = a
            .values
            .iter()
            .zip(&b.values)
            .fold(0.0f64, |w, (x, y)| w.max((x - y).abs()));
        assert!(worst < 1e-6, "heights differ by {worst}");
        let unread = heights(&stored, [0.0, 1.0], frame);
        let off = a
            .values
            .iter()
            .zip(&unread.values)
            .fold(0.0f64, |w, (x, y)| w.max((x - y).abs()));
        assert!(off > 0.01, "the range changes nothing here: {off}");
    }

    /// A height varying along s alone, on a map or a tile longer one way
    /// than the other (300 x 8 texels; a 4 x 1 m tile), with the 8-bit
    /// map's half-level tilt: a height field's within a few per cent. The
    /// misfit counts slopes, not height steps: a step along the short
    /// side must not weigh as much as dozens along the long one.
    #[test]
    fn a_map_or_tile_longer_one_way_is_weighed_by_slope() {
        let tau = std::f64::consts::TAU;
        let texels = |w: u32, h: u32| {
            let mut values = Vec::new();
            for _ in 0..h {
                for x in 0..w {
                    let v = 128.0 + (60.0 * (tau * x as f64 / 30.0).sin()).round();
                    values.extend([(v / 255.0) as f32, 128.0 / 255.0, 230.0 / 255.0]);
                }
            }
            Texels {
                width: w,
                height: h,
                values,
            }
        };
        let z = [0.0, 0.0, 1.0];
        for (map, es, et) in [
            (texels(300, 8), [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            (texels(30, 30), [4.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            (texels(30, 30), [1.0, 0.0, 0.0], [0.0, 4.0, 0.0]),
        ] {
            let h = heights(&map, [0.0, 1.0], frame(es, et, z).unwrap());
            assert!(
                h.missed < 0.05,
                "{}x{} on {es:?} {et:?}: missed {}",
                map.width,
                map.height,
                h.missed
            );
        }
    }

    /// The normal map of a known height on a sphere, H(d) = a (d.x +
    /// d.y d.z) over the direction d from the centre (smooth through the
    /// poles), laid by longitude and latitude as the built-in tracer
    /// lays it: the sphere's solve gives H back, poles and seam included.
    #[test]
    fn a_height_on_a_sphere_is_given_back() {
        let (n, a, radius) = (64u32, 0.05, 2.0);
        let pi = std::f64::consts::PI;
        let dir = |u: f64, v: f64| {
            let (lon, lat) = (2.0 * pi * u, pi * (v - 0.5));
            V3::new(lat.cos() * lon.cos(), lat.sin(), -lat.cos() * lon.sin())
        };
        let truth = |d: V3| a * (d.x + d.y * d.z);
        let mut values = Vec::new();
        for j in 0..n / 2 {
            for i in 0..n {
                let (u, v) = (
                    (i as f64 + 0.5) / n as f64,
                    1.0 - (j as f64 + 0.5) / (n / 2) as f64,
                );
                let d = dir(u, v);
                let g = V3::new(a, a * d.z, a * d.y);
                let grad = (g - d * g.dot(d)) / radius;
                let east = V3::new(d.z, 0.0, -d.x).normalized();
                let north = d.cross(east);
                let (ge, gn) = (grad.dot(east), grad.dot(north));
                let l = (ge * ge + gn * gn + 1.0).sqrt();
                for c in [-ge / l, -gn / l, 1.0 / l] {
                    values.push(((c + 1.0) / 2.0) as f32);
                }
            }
        }
        let texels = Texels {
            width: n,
            height: n / 2,
            values,
        };
        let h = sphere_heights(&texels, [0.0, 1.0], radius, [1.0, 1.0]);
        assert!(h.missed < 0.05, "missed {}", h.missed);
        let (w, rows) = (h.width as usize, h.height as usize);
        let want: Vec<f64> = (0..rows * w)
            .map(|k| {
                let (i, r) = (k % w, k / w);
                truth(dir(
                    (i as f64 + 0.5) / w as f64,
                    1.0 - (r as f64 + 0.5) / rows as f64,
                ))
            })
            .collect();
        let mean = want.iter().sum::<f64>() / want.len() as f64;
        let worst = want
            .iter()
            .zip(&h.values)
            .fold(0.0f64, |m, (t, v)| m.max((t - mean - v).abs()));
        assert!(worst < 0.05 * a, "worst {worst} of amplitude {a}");
    }

    /// A map laid over a sphere at a whole scale is its texels repeated
    /// (to rounding); at another scale it is finer, and each laid texel is the
    /// map's value where that texel's centre falls.
    #[test]
    fn a_map_laid_over_a_sphere_repeats_its_texels() {
        let values: Vec<f32> = (0..6).flat_map(|k| [k as f32 / 8.0; 3]).collect();
        let map = Texels {
            width: 3,
            height: 2,
            values,
        };
        let laid = over_sphere(&map, [2.0, 3.0]);
        assert_eq!((laid.width, laid.height), (6, 6));
        for r in 0..6 {
            for i in 0..6 {
                let k = 3 * (r * 6 + i);
                let want = map.values[3 * ((r % 2) * 3 + i % 3)];
                assert!((laid.values[k] - want).abs() < 1e-6, "texel ({i}, {r})");
            }
        }
        let laid = over_sphere(&map, [1.5, 1.0]);
        assert_eq!((laid.width, laid.height), (3 * 2 * FINE, 2 * FINE));
        let (w, h) = (laid.width as f64, laid.height as f64);
        for (i, r) in [(0, 0), (5, 3), (17, 7)] {
            let (u, v) = ((i as f64 + 0.5) / w, 1.0 - (r as f64 + 0.5) / h);
            let k = 3 * (r * laid.width as usize + i);
            assert_eq!(laid.values[k], map.sample(1.5 * u, v)[0]);
        }
    }
}
