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

/// Buckets of the linear range in [`encode_exact`]'s table.
const BUCKETS: usize = 4096;

/// [`encode`]'s result without its power: the code from a table of where
/// each code starts, found from a coarse table of the linear range. The
/// same as `encode` (up to rounding of a value exactly on a boundary), for
/// image-space passes that must match the exact encoding.
pub fn encode_exact(x: f64) -> u8 {
    struct Table {
        /// Least linear value of each code above 0.
        starts: [f64; 256],
        /// The code of each bucket's lowest value.
        first: [u8; BUCKETS + 1],
    }
    static TABLE: std::sync::OnceLock<Table> = std::sync::OnceLock::new();
    let t = TABLE.get_or_init(|| {
        // Code k starts where s * 255 + 0.5 reaches k.
        let starts = std::array::from_fn(|k| match k {
            0 => f64::NEG_INFINITY,
            _ => {
                let s = (k as f64 - 0.5) / 255.0;
                if s <= 12.92 * 0.0031308 {
                    s / 12.92
                } else {
                    ((s + 0.055) / 1.055).powf(2.4)
                }
            }
        });
        let first = std::array::from_fn(|i| encode(i as f64 / BUCKETS as f64));
        Table { starts, first }
    });
    // NaN becomes 0, as `encode`'s clamp and `as` make it.
    let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    let mut code = t.first[(x * BUCKETS as f64) as usize];
    while code < 255 && x >= t.starts[code as usize + 1] {
        code += 1;
    }
    // A value just below a bucket's edge by rounding of the product.
    while code > 0 && x < t.starts[code as usize] {
        code -= 1;
    }
    code
}

/// Coefficients of 1.055 * t^(5/3) - 0.055 as a degree-5 polynomial in
/// t = x^(1/4) over [0.0031308^(1/4), 1] (a Chebyshev fit; its largest
/// error is 0.0045 of an 8-bit step).
const POLY: [f32; 6] = [
    -0.061_700_27,
    0.165_346_22,
    1.243_955_8,
    -0.558_902_5,
    0.275_238_13,
    -0.063_948_42,
];

/// sRGB-encodes without a `powf` or a table: two square roots and a
/// polynomial, in a form the compiler vectorises. Equal to `encode` except
/// for values within 0.005 of a step from a rounding boundary, which may
/// land one code apart.
#[inline(always)]
pub fn encode_fast(x: f32) -> u8 {
    // max/min (unlike clamp) turn NaN into 0.
    #[allow(clippy::manual_clamp)]
    let x = x.max(0.0).min(1.0);
    let t = x.sqrt().sqrt();
    let p = POLY[0] + t * (POLY[1] + t * (POLY[2] + t * (POLY[3] + t * (POLY[4] + t * POLY[5]))));
    let s = if x <= 0.003_130_8 { 12.92 * x } else { p };
    #[allow(clippy::manual_clamp)] // clamp keeps NaN; this cannot see one, but stays uniform
    let v = (s * 255.0 + 0.5).max(0.0).min(255.0);
    // SAFETY: v is finite and within [0, 255]. The unchecked conversion
    // vectorises; `as`, which must saturate, does not.
    unsafe { v.to_int_unchecked::<i32>() as u8 }
}

/// Encodes a run of values.
pub fn encode_slice(src: &[f32], dst: &mut [u8]) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2, checked just above.
            unsafe { encode_slice_avx2(src, dst) };
            return;
        }
    }
    encode_slice_kernel(src, dst);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn encode_slice_avx2(src: &[f32], dst: &mut [u8]) {
    encode_slice_kernel(src, dst);
}

#[inline(always)]
fn encode_slice_kernel(src: &[f32], dst: &mut [u8]) {
    for (d, &s) in dst.iter_mut().zip(src) {
        *d = encode_fast(s);
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
    fn the_exact_table_matches_encode() {
        let n = 2_000_000;
        let mut off = 0;
        for i in 0..=n {
            // Even steps, and values clustered near 0 where codes are narrow.
            for x in [i as f64 / n as f64, (i as f64 / n as f64).powi(3)] {
                off += (encode_exact(x) != encode(x)) as usize;
            }
        }
        assert!(off <= 2, "{off} values differ");
        for k in 0..=255u8 {
            assert_eq!(encode_exact(decode(k)), k);
        }
        assert_eq!(encode_exact(f64::NAN), encode(f64::NAN));
        assert_eq!(encode_exact(-1.0), 0);
        assert_eq!(encode_exact(7.0), 255);
    }

    #[test]
    fn fast_matches_exact_but_at_boundaries() {
        let mut off = 0;
        let n = 1_000_000;
        for i in 0..=n {
            let x = i as f64 / n as f64;
            let (a, b) = (encode(x), encode_fast(x as f32));
            assert!((a as i32 - b as i32).abs() <= 1, "{x}: {a} vs {b}");
            off += (a != b) as usize;
        }
        assert!(off < n / 200, "{off} of {n} values one code off");
        for k in 0..=255u8 {
            assert_eq!(encode_fast(decode(k) as f32), k);
        }
        assert_eq!(encode_fast(f32::NAN), 0);
        assert_eq!(encode_fast(-1.0), 0);
        assert_eq!(encode_fast(7.0), 255);
    }
}
