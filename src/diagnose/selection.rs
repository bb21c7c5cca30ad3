//! Choosing between models: the sum of absolute differences from the
//! target, the Bayesian information criterion on it (the fit minimises
//! absolute differences, so errors are taken as Laplace:
//! `BIC = 2N ln(SAD/N) + k ln N`), and which candidate a round accepts.
//!
//! Neighbouring pixels' residuals are not independent (a misfit is smooth
//! over the image), so N channel values carry less evidence than N
//! independent ones. As in quasi-likelihood criteria (QAIC), the
//! log-likelihood is divided by an overdispersion ĉ, here the variance
//! inflation of a spatially correlated residual, estimated once a round on
//! the most general model tried (the lowest SAD):
//! `QBIC = 2(N/ĉ) ln(SAD/N) + k ln(N/ĉ)`. On white noise ĉ is 1 and this
//! is the BIC; on a smooth misfit it keeps a map of many values from
//! being paid for by evidence counted once per pixel.

use super::inputs::SetInputs;
use super::model::Model;
use super::{Candidate, DiagnoseConfig};
use crate::metric::Mask;
use crate::raster::Image;

/// The sum of absolute differences over the mask's channel values.
pub fn sad(target: &Image, render: &Image, mask: Option<&Mask>) -> f64 {
    let (t, r) = (target.as_raw(), render.as_raw());
    let d = |i: usize| t[i].abs_diff(r[i]) as f64;
    match mask {
        Some(m) => m
            .pixels()
            .iter()
            .map(|&p| (0..3).map(|c| d(3 * p as usize + c)).sum::<f64>())
            .sum(),
        None => (0..t.len()).map(d).sum(),
    }
}

/// N: the channel values that count.
pub fn samples(target: &Image, mask: Option<&Mask>) -> f64 {
    3.0 * mask.map_or((target.width() * target.height()) as usize, |m| {
        m.pixels().len()
    }) as f64
}

/// The criterion's N over a set: the channel values counted over every
/// photograph fitted.
pub(super) fn channel_values(inputs: &SetInputs) -> f64 {
    let counted =
        |s: &crate::fit::set::shots::Shot| samples(&s.target.image, s.target.mask.as_ref());
    inputs.shots.iter().map(counted).sum()
}

/// The criterion's change from a model with SAD `sad0` to one with SAD
/// `sad1` and `added` more free values, over `n` channel values whose
/// overdispersion is `c` (1: independent).
pub fn delta_bic(sad0: f64, sad1: f64, n: f64, added: usize, c: f64) -> f64 {
    let m = n / c.max(1.0);
    2.0 * m * (sad1.max(1e-9) / sad0.max(1e-9)).ln() + added as f64 * m.ln()
}

/// Each candidate's criterion change from the model with SAD `sad0`, its
/// refit's SAD in `sads` (in order), over `n` channel values, with the
/// round's overdispersion: `overdispersion_of(i)` of the lowest-SAD
/// candidate `i`, the most general model tried.
pub fn weigh(
    candidates: &mut [Candidate],
    sads: &[f64],
    sad0: f64,
    n: f64,
    overdispersion_of: impl FnOnce(usize) -> f64,
) {
    let Some(general) = (0..sads.len()).min_by(|&a, &b| sads[a].total_cmp(&sads[b])) else {
        return;
    };
    let c = overdispersion_of(general);
    for (cand, &sad) in candidates.iter_mut().zip(sads) {
        cand.delta_bic = Some(delta_bic(sad0, sad, n, cand.added_params, c));
        cand.overdispersion = Some(c);
    }
}

/// Largest lag-one correlation counted: beyond it the estimate says only
/// "smooth", and ĉ stays finite (at most 361).
const MAX_RHO: f64 = 0.9;

/// The overdispersion ĉ of residuals (target − render in the metric's
/// 8-bit codes, per channel about its mean): with ρx and ρy the lag-one
/// correlations of horizontally and vertically adjacent pixels inside the
/// mask, the variance inflation of a separable first-order correlated
/// field, `(1+ρx)/(1−ρx) · (1+ρy)/(1−ρy)`, at least 1.
pub fn overdispersion<'a>(
    pairs: impl IntoIterator<Item = (&'a Image, &'a Image, Option<&'a Mask>)>,
) -> f64 {
    let (mut sx, mut sy, mut s0) = (0.0, 0.0, 0.0);
    for (target, render, mask) in pairs {
        let (w, h) = (target.width() as usize, target.height() as usize);
        let inside = Mask::counted(mask, w * h);
        let (t, r) = (target.as_raw(), render.as_raw());
        for c in 0..3 {
            let d = |i: usize| t[3 * i + c] as f64 - r[3 * i + c] as f64;
            let (sum, count) = (0..w * h)
                .filter(|&i| inside[i])
                .fold((0.0, 0.0), |(s, n), i| (s + d(i), n + 1.0));
            if count == 0.0 {
                continue;
            }
            let mean = sum / count;
            let e = |i: usize| d(i) - mean;
            for y in 0..h {
                for x in 0..w {
                    let i = y * w + x;
                    if !inside[i] {
                        continue;
                    }
                    let ei = e(i);
                    s0 += ei * ei;
                    if x + 1 < w && inside[i + 1] {
                        sx += ei * e(i + 1);
                    }
                    if y + 1 < h && inside[i + w] {
                        sy += ei * e(i + w);
                    }
                }
            }
        }
    }
    if s0 <= 0.0 {
        return 1.0;
    }
    let inflation = |rho: f64| {
        let r = rho.clamp(0.0, MAX_RHO);
        (1.0 + r) / (1.0 - r)
    };
    inflation(sx / s0) * inflation(sy / s0)
}

/// ĉ of `model`'s residuals over every photograph of `inputs`: the one
/// measure the rounds, the backward step, the footing and the map's sides
/// all take, so that their criteria stay comparable.
pub(super) fn overdispersion_of(model: &Model, inputs: &SetInputs) -> f64 {
    let pairs = model.images.iter().zip(&inputs.shots);
    overdispersion(pairs.map(|(img, s)| (&s.target.image, img, s.target.mask.as_ref())))
}

/// True when a candidate's refit earns its parameters: BIC lower by more
/// than the margin and SAD down by at least `min_gain`.
pub fn acceptable(c: &Candidate, config: &DiagnoseConfig) -> bool {
    c.delta_bic.is_some_and(|d| d < -config.bic_margin)
        && c.gain.is_some_and(|g| g >= config.min_gain)
}

/// The acceptable candidate with the lowest BIC, if any.
pub fn choose(tried: &[Candidate], config: &DiagnoseConfig) -> Option<usize> {
    tried
        .iter()
        .enumerate()
        .filter(|(_, c)| acceptable(c, config))
        .min_by(|a, b| {
            a.1.delta_bic
                .unwrap_or(0.0)
                .total_cmp(&b.1.delta_bic.unwrap_or(0.0))
        })
        .map(|(i, _)| i)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn candidate(delta_bic: f64, gain: f64) -> Candidate {
        Candidate {
            effect: "x".into(),
            evidence: 0.0,
            deviation_after: None,
            round: 1,
            delta_bic: Some(delta_bic),
            overdispersion: Some(1.0),
            gain: Some(gain),
            added_params: 1,
            accepted: false,
            refit: "warm".into(),
            footing: None,
        }
    }

    #[test]
    fn the_lowest_bic_of_the_acceptable_wins() {
        let config = DiagnoseConfig::default();
        let tried = [
            candidate(-50.0, 0.01), // too small a gain
            candidate(-20.0, 0.2),
            candidate(-5.0, 0.5), // within the margin
            candidate(-30.0, 0.06),
        ];
        assert_eq!(choose(&tried, &config), Some(3));
        assert_eq!(choose(&tried[..1], &config), None);
    }

    #[test]
    fn more_parameters_cost_ln_n_each() {
        let n = 1000.0;
        assert!((delta_bic(50.0, 50.0, n, 1, 1.0) - n.ln()).abs() < 1e-9);
        assert!(delta_bic(50.0, 40.0, n, 0, 1.0) < 0.0);
    }

    #[test]
    fn overdispersion_divides_the_evidence_and_the_count() {
        let n = 1000.0;
        let plain = delta_bic(50.0, 40.0, n, 2, 1.0);
        let over = delta_bic(50.0, 40.0, n, 2, 4.0);
        let expect = 2.0 * 250.0 * 0.8f64.ln() + 2.0 * 250f64.ln();
        assert!((over - expect).abs() < 1e-9, "{over} vs {expect}");
        assert!(over > plain);
    }

    /// A 64x64 residual: independent noise, or the same noise smoothed.
    fn residual_pair(smooth: bool) -> (Image, Image) {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let (w, h) = (64usize, 64usize);
        let noise: Vec<f64> = (0..w * h).map(|_| rng.gen_range(-20.0..20.0)).collect();
        let value = |x: usize, y: usize| -> f64 {
            if !smooth {
                return noise[y * w + x];
            }
            let mut s = 0.0;
            for dy in 0..4 {
                for dx in 0..4 {
                    s += noise[((y + dy) % h) * w + (x + dx) % w];
                }
            }
            s / 4.0
        };
        let target = Image::from_fn(w as u32, h as u32, |x, y| {
            let v = (128.0 + value(x as usize, y as usize)).round() as u8;
            image::Rgb([v, v, v])
        });
        let flat = Image::from_fn(w as u32, h as u32, |_, _| image::Rgb([128, 128, 128]));
        (target, flat)
    }

    #[test]
    fn independent_noise_is_not_overdispersed_and_smooth_residual_is() {
        let (t, r) = residual_pair(false);
        let white = overdispersion([(&t, &r, None)]);
        assert!(white < 1.2, "white noise: c = {white}");
        let (t, r) = residual_pair(true);
        let smooth = overdispersion([(&t, &r, None)]);
        // A 4x4 box over white noise: lag-one correlation 3/4 each way,
        // so c = 7 * 7 = 49 (less a little for the 8-bit rounding).
        assert!((35.0..=55.0).contains(&smooth), "smoothed: c = {smooth}");
    }
}
