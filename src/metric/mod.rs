//! Image comparison: the paper's per-channel deviation over an optional
//! mask, and the fitness the optimizer minimises (the sum of the three
//! channel deviations).
//!
//! Deviation, per channel: `100 * mean_i |T_i - R_i| / 255` over the mask's
//! pixels (all pixels when there is none), on 8-bit sRGB values; `average`
//! is the mean of r, g and b. A photograph finer than 8-bit sRGB (16-bit,
//! float, linear) also has a precise deviation, [`deviation_levels`]: the
//! same formula on its unrounded levels.

pub mod blur;
pub mod mask;

pub use blur::{blurred_levels, blurred_residuals, blurred_residuals_with, blurred_weight};
pub use mask::Mask;

use crate::raster::Image;
use serde::{Deserialize, Serialize};

/// Per-channel deviation in percent, and its average.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Deviation {
    pub r: f64,
    pub g: f64,
    pub b: f64,
    pub average: f64,
}

impl Deviation {
    fn from_sums(sums: [u64; 3], count: u64) -> Deviation {
        Deviation::from_level_sums(sums.map(|s| s as f64), count)
    }

    fn from_level_sums(sums: [f64; 3], count: u64) -> Deviation {
        let scale = 100.0 / (255.0 * count.max(1) as f64);
        let (r, g, b) = (sums[0] * scale, sums[1] * scale, sums[2] * scale);
        Deviation {
            r,
            g,
            b,
            average: (r + g + b) / 3.0,
        }
    }

    /// The deviation of per-value residuals (`residuals`' order: r, g, b
    /// per pixel), in 8-bit levels.
    pub fn of_residuals(r: &[f32]) -> Deviation {
        let mut sums = [0f64; 3];
        for px in r.chunks_exact(3) {
            for c in 0..3 {
                sums[c] += f64::from(px[c].abs());
            }
        }
        Deviation::from_level_sums(sums, (r.len() / 3) as u64)
    }

    /// The deviation over several images together, each given with the
    /// number of pixels it counts: every counted pixel weighs the same.
    pub fn pooled(parts: &[(Deviation, usize)]) -> Deviation {
        let total: usize = parts.iter().map(|(_, n)| n).sum();
        let w = |n: usize| n as f64 / total.max(1) as f64;
        let sum = |f: fn(&Deviation) -> f64| parts.iter().map(|(d, n)| f(d) * w(*n)).sum::<f64>();
        let (r, g, b) = (sum(|d| d.r), sum(|d| d.g), sum(|d| d.b));
        Deviation {
            r,
            g,
            b,
            average: (r + g + b) / 3.0,
        }
    }

    /// What the optimizer minimises.
    pub fn fitness(&self) -> f64 {
        self.r + self.g + self.b
    }
}

/// The deviation of `render` from `target` (same size) over `mask`.
pub fn deviation(target: &Image, render: &Image, mask: Option<&Mask>) -> Deviation {
    debug_assert_eq!(target.dimensions(), render.dimensions());
    let (t, r) = (target.as_raw(), render.as_raw());
    let mut sums = [0u64; 3];
    match mask {
        None => {
            add_channels(t, r, &mut sums);
            Deviation::from_sums(sums, (t.len() / 3) as u64)
        }
        Some(m) => {
            for &(start, len) in m.runs() {
                let span = 3 * start as usize..3 * (start + len) as usize;
                add_channels(&t[span.clone()], &r[span], &mut sums);
            }
            Deviation::from_sums(sums, m.pixels().len() as u64)
        }
    }
}

/// Adds the absolute differences of `t` and `r` (RGB values) per channel.
/// Sixteen pixels at a time into 48 lanes (lane k holds channel k mod 3),
/// a loop the compiler vectorises; the rest a pixel at a time.
fn add_channels(t: &[u8], r: &[u8], sums: &mut [u64; 3]) {
    const LANES: usize = 48;
    let mut acc = [0u32; LANES];
    let (tb, rb) = (t.chunks_exact(LANES), r.chunks_exact(LANES));
    let (t_rest, r_rest) = (tb.remainder(), rb.remainder());
    for (tc, rc) in tb.zip(rb) {
        for k in 0..LANES {
            acc[k] += tc[k].abs_diff(rc[k]) as u32;
        }
    }
    for (k, a) in acc.iter().enumerate() {
        sums[k % 3] += *a as u64;
    }
    for (tc, rc) in t_rest.chunks_exact(3).zip(r_rest.chunks_exact(3)) {
        for c in 0..3 {
            sums[c] += tc[c].abs_diff(rc[c]) as u64;
        }
    }
}

/// The deviation of `render` from a photograph's unrounded 8-bit sRGB
/// `levels` (3 per pixel, `render`'s size) over `mask`: [`deviation`]
/// without the target's rounding to whole levels.
pub fn deviation_levels(levels: &[f32], render: &Image, mask: Option<&Mask>) -> Deviation {
    let r = render.as_raw();
    debug_assert_eq!(levels.len(), r.len());
    let mut sums = [0f64; 3];
    let mut add = |i: usize| {
        for c in 0..3 {
            sums[c] += (levels[i + c] - r[i + c] as f32).abs() as f64;
        }
    };
    match mask {
        None => {
            (0..r.len()).step_by(3).for_each(&mut add);
            Deviation::from_level_sums(sums, (r.len() / 3) as u64)
        }
        Some(m) => {
            m.pixels().iter().for_each(|&px| add(px as usize * 3));
            Deviation::from_level_sums(sums, m.pixels().len() as u64)
        }
    }
}

/// Render − target per channel value over `mask` (all pixels when none), in
/// 8-bit levels: what a local search fits in least squares. Their absolute
/// sum, scaled, is [`Deviation::fitness`].
pub fn residuals(target: &Image, render: &Image, mask: Option<&Mask>) -> Vec<f32> {
    debug_assert_eq!(target.dimensions(), render.dimensions());
    let (t, r) = (target.as_raw(), render.as_raw());
    let diff = |i: usize| r[i] as f32 - t[i] as f32;
    match mask {
        None => (0..t.len()).map(diff).collect(),
        Some(m) => m
            .pixels()
            .iter()
            .flat_map(|&px| {
                let i = px as usize * 3;
                [diff(i), diff(i + 1), diff(i + 2)]
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_deviation() {
        let t = Image::from_pixel(4, 2, image::Rgb([100, 100, 200]));
        let mut r = t.clone();
        r.put_pixel(0, 0, image::Rgb([100 + 51, 100, 200 - 102]));
        let d = deviation(&t, &r, None);
        // 51 over 8 pixels of 255 -> 2.5 %; 102 -> 5 %.
        assert!((d.r - 2.5).abs() < 1e-12 && d.g == 0.0 && (d.b - 5.0).abs() < 1e-12);
        assert!((d.average - 2.5).abs() < 1e-12);
        let m = Mask::from_pixels(4, 2, vec![0, 1]);
        let dm = deviation(&t, &r, Some(&m));
        assert!((dm.r - 10.0).abs() < 1e-12);
    }

    #[test]
    fn deviation_equals_a_plain_sum_per_channel() {
        // Values that vary per channel, a size not a multiple of 16 pixels
        // and a mask of uneven runs: every path of the sum.
        let value = |x: u32, y: u32, c: u32| ((x * 37 + y * 101 + c * 59) * 7 % 256) as u8;
        let t = Image::from_fn(37, 11, |x, y| image::Rgb([0, 1, 2].map(|c| value(x, y, c))));
        let r = Image::from_fn(37, 11, |x, y| {
            image::Rgb([0, 1, 2].map(|c| value(y, x, c + 1)))
        });
        let pixels: Vec<u32> = (0..37 * 11).filter(|p| p % 7 != 3 && p % 50 < 41).collect();
        let m = Mask::from_pixels(37, 11, pixels.clone());
        let plain = |px: &[u32]| {
            let mut s = [0u64; 3];
            for &p in px {
                for (c, sum) in s.iter_mut().enumerate() {
                    let i = 3 * p as usize + c;
                    *sum += t.as_raw()[i].abs_diff(r.as_raw()[i]) as u64;
                }
            }
            Deviation::from_sums(s, px.len() as u64)
        };
        let all: Vec<u32> = (0..37 * 11).collect();
        assert_eq!(deviation(&t, &r, None), plain(&all));
        assert_eq!(deviation(&t, &r, Some(&m)), plain(&pixels));
    }

    #[test]
    fn level_deviation_matches_on_whole_levels_and_sees_fractions() {
        let t = Image::from_pixel(4, 2, image::Rgb([100, 100, 200]));
        let mut r = t.clone();
        r.put_pixel(0, 0, image::Rgb([100 + 51, 100, 200 - 102]));
        let whole: Vec<f32> = t.as_raw().iter().map(|&v| v as f32).collect();
        let m = Mask::from_pixels(4, 2, vec![0, 1]);
        for mask in [None, Some(&m)] {
            let (a, b) = (deviation(&t, &r, mask), deviation_levels(&whole, &r, mask));
            assert!((a.average - b.average).abs() < 1e-9 && (a.b - b.b).abs() < 1e-9);
        }
        // Half a level off everywhere in red: 0.5 / 255 = 0.196 %.
        let half: Vec<f32> = whole
            .iter()
            .enumerate()
            .map(|(i, &v)| v + if i % 3 == 0 { 0.5 } else { 0.0 })
            .collect();
        let d = deviation_levels(&half, &t, None);
        assert!((d.r - 50.0 / 255.0).abs() < 1e-9 && d.g == 0.0, "{d:?}");
    }
}
