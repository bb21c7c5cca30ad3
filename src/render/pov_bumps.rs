//! A tangent-space normal map as POV-Ray can draw it on a planar map: a
//! height field whose slopes are the map's. POV-Ray's `normal` takes a
//! pattern's gradient (four samples `accuracy` apart), adds it to the
//! surface normal and renormalises; the built-in tracer turns the map's
//! vector (x, y, z) into x T + y B + z N (`render/phong/normal_map.rs`).
//! The two agree when the gradient is G = (x/z) T + (y/z) B, so the
//! height's slope along each map direction is fixed by each texel, and
//! the height itself is their least-squares integral over the repeating
//! tile (`heights`: a periodic Poisson equation, solved exactly by the
//! discrete Fourier transform). A map that is a height field's (bumps, grain, a scan's
//! relief) is drawn as given; the part of another that no height field
//! has (a twist of the normals, a tilt of the whole tile) is lost, which
//! `heights` reports.
//!
//! The height is laid out `FINE` times finer than the map: POV-Ray's
//! bilinear pattern has a slope that is constant across each cell, where
//! the built-in tracer interpolates the vectors themselves. At most
//! `MAX_SIDE` texels a side, which bounds the solve's memory (about 100
//! bytes a texel: 100 MB for 1024 x 1024).

use crate::math::V3;
use crate::scene::texture::{self, MapKind, Texels, TextureRef};
use crate::scene::Shape;
use rustfft::num_complex::Complex;
use rustfft::FftPlanner;
use std::sync::{Arc, Mutex};

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
        "{:.0} % of its slopes are not a height field's on this surface (at most {:.0} %: a map stretched unevenly by `scale` or the shape, or twisted), and POV-Ray draws a normal map as a height's gradient; use phong, blender or mitsuba, or a map made for this scale",
        100.0 * missed,
        100.0 * MAX_MISSED
    )
}

/// The height field of the normal map `t` (read as the scene reads it,
/// its `range` applied) on `frame`. The last few are kept: the refusal
/// check (`maps::povray_refusals`) asks on every render of a fit, and
/// the map's writer (`PovMaps`) once a session; each is solved once.
/// At most `KEPT` x 8 MB (`MAX_SIDE` squared values).
pub fn solved(t: &TextureRef, frame: Frame) -> Result<Arc<Heights>, String> {
    type Key = (String, [u64; 2], [u64; 4]);
    static SEEN: Mutex<Vec<(Key, Arc<Heights>)>> = Mutex::new(Vec::new());
    const KEPT: usize = 4;
    let range = t.range();
    let key = (
        t.file().to_string(),
        range.map(f64::to_bits),
        frame.map(f64::to_bits),
    );
    if let Some((_, h)) = SEEN
        .lock()
        .expect("heights")
        .iter()
        .find(|(k, _)| *k == key)
    {
        return Ok(h.clone());
    }
    let texels = texture::get(std::path::Path::new(t.file()), t.encoding(MapKind::Normal))?;
    let h = Arc::new(heights(&texels, range, frame));
    let mut seen = SEEN.lock().expect("heights");
    if seen.len() >= KEPT {
        seen.remove(0);
    }
    seen.push((key, h.clone()));
    Ok(h)
}

/// The share of its slopes the height field of normal map `t` on `frame`
/// misses when it is refused (`refused`), else None.
pub fn missed(t: &TextureRef, frame: Frame) -> Result<Option<f64>, String> {
    let h = solved(t, frame)?;
    Ok(refused(&h).then_some(h.missed))
}

/// A planar map's frame (None on a sphere, box or mesh): from the world
/// vectors of the map's coordinates at its `scale` and the normal.
pub fn planar_frame(shape: &Shape, scale: [f64; 2]) -> Option<Frame> {
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
        let [lo, hi] = range;
        let [r, g, b] = texels
            .sample(s, t)
            .map(|c| 2.0 * (lo + c as f64 * (hi - lo)) - 1.0);
        let z = b.max(MIN_Z);
        let (gx, gy) = (r / z, g / z);
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
    let at = |i: usize, r: usize| r * wn + i;
    let left = |i: usize| (i + wn - 1) % wn;
    let up = |r: usize| (r + hn - 1) % hn;
    let mut rhs = vec![0.0; wn * hn];
    for r in 0..hn {
        for i in 0..wn {
            rhs[at(i, r)] =
                dx[at(left(i), r)] - dx[at(i, r)] + beta * (dy[at(i, up(r))] - dy[at(i, r)]);
        }
    }
    let values = periodic_poisson(&rhs, wn, hn, beta);
    let (mut misfit, mut total) = (0.0, 0.0);
    for r in 0..hn {
        for i in 0..wn {
            let ex = values[at((i + 1) % wn, r)] - values[at(i, r)] - dx[at(i, r)];
            let ey = values[at(i, (r + 1) % hn)] - values[at(i, r)] - dy[at(i, r)];
            misfit += ex * ex + beta * ey * ey;
            total += dx[at(i, r)].powi(2) + beta * dy[at(i, r)].powi(2);
        }
    }
    Heights {
        width: w,
        height: h,
        values,
        missed: if total > 0.0 {
            (misfit / total).sqrt()
        } else {
            0.0
        },
        slope: (slope2 / (wn * hn) as f64).sqrt(),
    }
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
}
