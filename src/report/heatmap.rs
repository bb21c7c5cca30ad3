//! Signed difference heatmaps: target − render in 8-bit luminance per
//! pixel, on a diverging scale (red: the target is brighter, the render
//! misses light there; blue: the render is too bright), with a colour bar.
//! Pixels outside the mask are grey. Both heatmaps of a report share one
//! scale so that they can be compared by eye.
//!
//! Drawn with plotters as runs of equal colour per row (the difference is
//! mostly near zero), which keeps the SVG small.

use super::figure::{err, font, DrawResult, Figure};
use crate::metric::Mask;
use crate::raster::Image;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Levels of the colour scale on each side of zero.
const LEVELS: i32 = 20;

/// Per-pixel signed luminance difference (None outside the mask).
pub fn signed_luminance(target: &Image, render: &Image, mask: Option<&Mask>) -> Vec<Option<f64>> {
    let lum = |p: &image::Rgb<u8>| {
        0.2126 * p.0[0] as f64 + 0.7152 * p.0[1] as f64 + 0.0722 * p.0[2] as f64
    };
    let mut d: Vec<Option<f64>> = target
        .pixels()
        .zip(render.pixels())
        .map(|(t, r)| Some(lum(t) - lum(r)))
        .collect();
    if mask.is_some() {
        let keep = Mask::counted(mask, d.len());
        for (v, k) in d.iter_mut().zip(keep) {
            if !k {
                *v = None;
            }
        }
    }
    d
}

/// Mean signed difference per channel (target − render, 8-bit units) over
/// the mask: positive means the render is too dark in that channel.
pub fn channel_bias(target: &Image, render: &Image, mask: Option<&Mask>) -> [f64; 3] {
    let (t, r) = (target.as_raw(), render.as_raw());
    let all: Vec<u32>;
    let pixels: &[u32] = match mask {
        Some(m) => m.pixels(),
        None => {
            all = (0..(t.len() / 3) as u32).collect();
            &all
        }
    };
    let mut sum = [0.0; 3];
    for &p in pixels {
        for (c, total) in sum.iter_mut().enumerate() {
            let i = p as usize * 3 + c;
            if let (Some(a), Some(b)) = (t.get(i), r.get(i)) {
                *total += *a as f64 - *b as f64;
            }
        }
    }
    let n = pixels.len().max(1) as f64;
    sum.map(|s| s / n)
}

/// A symmetric scale limit that covers 99 % of |difference| in all maps,
/// at least 4 levels so that noise does not look like structure.
pub fn shared_limit(maps: &[&[Option<f64>]]) -> f64 {
    let mut v: Vec<f64> = maps
        .iter()
        .flat_map(|m| m.iter().flatten().map(|d| d.abs()))
        .collect();
    if v.is_empty() {
        return 4.0;
    }
    v.sort_by(f64::total_cmp);
    // Nearest rank.
    let p99 = v[((v.len() as f64 * 0.99).ceil() as usize).clamp(1, v.len()) - 1];
    p99.max(4.0).ceil()
}

/// Diverging colour for t in [-1, 1]: blue, white, red.
pub fn colour(t: f64) -> RGBColor {
    let t = t.clamp(-1.0, 1.0);
    let (end, a) = if t >= 0.0 {
        ((178.0, 24.0, 43.0), t)
    } else {
        ((33.0, 102.0, 172.0), -t)
    };
    let mix = |e: f64| (255.0 + (e - 255.0) * a).round() as u8;
    RGBColor(mix(end.0), mix(end.1), mix(end.2))
}

const MASKED: RGBColor = RGBColor(215, 215, 215);

/// One heatmap with its colour bar.
pub struct Heatmap {
    pub title: String,
    pub diff: Vec<Option<f64>>,
    pub width: u32,
    pub height: u32,
    /// Pixel size in the figure.
    pub k: u32,
    /// The scale runs from -limit to +limit.
    pub limit: f64,
}

const MARGIN: i32 = 10;
const TOP: i32 = 34;
const BAR: i32 = 18;

impl Heatmap {
    fn level(&self, d: Option<f64>) -> Option<i32> {
        d.map(|d| {
            ((d / self.limit) * LEVELS as f64)
                .round()
                .clamp(-(LEVELS as f64), LEVELS as f64) as i32
        })
    }

    fn draw_map<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let k = self.k as i32;
        for y in 0..self.height as usize {
            let row = &self.diff[y * self.width as usize..(y + 1) * self.width as usize];
            let mut x0 = 0;
            while x0 < row.len() {
                let level = self.level(row[x0]);
                let mut x1 = x0 + 1;
                while x1 < row.len() && self.level(row[x1]) == level {
                    x1 += 1;
                }
                let c = match level {
                    Some(l) => colour(l as f64 / LEVELS as f64),
                    None => MASKED,
                };
                let (px0, py0) = (MARGIN + x0 as i32 * k, TOP + y as i32 * k);
                // plotters fills [x0, x1) x [y0, y1): the next run starts where this ends.
                let (px1, py1) = (MARGIN + x1 as i32 * k, TOP + (y as i32 + 1) * k);
                root.draw(&Rectangle::new([(px0, py0), (px1, py1)], c.filled()))
                    .map_err(err)?;
                x0 = x1;
            }
        }
        Ok(())
    }

    fn draw_bar<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let h = (self.height * self.k) as i32;
        let x0 = MARGIN + (self.width * self.k) as i32 + 16;
        let steps = 2 * LEVELS + 1;
        for i in 0..steps {
            let level = LEVELS - i; // top: +LEVELS
            let y0 = TOP + i * h / steps;
            let y1 = TOP + (i + 1) * h / steps;
            let c = colour(level as f64 / LEVELS as f64);
            root.draw(&Rectangle::new(
                [(x0, y0), (x0 + BAR, y1.max(y0))],
                c.filled(),
            ))
            .map_err(err)?;
        }
        root.draw(&Rectangle::new([(x0, TOP), (x0 + BAR, TOP + h - 1)], BLACK))
            .map_err(err)?;
        for t in [-1.0, -0.5, 0.0, 0.5, 1.0] {
            let y = TOP + ((1.0 - t) / 2.0 * (h - 1) as f64).round() as i32;
            root.draw(&PathElement::new(
                vec![(x0 + BAR, y), (x0 + BAR + 4, y)],
                BLACK,
            ))
            .map_err(err)?;
            let v = t * self.limit;
            let label = if v.fract() == 0.0 {
                format!("{v:+.0}")
            } else {
                format!("{v:+.1}")
            };
            root.draw_text(&label, &font(12), (x0 + BAR + 7, y - 6))
                .map_err(err)?;
        }
        Ok(())
    }
}

impl Figure for Heatmap {
    fn size(&self) -> (u32, u32) {
        (
            (MARGIN as u32) * 2 + self.width * self.k + 16 + BAR as u32 + 50,
            TOP as u32 + self.height * self.k + 30,
        )
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        root.draw_text(&self.title, &font(15), (MARGIN, 8))
            .map_err(err)?;
        self.draw_map(root)?;
        self.draw_bar(root)?;
        let y = TOP + (self.height * self.k) as i32 + 8;
        root.draw_text(
            "target − render, 8-bit luminance (red: render too dark)",
            &font(12),
            (MARGIN, y),
        )
        .map_err(err)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signs_scale_and_mask() {
        let t = Image::from_pixel(2, 1, image::Rgb([100, 100, 100]));
        let mut r = t.clone();
        r.put_pixel(0, 0, image::Rgb([90, 90, 90]));
        let d = signed_luminance(&t, &r, None);
        assert!((d[0].unwrap() - 10.0).abs() < 1e-9 && d[1] == Some(0.0));
        let m = Mask::from_pixels(2, 1, vec![1]);
        assert_eq!(signed_luminance(&t, &r, Some(&m))[0], None);
        assert_eq!(channel_bias(&t, &r, None), [5.0, 5.0, 5.0]);
        assert_eq!(channel_bias(&t, &r, Some(&m)), [0.0, 0.0, 0.0]);
        assert_eq!(shared_limit(&[&d]), 10.0);
        assert_eq!(colour(0.0), RGBColor(255, 255, 255));
        assert_eq!(colour(1.0), RGBColor(178, 24, 43));
    }
}
