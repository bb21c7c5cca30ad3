//! The residual of a fit and its structure: the signed residual per
//! channel in linear units (target − render), its fit by each effect's
//! feature maps (the evidence), whether smooth structure remains, and the
//! residual heatmap images.
//!
//! Features are computed from the render alone (R: its linear luminance),
//! so that any backend's image can be diagnosed; each effect builds its
//! own from [`Features`] (src/diagnose/effects/).
//!
//! The evidence of an effect is the R² of a least-squares regression of the
//! residual on its features (with an intercept).

use super::effects::Effect;
use super::features::{blur, Features};
use crate::metric::Mask;
use crate::raster::Image;
use crate::render::srgb::decode;

/// Linear residual and render luminance over the image.
pub struct Residual {
    pub width: usize,
    pub height: usize,
    /// target − render per channel, linear, row-major.
    pub signed: [Vec<f64>; 3],
    /// Linear luminance of the render.
    pub render: Vec<f64>,
    /// Pixels that count.
    pub pixels: Vec<usize>,
}

impl Residual {
    pub fn new(target: &Image, render: &Image, mask: Option<&Mask>) -> Residual {
        let (w, h) = (target.width() as usize, target.height() as usize);
        let lut: Vec<f64> = (0..=255u8).map(decode).collect();
        let (t, r) = (target.as_raw(), render.as_raw());
        let mut signed = [vec![0.0; w * h], vec![0.0; w * h], vec![0.0; w * h]];
        let mut lum = vec![0.0; w * h];
        for i in 0..w * h {
            for c in 0..3 {
                signed[c][i] = lut[t[3 * i + c] as usize] - lut[r[3 * i + c] as usize];
            }
            lum[i] =
                (lut[r[3 * i] as usize] + lut[r[3 * i + 1] as usize] + lut[r[3 * i + 2] as usize])
                    / 3.0;
        }
        let pixels = match mask {
            Some(m) => m.pixels().iter().map(|&p| p as usize).collect(),
            None => (0..w * h).collect(),
        };
        Residual {
            width: w,
            height: h,
            signed,
            render: lum,
            pixels,
        }
    }

    /// The residual averaged over channels.
    pub fn mean(&self) -> Vec<f64> {
        (0..self.width * self.height)
            .map(|i| (self.signed[0][i] + self.signed[1][i] + self.signed[2][i]) / 3.0)
            .collect()
    }

    /// R² of the residual on `effect`'s feature maps.
    pub fn evidence(&self, effect: &dyn Effect) -> f64 {
        let y = self.mean();
        let maps = effect.features(&self.features());
        if maps.is_empty() {
            return 0.0;
        }
        r_squared(&y, &maps, &self.pixels)
    }

    /// What the effects build their feature maps from.
    fn features(&self) -> Features<'_> {
        let (w, h) = (self.width as f64, self.height as f64);
        let half = ((w * w + h * h) / 4.0).sqrt();
        let mut xs = Vec::with_capacity(self.width * self.height);
        let mut ys = Vec::with_capacity(self.width * self.height);
        for y in 0..self.height {
            for x in 0..self.width {
                xs.push((x as f64 + 0.5 - w / 2.0) / half);
                ys.push((h / 2.0 - y as f64 - 0.5) / half);
            }
        }
        let r = &self.render;
        let peak = self
            .pixels
            .iter()
            .map(|&i| r[i])
            .fold(0.0, f64::max)
            .max(1e-9);
        Features {
            render: r,
            xs,
            ys,
            peak,
            width: self.width,
            height: self.height,
        }
    }

    /// True when smooth structure remains: the residual blurred over 2 px
    /// keeps most of its energy, and is larger than 8-bit rounding.
    pub fn structured(&self) -> bool {
        let y = self.mean();
        let b = blur(&y, self.width, self.height, 2);
        let n = self.pixels.len().max(1) as f64;
        let raw: f64 = self.pixels.iter().map(|&i| y[i] * y[i]).sum::<f64>() / n;
        let smooth: f64 = self.pixels.iter().map(|&i| b[i] * b[i]).sum::<f64>() / n;
        // 0.004 linear is about one 8-bit step at mid-grey.
        smooth.sqrt() > 0.004 && smooth > 0.5 * raw
    }

    /// A heatmap of the mean residual: red where the target is brighter,
    /// blue where darker, grey outside the mask; `scale` is the linear
    /// residual drawn at full colour.
    pub fn heatmap(&self, scale: f64) -> Image {
        let y = self.mean();
        let mut inside = vec![false; y.len()];
        for &p in &self.pixels {
            inside[p] = true;
        }
        Image::from_fn(self.width as u32, self.height as u32, |x, yy| {
            let i = yy as usize * self.width + x as usize;
            if !inside[i] {
                return image::Rgb([128, 128, 128]);
            }
            let v = (y[i] / scale.max(1e-9)).clamp(-1.0, 1.0);
            let a = (255.0 * (1.0 - v.abs())) as u8;
            if v >= 0.0 {
                image::Rgb([255, a, a])
            } else {
                image::Rgb([a, a, 255])
            }
        })
    }

    /// The largest absolute mean residual over the mask (a heatmap scale).
    pub fn peak(&self) -> f64 {
        let y = self.mean();
        self.pixels.iter().map(|&i| y[i].abs()).fold(0.0, f64::max)
    }
}

/// R² of y on the maps (plus an intercept) over `pixels`, by the normal
/// equations (a handful of features: Gaussian elimination suffices).
// Indices read as the algebra (normal equations, elimination).
#[allow(clippy::needless_range_loop)]
fn r_squared(y: &[f64], maps: &[Vec<f64>], pixels: &[usize]) -> f64 {
    let k = maps.len() + 1;
    let n = pixels.len() as f64;
    if n < (k + 2) as f64 {
        return 0.0;
    }
    let mean_y = pixels.iter().map(|&i| y[i]).sum::<f64>() / n;
    let tss: f64 = pixels.iter().map(|&i| (y[i] - mean_y).powi(2)).sum();
    if tss <= 0.0 {
        return 0.0;
    }
    let feat = |j: usize, i: usize| if j == 0 { 1.0 } else { maps[j - 1][i] };
    let mut a = vec![vec![0.0; k + 1]; k];
    for &i in pixels {
        for p in 0..k {
            let fp = feat(p, i);
            for q in 0..k {
                a[p][q] += fp * feat(q, i);
            }
            a[p][k] += fp * y[i];
        }
    }
    // Ridge-stabilised: features may be nearly collinear.
    for (p, row) in a.iter_mut().enumerate() {
        row[p] += 1e-9 * (1.0 + row[p].abs());
    }
    let Some(beta) = solve(a) else {
        return 0.0;
    };
    let rss: f64 = pixels
        .iter()
        .map(|&i| {
            let pred: f64 = (0..k).map(|j| beta[j] * feat(j, i)).sum();
            (y[i] - pred).powi(2)
        })
        .sum();
    (1.0 - rss / tss).clamp(0.0, 1.0)
}

#[allow(clippy::needless_range_loop)]
fn solve(mut a: Vec<Vec<f64>>) -> Option<Vec<f64>> {
    let k = a.len();
    for c in 0..k {
        let p = (c..k).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        if a[p][c].abs() < 1e-300 {
            return None;
        }
        a.swap(c, p);
        for r in 0..k {
            if r != c {
                let f = a[r][c] / a[c][c];
                for q in c..=k {
                    a[r][q] -= f * a[c][q];
                }
            }
        }
    }
    Some((0..k).map(|i| a[i][k] / a[i][i]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regression_finds_a_planted_feature() {
        let y: Vec<f64> = (0..100).map(|i| 0.3 * (i as f64) + 2.0).collect();
        let m = vec![(0..100).map(|i| i as f64).collect::<Vec<_>>()];
        let px: Vec<usize> = (0..100).collect();
        assert!(r_squared(&y, &m, &px) > 0.999);
    }
}
