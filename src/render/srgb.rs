//! The sRGB transfer function: linear radiance to 8-bit values, as every
//! backend writes its PNGs, and back.

/// sRGB-encodes a linear value (clamped to [0, 1]) to 8 bits, exactly.
pub fn encode(x: f64) -> u8 {
    let x = x.clamp(0.0, 1.0);
    let s = if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5) as u8
}

/// The linear value of an 8-bit sRGB code.
pub fn decode(v: u8) -> f64 {
    let s = v as f64 / 255.0;
    if s <= 0.04045 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

/// Fast exact encoding: a table of the 255 linear thresholds between
/// successive codes, searched in 8 steps. `encode` costs a `powf`; this
/// costs a few comparisons and gives the same byte.
pub struct Encoder {
    thresholds: [f32; 256],
    /// The code of the start of each of LUT_SIZE equal linear buckets; a
    /// bucket is narrower than the gap between two thresholds, so one
    /// comparison finishes the job.
    lut: Vec<u8>,
}

const LUT_SIZE: usize = 8192;

impl Default for Encoder {
    fn default() -> Self {
        Self::new()
    }
}

impl Encoder {
    pub fn new() -> Encoder {
        let mut thresholds = [f32::INFINITY; 256];
        // thresholds[k] = the smallest linear value that encodes to k + 1.
        for (k, t) in thresholds.iter_mut().enumerate().take(255) {
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if encode(mid) as usize > k {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            *t = hi as f32;
        }
        let mut e = Encoder {
            thresholds,
            lut: Vec::new(),
        };
        e.lut = (0..LUT_SIZE)
            .map(|i| e.search(i as f32 / LUT_SIZE as f32))
            .collect();
        e
    }

    #[inline]
    pub fn encode(&self, x: f32) -> u8 {
        let i = ((x * LUT_SIZE as f32) as usize).min(LUT_SIZE - 1); // NaN and negatives go to 0
        let k = self.lut[i];
        if x >= self.thresholds[k as usize] {
            k + 1
        } else {
            k
        }
    }

    fn search(&self, x: f32) -> u8 {
        // Binary search over 256 entries.
        let mut i = 0usize;
        let mut step = 128;
        while step > 0 {
            if x >= self.thresholds[i + step - 1] {
                i += step;
            }
            step >>= 1;
        }
        i as u8
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_encodes_to_188() {
        assert_eq!(encode(0.5), 188);
        assert_eq!(encode(0.0), 0);
        assert_eq!(encode(1.0), 255);
        assert_eq!(encode(2.0), 255);
    }

    #[test]
    fn table_matches_exact() {
        let e = Encoder::new();
        for i in 0..=20000 {
            let x = i as f64 / 20000.0;
            let (a, b) = (encode(x), e.encode(x as f32));
            assert!((a as i32 - b as i32).abs() <= 1, "{x}: {a} vs {b}");
        }
        for k in 0..=255u8 {
            assert_eq!(e.encode(decode(k) as f32), k);
        }
    }
}
