//! The maps an effect's evidence is built from: the render's linear
//! luminance, pixel coordinates, and the smoothings every effect shares.

/// The maps an effect's features are made of, over the image (row-major).
pub struct Features<'a> {
    /// R: the render's linear luminance.
    pub render: &'a [f64],
    /// Pixel centres from the image centre over the half-diagonal, y up.
    pub xs: Vec<f64>,
    pub ys: Vec<f64>,
    /// The largest R over the mask.
    pub peak: f64,
    pub width: usize,
    pub height: usize,
}

impl Features<'_> {
    /// A map with `f(i)` at pixel `i`.
    pub fn map(&self, f: impl Fn(usize) -> f64) -> Vec<f64> {
        (0..self.render.len()).map(f).collect()
    }

    /// `src` box-blurred over radius `r`.
    pub fn blur(&self, src: &[f64], r: usize) -> Vec<f64> {
        blur(src, self.width, self.height, r)
    }

    /// R·x, R·y, R·x², R·y²: a smooth multiplicative ramp over the image
    /// (a light's irradiance changing across the scene).
    pub fn ramp(&self) -> Vec<Vec<f64>> {
        let (r, xs, ys) = (self.render, &self.xs, &self.ys);
        vec![
            self.map(|i| r[i] * xs[i]),
            self.map(|i| r[i] * ys[i]),
            self.map(|i| r[i] * xs[i] * xs[i]),
            self.map(|i| r[i] * ys[i] * ys[i]),
        ]
    }

    /// The highlight excess S = max(0, R − blur R) and its blur over 2 and
    /// 5 px.
    pub fn highlight(&self) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let r = self.render;
        let base = self.blur(r, 3);
        let s: Vec<f64> = self.map(|i| (r[i] - base[i]).max(0.0));
        let s1 = self.blur(&s, 2);
        let s2 = self.blur(&s, 5);
        (s, s1, s2)
    }
}

/// Box blur of radius `r` (separable, edges clamped).
pub fn blur(src: &[f64], w: usize, h: usize, r: usize) -> Vec<f64> {
    let pass = |src: &[f64], horizontal: bool| -> Vec<f64> {
        let mut out = vec![0.0; src.len()];
        for y in 0..h {
            for x in 0..w {
                let (mut sum, mut cnt) = (0.0, 0.0);
                let (c, len) = if horizontal { (x, w) } else { (y, h) };
                let lo = c.saturating_sub(r);
                let hi = (c + r).min(len - 1);
                for k in lo..=hi {
                    let i = if horizontal { y * w + k } else { k * w + x };
                    sum += src[i];
                    cnt += 1.0;
                }
                out[y * w + x] = sum / cnt;
            }
        }
        out
    };
    pass(&pass(src, true), false)
}
