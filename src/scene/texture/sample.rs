//! A map's texels and their lookup: bilinear between the four nearest
//! texel centres, with repeat wrap (the texture tiles the plane of texture
//! coordinates). The convention, the same in every backend: u runs left
//! to right across the image, v bottom to top; texel (column i, row j,
//! rows counted from the top) has its centre at u = (i + 1/2) / W,
//! v = 1 - (j + 1/2) / H; (u, v) and (u + 1, v + 1) are the same point.

/// A map's linear values, RGB per texel, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Texels {
    pub width: u32,
    pub height: u32,
    pub values: Vec<f32>,
}

impl Texels {
    /// The RGB value at texel (i, j), both already wrapped.
    #[inline]
    fn at(&self, i: usize, j: usize) -> [f32; 3] {
        let k = 3 * (j * self.width as usize + i);
        [self.values[k], self.values[k + 1], self.values[k + 2]]
    }

    /// The bilinear value at (u, v), repeat wrap.
    pub fn sample(&self, u: f64, v: f64) -> [f32; 3] {
        let (w, h) = (self.width as f64, self.height as f64);
        let x = u * w - 0.5;
        let y = (1.0 - v) * h - 0.5;
        if !(x.is_finite() && y.is_finite()) {
            return self.at(0, 0);
        }
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
        let wrap = |a: f64, n: f64| a.rem_euclid(n) as usize;
        let (i0, j0) = (wrap(x0, w), wrap(y0, h));
        let (i1, j1) = (wrap(x0 + 1.0, w), wrap(y0 + 1.0, h));
        let (a, b, c, d) = (
            self.at(i0, j0),
            self.at(i1, j0),
            self.at(i0, j1),
            self.at(i1, j1),
        );
        let mut out = [0f32; 3];
        for k in 0..3 {
            let top = a[k] + (b[k] - a[k]) * fx;
            let bottom = c[k] + (d[k] - c[k]) * fx;
            out[k] = top + (bottom - top) * fy;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 2x2: top row red, green; bottom row blue, white.
    fn quad() -> Texels {
        Texels {
            width: 2,
            height: 2,
            values: vec![1., 0., 0., 0., 1., 0., 0., 0., 1., 1., 1., 1.],
        }
    }

    #[test]
    fn texel_centres_return_their_texel_and_v_runs_upwards() {
        let t = quad();
        assert_eq!(t.sample(0.25, 0.75), [1.0, 0.0, 0.0]); // top left
        assert_eq!(t.sample(0.75, 0.75), [0.0, 1.0, 0.0]); // top right
        assert_eq!(t.sample(0.25, 0.25), [0.0, 0.0, 1.0]); // bottom left
        assert_eq!(t.sample(1.25, -0.75), [0.0, 0.0, 1.0]); // repeated
    }

    #[test]
    fn between_centres_the_value_is_bilinear_and_wraps_at_the_edges() {
        let t = quad();
        let mid = t.sample(0.5, 0.5);
        assert!(mid.iter().all(|&x| (x - 0.5).abs() < 1e-6), "{mid:?}");
        // u = 0 lies halfway between the last column and the first
        let edge = t.sample(0.0, 0.75);
        assert!((edge[0] - 0.5).abs() < 1e-6 && (edge[1] - 0.5).abs() < 1e-6);
    }
}
