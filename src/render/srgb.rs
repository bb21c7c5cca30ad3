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
