//! A solved map's side (`albedo.rs`) scored by how well the map predicts
//! photographs left out of its solve: the photographs are dealt into
//! `FOLDS` groups, the map solved from all but one group and each pixel
//! of that group predicted through it (`texels.rs`'s linear model:
//! target = dark + m (lit - dark)), the absolute deviations in levels
//! summed over every group. The side with the least is offered;
//! `albedo.rs` keeps it when the criterion pays for it once refitted.
//!
//! Why not the criterion alone: a map too coarse for its texture leaves a
//! residual along every edge, which the criterion's overdispersion reads
//! as noise, so it charged each finer texel as if the residual were noise
//! and kept a side too coarse to draw the pattern (a textured plane: side
//! 16 for a 6 x 6 checker, the deviation only halved, where side 64 cut
//! it to a quarter). A prediction of unseen photographs needs no model of
//! the noise: a texel that only fits noise, or that no other photograph
//! saw, predicts worse than the coarser texel it replaces. It needs no
//! render either: the lit and dark renders the solve reads are the same
//! for every side.

use super::texel_fit::{Levels, Sample};
use super::texel_layout::Layout;
use super::texels::{samples, solve_samples, Evidence, ObjectMap};
use crate::scene::texture::MapKind;
use crate::scene::Response;

/// Groups the photographs are dealt into (photograph k in group k mod
/// `FOLDS`; fewer when there are fewer photographs): five solves a side
/// whatever the size of the set, each from four fifths of it.
const FOLDS: usize = 5;

/// The deviation, in levels summed over the counted pixels that see a
/// laid-out object, of each photograph from its prediction by the maps
/// of `kind` at `layouts` solved without its group.
pub fn held_out_sad(
    evidence: &[Evidence],
    layouts: &[Option<Layout>],
    response: Option<Response>,
    kind: MapKind,
) -> f64 {
    let (all, n, sad) = samples(evidence, layouts);
    let levels = Levels::new(response);
    held_out(&all, evidence.len(), layouts, (n, sad), &levels, kind)
}

/// `held_out_sad` from each object's samples of `photos` photographs.
fn held_out(
    all: &[Vec<Sample>],
    photos: usize,
    layouts: &[Option<Layout>],
    totals: (f64, f64),
    levels: &Levels,
    kind: MapKind,
) -> f64 {
    let folds = FOLDS.min(photos).max(1);
    let mut total = 0.0;
    for fold in 0..folds {
        let out = |s: &Sample| s.photo as usize % folds == fold;
        let train: Vec<Vec<Sample>> = all
            .iter()
            .map(|o| o.iter().filter(|s| !out(s)).copied().collect())
            .collect();
        let maps = solve_samples(&train, layouts, totals, levels, kind);
        for (object, samples) in all.iter().enumerate() {
            let map = maps.iter().find(|m| m.object == object);
            total += samples
                .iter()
                .filter(|s| out(s))
                .map(|s| deviation(s, map, levels))
                .sum::<f64>();
        }
    }
    total
}

/// A sample's deviation in levels, over its three channels, from its
/// prediction through `map` (None: every texel 1, the scalar value).
fn deviation(s: &Sample, map: Option<&ObjectMap>, levels: &Levels) -> f64 {
    let lin = &levels.linear;
    (0..3)
        .map(|c| {
            let m: f64 = map.map_or(1.0, |map| {
                (0..4)
                    .map(|j| s.weights[j] as f64 * map.values[3 * s.texels[j] as usize + c] as f64)
                    .sum()
            });
            let [t, l, d] = s.levels[c];
            let (ll, dl) = (lin[l as usize], lin[d as usize]);
            t.abs_diff(levels.level(dl + m * (ll - dl))) as f64
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Samples of one object whose true multiplier is `truth(u)`, seen by
    /// six photographs, each at its own 40 x 40 points (a camera that
    /// moves) under its own light, with noise of `noise` levels, laid out
    /// at `side`.
    fn seen(truth: impl Fn(f64) -> f64, noise: f64, side: u32) -> Vec<Sample> {
        let layout = Layout {
            side,
            scale: [1.0, 1.0],
        };
        let levels = Levels::new(None);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut out = Vec::new();
        for photo in 0..6u16 {
            let lit = 0.15 + 0.03 * photo as f64;
            let shift = photo as f64 / 240.0;
            for y in 0..40 {
                for x in 0..40 {
                    let uv = [(x as f64 + 0.5) / 40.0 + shift, (y as f64 + 0.5) / 40.0];
                    let (texels, weights) = layout.bilinear(uv);
                    let dark = 0.01;
                    let mut level = |v: f64| {
                        let l = levels.level(v) as f64;
                        (l + noise * rng.gen_range(-1.0..1.0))
                            .round()
                            .clamp(0.0, 254.0) as u8
                    };
                    let t = level(dark + truth(uv[0].rem_euclid(1.0)) * (lit - dark));
                    let (l, d) = (levels.level(lit), levels.level(dark));
                    out.push(Sample {
                        photo,
                        texels,
                        weights,
                        nearest: layout.texel(uv) as u32,
                        levels: [[t, l, d]; 3],
                    });
                }
            }
        }
        out
    }

    fn score(truth: impl Fn(f64) -> f64 + Copy, noise: f64, side: u32) -> f64 {
        let layouts = [Some(Layout {
            side,
            scale: [1.0, 1.0],
        })];
        let all = vec![seen(truth, noise, side)];
        let n = (all[0].len() * 3) as f64;
        let sad = n * (noise / 2.0).max(0.5);
        let levels = Levels::new(None);
        held_out(&all, 6, &layouts, (n, sad), &levels, MapKind::Color)
    }

    /// Eight stripes across the object: a side of 8 or 16 draws them and
    /// predicts the photographs left out better than a side of 2, which
    /// blurs them.
    #[test]
    fn a_pattern_is_predicted_best_at_a_side_that_draws_it() {
        let stripes = |u: f64| {
            if ((u * 8.0) as usize).is_multiple_of(2) {
                0.5
            } else {
                1.5
            }
        };
        let s: Vec<f64> = [2, 8, 16].map(|side| score(stripes, 2.0, side)).to_vec();
        assert!(s[1] < 0.8 * s[0] && s[2] < 0.8 * s[0], "{s:?}");
    }

    /// A uniform material under noise: a finer map only fits the noise,
    /// and predicts the photographs left out worse than a coarse one.
    #[test]
    fn a_uniform_material_is_predicted_best_by_a_coarse_map() {
        let uniform = |_: f64| 1.0;
        let s: Vec<f64> = [1, 4, 16, 32]
            .map(|side| score(uniform, 3.0, side))
            .to_vec();
        assert!(s[0] <= s[2] && s[1] <= s[3], "{s:?}");
    }
}
