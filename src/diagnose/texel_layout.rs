//! Where a colour texture solved in the object's frame (`texels.rs`) puts
//! each pixel: per object, the side of its square map and the scale of
//! its texture coordinates. The side is chosen from how many pixels see
//! the object over every photograph (the largest power of two at which
//! three quarters of those pixels lie in texels holding at least
//! `SAMPLES_PER_TEXEL` of them), or fixed by
//! `diagnose --map-size`; at most `MAX_MAP_SIDE` either way, which bounds
//! a map's memory (1024² texels: 12 MiB of floats). A plane's coordinates
//! are metres without bound, so its map is scaled to hold the region the
//! photographs see in one tile (the lookup repeats, so the offset does
//! not matter); the other shapes' coordinates span [0, 1] already.

use crate::render::SurfaceCoords;
use crate::scene::{Scene, Shape};

/// The largest side of a solved map, texels.
pub const MAX_MAP_SIDE: u32 = 1024;

/// Pixels a texel needs to count as densely seen: fewer, and its value
/// rests on one or two pixels, where noise decides it.
const SAMPLES_PER_TEXEL: f64 = 16.0;

/// The share of the pixels that must lie in densely seen texels. Not an
/// average over the texels seen: near the silhouette a pixel spans many
/// texels, and those sparse texels pulled an average (8 a texel) down to
/// a map too coarse for the texture.
const DENSE: f64 = 0.75;

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

/// The scale that maps the extent of `uvs` to a little under one tile.
fn plane_scale(uvs: &[[f64; 2]]) -> [f64; 2] {
    let extent = |k: usize| {
        let (lo, hi) = uvs
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p[k]), hi.max(p[k]))
            });
        hi - lo
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

/// The largest power of two at which `DENSE` of `uvs` lie in texels
/// holding `SAMPLES_PER_TEXEL` of them at least (1 when none does).
fn chosen_side(uvs: &[[f64; 2]], scale: [f64; 2]) -> u32 {
    let mut side = 1;
    while side < MAX_MAP_SIDE {
        let next = Layout {
            side: side * 2,
            scale,
        };
        let mut count = vec![0u32; (next.side * next.side) as usize];
        for &uv in uvs {
            count[next.texel(uv)] += 1;
        }
        let dense: u64 = count
            .iter()
            .filter(|&&c| c as f64 >= SAMPLES_PER_TEXEL)
            .map(|&c| c as u64)
            .sum();
        if (dense as f64) < DENSE * uvs.len() as f64 {
            break;
        }
        side = next.side;
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

    #[test]
    fn the_side_grows_with_the_pixels_that_see_the_object() {
        // A grid of n x n points over the whole square: n² / side² per
        // texel, at least 16 kept.
        let grid = |n: usize| -> Vec<[f64; 2]> {
            (0..n * n)
                .map(|k| {
                    [
                        ((k % n) as f64 + 0.5) / n as f64,
                        ((k / n) as f64 + 0.5) / n as f64,
                    ]
                })
                .collect()
        };
        assert_eq!(chosen_side(&grid(64), [1.0, 1.0]), 16, "16 per texel at 16");
        assert_eq!(chosen_side(&grid(128), [1.0, 1.0]), 32);
        assert_eq!(chosen_side(&grid(2), [1.0, 1.0]), 1);
        // A plane seen over 3 m by 1 m fits one tile.
        let s = plane_scale(&[[-1.0, 0.0], [2.0, 1.0]]);
        assert!(s[0] * 3.0 < 1.0 && s[0] * 3.0 > 0.99 && s[1] < 1.0 && s[1] > 0.99);
    }
}
