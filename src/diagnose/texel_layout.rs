//! Where a colour texture solved in the object's frame (`texels.rs`) puts
//! each pixel: per object, the side of its square map and the scale of
//! its texture coordinates.
//!
//! The side follows the evidence: the samples are every counted pixel of
//! every photograph that sees the object, so a fixed camera with eight
//! photographs gives a pixel-sized texel eight samples, and a camera that
//! moves spreads its samples over new places. It is the largest power of
//! two at which the median texel seen holds at least `MIN_SAMPLES`
//! samples: counted over the samples, not assumed from an image's pixels,
//! so it holds for a longitude/latitude sphere or a plane in perspective,
//! whose footprint varies over the surface. With a fixed camera every
//! texel seen holds as many samples as photographs, so from three on the
//! side is the largest allowed: a value per surface point that every
//! photograph pins.
//! Whether each value pays for itself is the criterion's to say
//! (`texels.rs` keeps one only when the SAD of its samples falls by more
//! than it costs), so a finer map must still earn its values.
//! `diagnose --map-size` fixes the side instead; at most `MAX_MAP_SIDE`
//! either way, which bounds a map's memory (1024² texels: 12 MiB of
//! floats).
//!
//! A plane's coordinates are metres without bound, so its map is scaled
//! to hold every sample in one tile, unless that tile would be more than
//! `PLANE_STRETCH` times the extent of the middle `1 - 2 PLANE_TAIL` of
//! the samples along a direction: a plane seen towards its horizon has a
//! few pixels spread over hundreds of metres, and a tile stretched over
//! them left the near field, where most pixels are, with texels many
//! pixels wide. Those few pixels fall on the repeated tile (the lookup
//! repeats, so the offset does not matter either). A tile that held only
//! the middle 90 % folded the other 10 % of an ordinary view onto it,
//! where they contradict the pixels they land on (a textured plane seen
//! from 3 m: its map refused at side 64). The other shapes' coordinates
//! span [0, 1] already.

use crate::render::SurfaceCoords;
use crate::scene::{Scene, Shape};

/// The largest side of a solved map, texels.
pub const MAX_MAP_SIDE: u32 = 1024;

/// Samples the median texel seen needs: one value per texel and channel
/// rests on a weighted median of its samples' ratios (`texel_fit.rs`), and
/// three is the fewest at which that median survives one sample the model
/// misreads (a highlight, a shadow it lacks) and the value is checked by
/// two samples besides the one that sets it.
const MIN_SAMPLES: usize = 3;

/// The share of a plane's samples at each end of each direction that
/// measures how far its middle extends (`plane_scale`).
const PLANE_TAIL: f64 = 0.05;

/// The longest a plane's tile may be, in extents of its middle samples:
/// twice costs one step of side (a power of two) for the same texel size,
/// which the side search affords; further would be a horizon's few pixels
/// deciding the near field's texel size.
const PLANE_STRETCH: f64 = 2.0;

/// One object's map: its side and the scale of (u, v).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layout {
    pub side: u32,
    pub scale: [f64; 2],
}

impl Layout {
    /// The texel (index into rows top to bottom) whose cell holds `uv`,
    /// as `scene::texture::Texels` lays them out (v runs upwards).
    pub fn texel(&self, uv: [f64; 2]) -> usize {
        let s = self.side as f64;
        let wrap = |a: f64| (a.floor().rem_euclid(s) as usize).min(self.side as usize - 1);
        let i = wrap(uv[0] * self.scale[0] * s);
        let j = wrap((1.0 - uv[1] * self.scale[1]) * s);
        j * self.side as usize + i
    }

    /// The four texels the bilinear lookup at `uv` blends and their
    /// weights, as `scene::texture::Texels::sample` takes them.
    pub fn bilinear(&self, uv: [f64; 2]) -> ([u32; 4], [f32; 4]) {
        let s = self.side as f64;
        let x = uv[0] * self.scale[0] * s - 0.5;
        let y = (1.0 - uv[1] * self.scale[1]) * s - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
        let wrap = |a: f64| (a.rem_euclid(s) as u32).min(self.side - 1);
        let (i0, j0, i1, j1) = (wrap(x0), wrap(y0), wrap(x0 + 1.0), wrap(y0 + 1.0));
        let at = |i: u32, j: u32| j * self.side + i;
        (
            [at(i0, j0), at(i1, j0), at(i0, j1), at(i1, j1)],
            [
                (1.0 - fx) * (1.0 - fy),
                fx * (1.0 - fy),
                (1.0 - fx) * fy,
                fx * fy,
            ],
        )
    }
}

/// Each object's layout (None: not covered, or seen by no pixel), from the
/// pixels of every photograph that count (`inside`) and see it.
pub fn layouts(
    scene: &Scene,
    covered: &[bool],
    coords: &[(&SurfaceCoords, Vec<bool>)],
    fixed: Option<u32>,
) -> Vec<Option<Layout>> {
    (0..scene.objects.len())
        .map(|o| {
            if !covered[o] {
                return None;
            }
            let uvs: Vec<[f64; 2]> = coords
                .iter()
                .flat_map(|(c, inside)| {
                    c.points
                        .iter()
                        .zip(inside)
                        .filter(|(_, &i)| i)
                        .filter_map(|(p, _)| p.filter(|p| p.object as usize == o))
                        .map(|p| p.uv.map(f64::from))
                })
                .collect();
            if uvs.is_empty() {
                return None;
            }
            let scale = match scene.objects[o].shape {
                Shape::Plane { .. } => plane_scale(&uvs),
                _ => [1.0, 1.0],
            };
            let side = fixed.map_or_else(|| chosen_side(&uvs, scale), |s| s.min(MAX_MAP_SIDE));
            Some(Layout { side, scale })
        })
        .collect()
}

/// The scale that maps all of `uvs` along each direction to a little
/// under one tile, or `PLANE_STRETCH` times their middle's extent where
/// that is shorter.
fn plane_scale(uvs: &[[f64; 2]]) -> [f64; 2] {
    let extent = |k: usize| {
        let mut v: Vec<f64> = uvs.iter().map(|p| p[k]).filter(|x| x.is_finite()).collect();
        if v.is_empty() {
            return 0.0;
        }
        v.sort_by(f64::total_cmp);
        let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
        let middle = at(1.0 - PLANE_TAIL) - at(PLANE_TAIL);
        (at(1.0) - at(0.0)).min(PLANE_STRETCH * middle)
    };
    [0, 1].map(|k| {
        let e = extent(k);
        if e.is_finite() && e > 1e-9 {
            1.0 / (e * 1.001)
        } else {
            1.0
        }
    })
}

/// Per texel of a `side` map, the samples among `uvs` its cell holds.
fn counts(uvs: &[[f64; 2]], side: u32, scale: [f64; 2]) -> Vec<u32> {
    let layout = Layout { side, scale };
    let mut count = vec![0u32; (side * side) as usize];
    for &uv in uvs {
        count[layout.texel(uv)] += 1;
    }
    count
}

/// The largest power of two at which the median texel seen holds
/// `MIN_SAMPLES` of `uvs` (1 when no finer side does).
fn chosen_side(uvs: &[[f64; 2]], scale: [f64; 2]) -> u32 {
    let mut side = 1;
    while side < MAX_MAP_SIDE {
        let count = counts(uvs, side * 2, scale);
        let mut held: Vec<u32> = count.iter().copied().filter(|&n| n > 0).collect();
        if held.is_empty() {
            break;
        }
        let middle = held.len() / 2;
        let (_, median, _) = held.select_nth_unstable(middle);
        if (*median as usize) < MIN_SAMPLES {
            break;
        }
        side *= 2;
    }
    side
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texels_follow_the_lookup_convention() {
        let l = Layout {
            side: 4,
            scale: [1.0, 1.0],
        };
        assert_eq!(l.texel([0.1, 0.9]), 0, "top left");
        assert_eq!(l.texel([0.9, 0.1]), 15, "bottom right");
        assert_eq!(l.texel([1.1, 0.9]), 0, "repeats");
        let half = Layout {
            side: 4,
            scale: [0.5, 0.5],
        };
        assert_eq!(half.texel([1.9, 0.1]), 3 * 4 + 3);
        // At a texel's centre the lookup is that texel alone; halfway
        // between two, half each.
        let (t, w) = l.bilinear([0.375, 0.875]);
        assert_eq!((t[0], w[0]), (1, 1.0));
        let (t, w) = l.bilinear([0.5, 0.875]);
        assert_eq!((t[0], t[1], w[0], w[1]), (1, 2, 0.5, 0.5));
    }

    /// A grid of n x n points over the whole square, `photos` times.
    fn grid(n: usize, photos: usize) -> Vec<[f64; 2]> {
        (0..photos * n * n)
            .map(|k| {
                let k = k % (n * n);
                [
                    ((k % n) as f64 + 0.5) / n as f64,
                    ((k / n) as f64 + 0.5) / n as f64,
                ]
            })
            .collect()
    }

    #[test]
    fn the_side_follows_the_samples_of_every_photograph() {
        // One photograph: a texel needs three samples, so four pixels.
        assert_eq!(chosen_side(&grid(64, 1), [1.0, 1.0]), 32);
        assert_eq!(chosen_side(&grid(2, 1), [1.0, 1.0]), 1);
        // Eight from one place (a fixed camera): every texel seen holds
        // eight samples however fine, so the largest side.
        assert_eq!(chosen_side(&grid(64, 8), [1.0, 1.0]), MAX_MAP_SIDE);
        // Eight photographs each from its own place (a camera that
        // moves): eight samples a 64-texel cell, two a 128-texel one.
        let moved: Vec<[f64; 2]> = (0..8)
            .flat_map(|k| {
                let d = [
                    ((k % 4) as f64 - 1.5) / 256.0,
                    ((k / 4) as f64 - 0.5) / 128.0,
                ];
                grid(64, 1)
                    .into_iter()
                    .map(move |p| [p[0] + d[0], p[1] + d[1]])
            })
            .collect();
        assert_eq!(chosen_side(&moved, [1.0, 1.0]), 64);
    }

    #[test]
    fn a_plane_tile_holds_every_sample_unless_a_few_lie_far_off() {
        // A plane seen over 3 m by 1 m fits one tile, every sample in it...
        let mut pts: Vec<[f64; 2]> = (0..=100)
            .map(|i| [-1.0 + 3.0 * i as f64 / 100.0, i as f64 / 100.0])
            .collect();
        let s = plane_scale(&pts);
        let (a, b) = (s[0] * 3.0, s[1] * 1.0);
        assert!(a < 1.0 && a > 0.99 && b < 1.0 && b > 0.99, "{s:?}");
        // ... and a few samples far off towards a horizon stretch it to
        // twice the middle 90 % (2.7 m by 0.9 m), not to them.
        pts.extend([[-300.0, 500.0], [250.0, 900.0]]);
        let t = plane_scale(&pts);
        let (a, b) = (t[0] * 2.0 * 2.7, t[1] * 2.0 * 0.9);
        assert!(a < 1.05 && a > 0.95 && b < 1.05 && b > 0.95, "{t:?}");
    }
}
