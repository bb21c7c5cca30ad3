//! One channel of one object's colour texture (`texels.rs`), or the one
//! value per texel of a scalar map (a specular strength: each sample's
//! three channels are three equations in it), fitted to its samples: the
//! multipliers m whose bilinear lookup best explains each sample, target = dark + (Σ w m)(lit - dark) in linear values, by least
//! squares in the file's levels (each sample weighed by the levels a unit
//! of the map moves it). Solving per texel alone (each pixel given to the
//! texel whose cell holds it) left the bilinear lookup to blur every edge
//! of the texture by a texel, a residual along every edge that the
//! criterion's overdispersion read as a smooth misfit (a 3-photograph
//! checker ball: SAD only halved, the map refused).
//!
//! The unknowns are the texels with evidence in at least `min_photos`
//! photographs (that an object is seen by two photographs at least is
//! `texels.rs`'s rule; a specular map asks it of each texel too); the
//! others stay 1 (the scalar value).
//! Each starts at the weighted median of its own samples' ratios and the
//! normal equations are relaxed by Gauss-Seidel sweeps (`SWEEPS`, texels
//! in order: deterministic). A value is then kept only when the SAD of
//! the samples in its cell falls by more than `cost`.

use crate::render::camera_effects;
use crate::scene::Response;
use std::ops::Range;

/// The camera between the linear values the renderer shades and the
/// 8-bit levels of the file, as the image-space pass writes them
/// (`render/camera_effects.rs`): the curve `black + gain v^gamma`, then
/// the sRGB encoding or, for a response whose `encoding` is `linear`, the
/// level as it is. Without a declared response, the sRGB encoding alone.
pub struct Levels {
    response: Response,
    /// Each level's linear value, the curve undone.
    pub linear: Vec<f64>,
}

impl Levels {
    pub fn new(response: Option<Response>) -> Levels {
        let response = response.unwrap_or_default();
        let linear = (0..=255u8)
            .map(|v| camera_effects::linear(&response, v))
            .collect();
        Levels { response, linear }
    }

    /// The level written for the linear value `x`.
    pub fn level(&self, x: f64) -> u8 {
        camera_effects::level(&self.response, x)
    }
}

/// One counted pixel seeing a laid-out object: the photograph, the four
/// texels its lookup blends and their weights, the texel whose cell holds
/// it, and per channel the target, lit and dark levels.
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    pub photo: u16,
    pub texels: [u32; 4],
    pub weights: [f32; 4],
    pub nearest: u32,
    pub levels: [[u8; 3]; 3],
}

/// Multipliers are clamped to this (a pixel lit far less than the model
/// says, e.g. a shadow the model misses, is not a map).
pub const MAX_MULTIPLIER: f64 = 8.0;

/// Gauss-Seidel sweeps over the texels: from the per-texel medians the
/// change after 20 sweeps is below a level on the generated sets.
const SWEEPS: usize = 30;

/// A channel's multipliers, per texel, and which were kept.
pub struct Fitted {
    pub m: Vec<f64>,
    pub kept: Vec<bool>,
    /// Each texel's cell's SAD in levels over the channels fitted, as
    /// `m` predicts it (1 where not kept): what another solve of the same
    /// samples is compared with, texel by texel (`diagnose/gloss.rs`).
    pub cell_sad: Vec<f64>,
}

/// One sample's equation in channel `c`: the map's reach `a` (lit - dark),
/// the target's `b` (target - dark), both linear, and the weight (0: no
/// evidence).
fn equation(s: &Sample, c: usize, levels: &Levels) -> (f64, f64, f64) {
    let [t, l, d] = s.levels[c];
    let lin = &levels.linear;
    let (tl, ll, dl) = (lin[t as usize], lin[l as usize], lin[d as usize]);
    if t == 255 || l == 255 || l <= d || ll <= dl {
        return (0.0, 0.0, 0.0);
    }
    let a = ll - dl;
    let per_level = (l - d) as f64 / a;
    (a, tl - dl, per_level * per_level)
}

/// Per texel, the items `(entry, texel)` name it with, in order
/// (compressed rows: texel k's entries are `list[start[k]..start[k + 1]]`).
fn lists(n: usize, items: impl Iterator<Item = (usize, u32)> + Clone) -> (Vec<usize>, Vec<u32>) {
    let mut start = vec![0usize; n + 1];
    for (_, k) in items.clone() {
        start[k as usize + 1] += 1;
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    let mut fill = start.clone();
    let mut out = vec![0u32; start[n]];
    for (s, k) in items {
        out[fill[k as usize]] = s as u32;
        fill[k as usize] += 1;
    }
    (start, out)
}

/// Each sample's equations, one per channel of `channels` (the rest of
/// the three weigh 0, no evidence).
type Equations = Vec<[(f64, f64, f64); 3]>;

/// Fits one value per texel of a map of `texels` texels to the
/// `channels` of `samples` together (a colour map's channel alone, a
/// scalar map's all three: each pixel taken once, its channels summed in
/// the fit and in the SAD that decides what is kept), a texel solved when
/// its cell holds evidence from `min_photos` photographs.
pub fn fit_channels(
    samples: &[Sample],
    channels: Range<usize>,
    texels: usize,
    levels: &Levels,
    (cost, min_photos): (f64, usize),
) -> Fitted {
    let eq: Equations = samples
        .iter()
        .map(|s| {
            let mut e = [(0.0, 0.0, 0.0); 3];
            for (i, c) in channels.clone().enumerate() {
                e[i] = equation(s, c, levels);
            }
            e
        })
        .collect();
    let cells = lists(
        texels,
        samples.iter().enumerate().map(|(i, s)| (i, s.nearest)),
    );
    let touch = lists(
        texels,
        samples
            .iter()
            .enumerate()
            .flat_map(|(i, s)| (0..4).map(move |j| (4 * i + j, s.texels[j]))),
    );
    let mut m = vec![1.0; texels];
    let active = start(samples, &eq, &cells, &mut m, min_photos);
    let mut p: Vec<f64> = samples
        .iter()
        .map(|s| {
            (0..4)
                .map(|j| s.weights[j] as f64 * m[s.texels[j] as usize])
                .sum()
        })
        .collect();
    for _ in 0..SWEEPS {
        sweep(samples, &eq, &touch, &active, &mut m, &mut p);
    }
    let sads = cell_sads(samples, channels, levels, &cells, &p);
    let kept: Vec<bool> = (0..texels)
        .map(|k| active[k] && sads[k].0 - sads[k].1 > cost)
        .collect();
    let mut cell_sad = Vec::with_capacity(texels);
    for k in 0..texels {
        if !kept[k] {
            m[k] = 1.0;
        }
        cell_sad.push(if kept[k] { sads[k].1 } else { sads[k].0 });
    }
    Fitted { m, kept, cell_sad }
}

/// Marks the texels with evidence from `min_photos` photographs and
/// starts each at the weighted median of its cell's ratios b / a, weighed
/// by the levels between lit and dark.
fn start(
    samples: &[Sample],
    eq: &Equations,
    (start, list): &(Vec<usize>, Vec<u32>),
    m: &mut [f64],
    min_photos: usize,
) -> Vec<bool> {
    let mut active = vec![false; m.len()];
    let mut ratios = Vec::new();
    for k in 0..m.len() {
        ratios.clear();
        // A cell's samples come in photograph order: count the changes.
        let (mut photos, mut last) = (0, None);
        for &s in &list[start[k]..start[k + 1]] {
            for &(a, b, w) in &eq[s as usize] {
                if w > 0.0 {
                    ratios.push((b / a, w.sqrt() * a));
                    let photo = samples[s as usize].photo;
                    photos += usize::from(last != Some(photo));
                    last = Some(photo);
                }
            }
        }
        if !ratios.is_empty() && photos >= min_photos {
            active[k] = true;
            m[k] = weighted_median(&mut ratios).clamp(0.0, MAX_MULTIPLIER);
        }
    }
    active
}

/// One Gauss-Seidel sweep of the weighted normal equations over the
/// active texels; `p` holds each sample's lookup Σ w m and follows.
fn sweep(
    samples: &[Sample],
    eq: &Equations,
    (start, list): &(Vec<usize>, Vec<u32>),
    active: &[bool],
    m: &mut [f64],
    p: &mut [f64],
) {
    for k in (0..m.len()).filter(|&k| active[k]) {
        let entries = &list[start[k]..start[k + 1]];
        let (mut num, mut den) = (0.0, 0.0);
        for &e in entries {
            let (s, j) = (e as usize / 4, e as usize % 4);
            let wk = samples[s].weights[j] as f64;
            for &(a, b, w) in &eq[s] {
                num += w * a * wk * (b - a * p[s]);
                den += w * a * a * wk * wk;
            }
        }
        if den <= 1e-12 {
            continue;
        }
        let new = (m[k] + num / den).clamp(0.0, MAX_MULTIPLIER);
        let delta = new - m[k];
        m[k] = new;
        for &e in entries {
            let (s, j) = (e as usize / 4, e as usize % 4);
            p[s] += samples[s].weights[j] as f64 * delta;
        }
    }
}

/// Each texel's cell's SAD in levels over `channels`: at the scalar
/// value (the lit render) and predicted through the fitted lookups `p`.
/// A texel is kept when the drop from the one to the other is more than
/// the cost of its value.
fn cell_sads(
    samples: &[Sample],
    channels: Range<usize>,
    levels: &Levels,
    (start, list): &(Vec<usize>, Vec<u32>),
    p: &[f64],
) -> Vec<(f64, f64)> {
    let lin = &levels.linear;
    (0..start.len() - 1)
        .map(|k| {
            list[start[k]..start[k + 1]]
                .iter()
                .flat_map(|&s| channels.clone().map(move |c| (s as usize, c)))
                .map(|(s, c)| {
                    let [t, l, d] = samples[s].levels[c];
                    let (ll, dl) = (lin[l as usize], lin[d as usize]);
                    let predicted = levels.level(dl + p[s] * (ll - dl));
                    (t.abs_diff(l) as f64, t.abs_diff(predicted) as f64)
                })
                .fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1))
        })
        .collect()
}

/// The value minimising the weighted sum of absolute deviations.
fn weighted_median(v: &mut [(f64, f64)]) -> f64 {
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let half = v.iter().map(|x| x.1).sum::<f64>() / 2.0;
    let mut acc = 0.0;
    for &(x, w) in v.iter() {
        acc += w;
        if acc >= half {
            return x;
        }
    }
    v.last().map_or(1.0, |x| x.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::texel_layout::Layout;

    #[test]
    fn the_weighted_median_follows_the_weights() {
        let mut v = [(1.0, 1.0), (5.0, 3.0), (2.0, 1.0)];
        assert_eq!(weighted_median(&mut v), 5.0);
        let mut v = [(1.0, 3.0), (5.0, 1.0), (2.0, 1.0)];
        assert_eq!(weighted_median(&mut v), 1.0);
    }

    /// A 4 x 4 map with a sharp pattern (0.4 and 1.6 in alternate
    /// columns), seen through its bilinear lookup by 12 x 12 points a
    /// photograph: two photographs under different light see the left
    /// three columns, none the last. The fit recovers the pattern (the
    /// per-texel medians alone blur it towards the neighbours); the last
    /// column keeps 1, not counted.
    #[test]
    fn a_sharp_pattern_is_recovered_through_the_bilinear_lookup() {
        let layout = Layout {
            side: 4,
            scale: [1.0, 1.0],
        };
        let truth = |k: u32| if k.is_multiple_of(2) { 0.4 } else { 1.6 };
        let levels = Levels::new(None);
        let mut samples = Vec::new();
        for (photo, lit) in [(0u16, 0.2), (1, 0.35)] {
            for y in 0..12 {
                for x in 0..12 {
                    let uv = [(x as f64 + 0.5) / 12.0, (y as f64 + 0.5) / 12.0];
                    let nearest = layout.texel(uv) as u32;
                    if nearest % 4 == 3 {
                        continue;
                    }
                    let (texels, weights) = layout.bilinear(uv);
                    let m: f64 = (0..4).map(|j| weights[j] as f64 * truth(texels[j])).sum();
                    let dark = 0.01;
                    let t = levels.level(dark + m * (lit - dark));
                    let (l, d) = (levels.level(lit), levels.level(dark));
                    samples.push(Sample {
                        photo,
                        texels,
                        weights,
                        nearest,
                        levels: [[t, l, d]; 3],
                    });
                }
            }
        }
        let f = fit_channels(&samples, 0..1, 16, &levels, (0.0, 1));
        for k in 0..16u32 {
            if k % 4 == 3 {
                assert!(!f.kept[k as usize] && f.m[k as usize] == 1.0, "texel {k}");
            } else if k % 4 == 1 {
                // between two solved columns: the pattern itself
                let e = (f.m[k as usize] - truth(k)).abs();
                assert!(
                    f.kept[k as usize] && e < 0.05,
                    "texel {k}: {}",
                    f.m[k as usize]
                );
            }
        }
    }

    /// A 2 x 1 map, each texel's cell seen at its centre (the lookup
    /// there is that texel alone): texel 0 by two photographs, texel 1 by
    /// one. Asked for two photographs a texel, the fit solves texel 0 (to
    /// the true 0.5) and leaves texel 1 at 1, uncounted; asked for one,
    /// it solves both.
    #[test]
    fn a_texel_is_solved_only_with_evidence_from_enough_photographs() {
        let layout = Layout {
            side: 2,
            scale: [1.0, 1.0],
        };
        let levels = Levels::new(None);
        let mut samples = Vec::new();
        for (photo, uv) in [(0u16, [0.25, 0.75]), (1, [0.25, 0.75]), (0, [0.75, 0.75])] {
            let (texels, weights) = layout.bilinear(uv);
            let (lit, dark) = (0.4, 0.05);
            let t = levels.level(dark + 0.5 * (lit - dark));
            samples.push(Sample {
                photo,
                texels,
                weights,
                nearest: layout.texel(uv) as u32,
                levels: [[t, levels.level(lit), levels.level(dark)]; 3],
            });
        }
        samples.sort_by_key(|s| s.photo);
        let two = fit_channels(&samples, 0..1, 4, &levels, (0.0, 2));
        let (t0, t1) = (layout.texel([0.25, 0.75]), layout.texel([0.75, 0.75]));
        assert!(
            two.kept[t0] && (two.m[t0] - 0.5).abs() < 0.02,
            "{:?}",
            two.m
        );
        assert!(!two.kept[t1] && two.m[t1] == 1.0, "{:?}", two.m);
        let one = fit_channels(&samples, 0..1, 4, &levels, (0.0, 1));
        assert!(one.kept[t0] && one.kept[t1], "{:?}", one.kept);
    }

    /// One texel (side 1) seen by two photographs whose three channels
    /// each show half the map's reach: fitted to the three together it is
    /// 0.5, kept at a cost that no channel's drop alone pays (the SAD
    /// counted over the three channels of each pixel, one value).
    #[test]
    fn a_scalar_value_is_fitted_and_kept_on_the_three_channels_together() {
        let layout = Layout {
            side: 1,
            scale: [1.0, 1.0],
        };
        let levels = Levels::new(None);
        let mut samples = Vec::new();
        for photo in [0u16, 1] {
            let (texels, weights) = layout.bilinear([0.5, 0.5]);
            let dark = 0.02;
            let channel = |lit: f64| {
                let t = levels.level(dark + 0.5 * (lit - dark));
                [t, levels.level(lit), levels.level(dark)]
            };
            samples.push(Sample {
                photo,
                texels,
                weights,
                nearest: 0,
                levels: [channel(0.3), channel(0.5), channel(0.7)],
            });
        }
        let drop = |c: usize| -> f64 {
            let m = samples.iter().map(|s| {
                let [t, l, _] = s.levels[c];
                t.abs_diff(l) as f64
            });
            m.sum::<f64>()
        };
        let (single, all) = (
            (0..3).map(drop).fold(0.0, f64::max),
            (0..3).map(drop).sum::<f64>(),
        );
        let cost = (single + all) / 2.0;
        let f = fit_channels(&samples, 0..3, 1, &levels, (cost, 2));
        assert!(f.kept[0] && (f.m[0] - 0.5).abs() < 0.02, "{:?}", f.m);
        for c in 0..3 {
            let one = fit_channels(&samples, c..c + 1, 1, &levels, (cost, 2));
            assert!(!one.kept[0], "channel {c} alone kept");
        }
    }

    /// Random samples of a map seen by four photographs, each channel
    /// lit to its own level: the scalar fit on each pixel once gives the
    /// values and kept texels of the fit on each pixel taken three times,
    /// one channel each (the specular map's samples before), up to the
    /// order of the sums.
    #[test]
    fn a_scalar_fit_equals_the_fit_of_its_pixels_tripled() {
        use rand::{Rng, SeedableRng};
        let levels = Levels::new(None);
        for side in [1u32, 2, 8] {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(side as u64);
            let layout = Layout {
                side,
                scale: [1.0, 1.0],
            };
            let n = (side * side) as usize;
            let truth: Vec<f64> = (0..n).map(|_| rng.gen_range(0.2..2.0)).collect();
            let mut single = Vec::new();
            for photo in 0..4u16 {
                for _ in 0..20 * n {
                    let uv = [rng.gen::<f64>(), rng.gen::<f64>()];
                    let (texels, weights) = layout.bilinear(uv);
                    let m: f64 = (0..4)
                        .map(|j| weights[j] as f64 * truth[texels[j] as usize])
                        .sum();
                    let dark = rng.gen_range(0.0..0.05);
                    let mut channel = || {
                        let lit = rng.gen_range(0.05..0.5);
                        let noise = rng.gen_range(-0.01..0.01);
                        let t = levels.level(dark + m * (lit - dark) + noise);
                        [t, levels.level(lit), levels.level(dark)]
                    };
                    let levels = [channel(), channel(), channel()];
                    let nearest = layout.texel(uv) as u32;
                    single.push(Sample {
                        photo,
                        texels,
                        weights,
                        nearest,
                        levels,
                    });
                }
            }
            let tripled: Vec<Sample> = single
                .iter()
                .flat_map(|s| {
                    (0..3).map(move |c| Sample {
                        levels: [s.levels[c]; 3],
                        ..*s
                    })
                })
                .collect();
            for cost in [0.0, 20.0] {
                let one = fit_channels(&single, 0..3, n, &levels, (cost, 2));
                let three = fit_channels(&tripled, 0..1, n, &levels, (cost, 2));
                assert_eq!(one.kept, three.kept, "side {side}, cost {cost}");
                // A comparison of fits that solved something.
                assert!(one.kept.contains(&true), "side {side}: nothing kept");
                for (a, b) in one.m.iter().zip(&three.m) {
                    assert!((a - b).abs() < 1e-9, "side {side}: {a} against {b}");
                }
            }
        }
    }
}
