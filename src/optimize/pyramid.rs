//! The coarse-to-fine schedule of a local run: when a difference
//! column is noise, it minimises the residuals of blurred images first
//! ([`BLUR_START`] pixels), then halves the blur down to none, each level
//! starting where the last one ended.
//!
//! Why: a parameter that moves edges (a camera's, an object's pose, a
//! thin shadow's light) changes an anti-aliased 8-bit image in steps of a
//! sample, so its forward and backward differences disagree value by
//! value at every step length (docs/results.md, "Why the local phase
//! stalls there"): the Jacobian is noise and Levenberg–Marquardt stalls
//! short of the minimum. On images blurred by a few pixels the same
//! differences agree, and the blurred problem has its minimum where the
//! sharp one has (a render that matches matches blurred too). The blur is
//! in pixels because the steps it smooths are a pixel's samples; the
//! metric applies it (`metric::blur`), the search only names it.
//!
//! **When.** Automatically: a sharp Jacobian with a column that is noise
//! ([`rough`]: among its resolved columns, one whose forward and backward
//! differences have a cosine below [`AGREE_MIN`]) sends the run to the
//! coarsest level (each local run decides at its own first sharp
//! Jacobian). One
//! such column is enough: the step along it is noise whatever the others
//! are (on a thin shadow the sun's three direction columns agree at
//! 0.0–0.3 while the intensity's and the floor colour's four agree at 1.00,
//! and a median over the seven said smooth). On a landscape whose columns
//! all agree (shading, a light's intensity) nothing changes: not one
//! render more.

/// The first level's blur, in pixels (a Gaussian's standard deviation).
pub const BLUR_START: f64 = 4.0;
/// A level whose halved blur would be below this is followed by the sharp
/// one (4, 2, 1, then 0).
pub const BLUR_LAST: f64 = 0.75;
/// A column agreeing less than this is noise.
pub const AGREE_MIN: f64 = 0.5;

/// The level after `blur`: half of it, or 0 (sharp) below [`BLUR_LAST`].
pub fn next_level(blur: f64) -> f64 {
    let half = 0.5 * blur;
    if half < BLUR_LAST {
        0.0
    } else {
        half
    }
}

/// What a run minimises at a blurred level, in the fitness's units (the
/// sum of the three channel deviations, percent): the mean absolute
/// residual, ×3 channels, as a share of 255 levels. Infinite without
/// residuals (a failed render).
pub fn merit(residuals: Option<&[f32]>) -> f64 {
    match residuals {
        Some(r) if !r.is_empty() => {
            let sum: f64 = r.iter().map(|v| f64::from(v.abs())).sum();
            300.0 * sum / (255.0 * r.len() as f64)
        }
        _ => f64::INFINITY,
    }
}

/// The cosine between the slopes a column's two neighbours see: `a` at
/// signed offset `s`, `b` at `t`, from the point's residuals `r`. 1 when
/// both see the same slope in every value; `None` when either moved
/// nothing (a coordinate the image ignores, or a failed render).
pub fn agreement(r: &[f32], (a, s): (&[f32], f64), (b, t): (&[f32], f64)) -> Option<f64> {
    if a.len() != r.len() || b.len() != r.len() || s == 0.0 || t == 0.0 {
        return None;
    }
    let (mut ab, mut aa, mut bb) = (0.0, 0.0, 0.0);
    for ((&r, &a), &b) in r.iter().zip(a).zip(b) {
        let x = f64::from(a - r) / s;
        let y = f64::from(b - r) / t;
        ab += x * y;
        aa += x * x;
        bb += y * y;
    }
    (aa > 0.0 && bb > 0.0).then(|| ab / (aa * bb).sqrt())
}

/// Whether a Jacobian has a column that is noise: one of the agreements
/// given (one per resolved column) below [`AGREE_MIN`]. None given: not
/// known to be rough.
pub fn rough(agreements: &[f64]) -> bool {
    agreements.iter().any(|&a| a < AGREE_MIN)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_levels_halve_down_to_sharp() {
        let mut levels = vec![BLUR_START];
        while *levels.last().unwrap() > 0.0 {
            levels.push(next_level(*levels.last().unwrap()));
        }
        assert_eq!(levels, vec![4.0, 2.0, 1.0, 0.0]);
    }

    #[test]
    fn merit_is_the_fitness_of_its_residuals() {
        // One pixel off by 51 levels in red of four pixels: 5 % in red.
        let mut r = vec![0f32; 12];
        r[0] = 51.0;
        assert!((merit(Some(&r)) - 5.0).abs() < 1e-12);
        assert_eq!(merit(None), f64::INFINITY);
    }

    #[test]
    fn a_smooth_column_agrees_and_a_staircase_does_not() {
        // A ramp seen at ±1: both slopes equal.
        let r: Vec<f32> = (0..50).map(|i| i as f32).collect();
        let up: Vec<f32> = r.iter().map(|v| v + 2.0).collect();
        let down: Vec<f32> = r.iter().map(|v| v - 2.0).collect();
        let smooth = agreement(&r, (&up, 1.0), (&down, -1.0)).unwrap();
        assert!((smooth - 1.0).abs() < 1e-9, "{smooth}");
        // An edge that moves in sample steps: the forward step flips some
        // values, the backward step others.
        let fwd: Vec<f32> = (0..50)
            .map(|i| r[i] + if i % 2 == 0 { 4.0 } else { 0.0 })
            .collect();
        let back: Vec<f32> = (0..50)
            .map(|i| r[i] - if i % 2 == 1 { 4.0 } else { 0.0 })
            .collect();
        let stairs = agreement(&r, (&fwd, 1.0), (&back, -1.0)).unwrap();
        assert!(stairs.abs() < 1e-9, "{stairs}");
        // One noisy column among smooth ones is enough (a thin shadow's
        // light direction among the floor's colour).
        assert!(rough(&[stairs, stairs, smooth]) && rough(&[smooth, smooth, smooth, stairs]));
        assert!(!rough(&[smooth, smooth, smooth]));
        assert!(!rough(&[]));
        assert_eq!(agreement(&r, (&r, 1.0), (&down, -1.0)), None);
    }
}
