//! Imitations named: which effects a round tried explain the same residual
//! as the one it accepted (diagnosis.json's `imitations`, and the report's
//! line), measured by the correlation of the changes their refits made to
//! the render. Why: a model that lacks a camera's response bends a
//! specular lobe or blurs its light to imitate it; a user reading the
//! diagnosis should see which effects stood in for each other and why one
//! was chosen, not only the winner.

pub use super::diagnosis::Imitation;
use super::Candidate;
use crate::metric::Mask;
use crate::raster::Image;

/// Correlation above which two effects' changes count as one explanation.
const SAME: f64 = 0.7;

/// One photograph's render before a round, after one candidate's refit
/// and after another's, with its mask.
pub type Views<'a> = (&'a Image, &'a Image, &'a Image, Option<&'a Mask>);

/// The correlation of the changes `a − before` and `b − before` over the
/// masks' channel values of every photograph.
pub fn correlation<'a>(views: impl IntoIterator<Item = Views<'a>>) -> f64 {
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (before, a, b, mask) in views {
        let (p, x, y) = (before.as_raw(), a.as_raw(), b.as_raw());
        let n = (before.width() * before.height()) as usize;
        let inside = Mask::counted(mask, n);
        for i in (0..n).filter(|&i| inside[i]) {
            for c in 0..3 {
                let j = 3 * i + c;
                let (da, db) = (x[j] as f64 - p[j] as f64, y[j] as f64 - p[j] as f64);
                sab += da * db;
                saa += da * da;
                sbb += db * db;
            }
        }
    }
    if saa <= 0.0 || sbb <= 0.0 {
        return 0.0;
    }
    sab / (saa * sbb).sqrt()
}

/// The round's candidates whose changes correlate with the accepted one's
/// (`chosen`) above [`SAME`], each explaining part of the residual (SAD
/// down), with the reason the criterion gave; `corr(i)` measures candidate
/// `i` against the chosen.
pub fn named(
    candidates: &[Candidate],
    chosen: usize,
    corr: impl Fn(usize) -> f64,
) -> Vec<Imitation> {
    let c = &candidates[chosen];
    let bic = |x: &Candidate| x.delta_bic.unwrap_or(0.0);
    candidates
        .iter()
        .enumerate()
        .filter(|&(i, o)| i != chosen && o.gain.is_some_and(|g| g > 0.0))
        .filter_map(|(i, o)| {
            let r = corr(i);
            (r >= SAME).then(|| Imitation {
                round: c.round,
                chosen: c.effect.clone(),
                other: o.effect.clone(),
                correlation: r,
                reason: format!(
                    "{} and {} explain the same residual (correlation {r:.2}); {} chosen: its criterion change {:.1} against {:.1}, SAD down {:.1} % against {:.1} %, {} against {} added values",
                    c.effect,
                    o.effect,
                    c.effect,
                    bic(c),
                    bic(o),
                    100.0 * c.gain.unwrap_or(0.0),
                    100.0 * o.gain.unwrap_or(0.0),
                    c.added_params,
                    o.added_params
                ),
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(v: [u8; 4]) -> Image {
        Image::from_fn(2, 2, |x, y| {
            let l = v[(y * 2 + x) as usize];
            image::Rgb([l, l, l])
        })
    }

    #[test]
    fn the_same_change_correlates_and_an_unrelated_one_does_not() {
        let before = flat([10, 10, 10, 10]);
        let a = flat([20, 10, 30, 10]);
        let same = flat([15, 10, 20, 10]);
        let other = flat([10, 20, 10, 30]);
        let r = correlation([(&before, &a, &same, None)]);
        assert!((r - 1.0).abs() < 1e-9, "{r}");
        let r = correlation([(&before, &a, &other, None)]);
        assert!(r.abs() < 1e-9, "{r}");
    }
}
