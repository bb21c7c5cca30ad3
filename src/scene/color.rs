//! HSV <-> RGB, as the paper searches colours in HSV. Applied to linear RGB
//! values directly: `hsv(h, s, v)` with all three in [0, 1].

use super::types::Vec3;

/// HSV (each in [0, 1], hue wrapping) to RGB.
pub fn hsv_to_rgb([h, s, v]: Vec3) -> Vec3 {
    let h6 = (h.rem_euclid(1.0)) * 6.0;
    let sector = (h6.floor() as i32).clamp(0, 5);
    let f = h6 - sector as f64;
    let p = v * (1.0 - s);
    let q = v * (1.0 - s * f);
    let t = v * (1.0 - s * (1.0 - f));
    match sector {
        0 => [v, t, p],
        1 => [q, v, p],
        2 => [p, v, t],
        3 => [p, q, v],
        4 => [t, p, v],
        _ => [v, p, q],
    }
}

/// RGB to HSV (hue in [0, 1)); grey has hue 0 and saturation 0.
pub fn rgb_to_hsv([r, g, b]: Vec3) -> Vec3 {
    let max = r.max(g).max(b);
    let min = r.min(g).min(b);
    let d = max - min;
    let s = if max > 0.0 { d / max } else { 0.0 };
    let h = if d <= 0.0 {
        0.0
    } else if max == r {
        ((g - b) / d).rem_euclid(6.0) / 6.0
    } else if max == g {
        ((b - r) / d + 2.0) / 6.0
    } else {
        ((r - g) / d + 4.0) / 6.0
    };
    [h, s, max]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        for rgb in [
            [0.8, 0.7, 0.1],
            [0.1, 0.2, 0.9],
            [0.5, 0.5, 0.5],
            [0.9, 0.1, 0.3],
            [0.0, 0.0, 0.0],
        ] {
            let back = hsv_to_rgb(rgb_to_hsv(rgb));
            for c in 0..3 {
                assert!((back[c] - rgb[c]).abs() < 1e-12, "{rgb:?} -> {back:?}");
            }
        }
    }

    #[test]
    fn primaries() {
        assert_eq!(hsv_to_rgb([0.0, 1.0, 1.0]), [1.0, 0.0, 0.0]);
        let g = hsv_to_rgb([1.0 / 3.0, 1.0, 1.0]);
        assert!((g[1] - 1.0).abs() < 1e-12 && g[0].abs() < 1e-12);
    }
}
