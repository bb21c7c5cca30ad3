//! Where an effect's search starts, for one photograph and a set alike:
//! the extended scene or one of the effect's other starts, each also with
//! its level matched to the photographs', whichever renders closest.

use super::effects::edit::match_level_where;
use super::effects::Extension;
use super::inputs::{Params, SetInputs};
use super::model::{shots_of, weighted_mean};
use super::refits::Refits;
use crate::error::Result;
use crate::fit::set::shots::Shot;
use crate::metric::Mask;
use crate::raster::Image;
use crate::scene::{ParamSpace, ResponseEncoding, Scene};

impl Refits<'_> {
    /// The best of an extension's starts over the photographs (the
    /// extended scene included): each start's shared values with every
    /// photograph's own values, and again with its level matched to the
    /// photographs': the shared free intensities scaled by the pooled
    /// ratio, and each photograph's own free intensities by its own ratio
    /// (a new gamma changes each photograph's level by its own amount).
    /// The start's scene and own values; the renders spent are counted.
    pub(super) fn best_start(
        &mut self,
        ext: &Extension,
        own: &[Params],
    ) -> Result<(Scene, Vec<Params>)> {
        if ext.starts.is_empty() {
            return Ok((ext.scene.clone(), own.to_vec()));
        }
        let inputs = self.inputs;
        let targets: Vec<&Image> = inputs.shots.iter().map(|s| &s.target.image).collect();
        let mut best = (f64::INFINITY, ext.scene.clone(), own.to_vec());
        for start in std::iter::once(&ext.scene).chain(&ext.starts) {
            let scale = Scale::of(start);
            let want = levels(inputs, &targets, scale);
            // A start the renderer refuses is no start; the others remain.
            let Ok(shots) = shots_of(start, inputs, own) else {
                continue;
            };
            let Ok(Some((images, d))) = self.render(&shots) else {
                continue;
            };
            if d < best.0 {
                best = (d, start.clone(), own.to_vec());
            }
            let have = levels(inputs, &images.iter().collect::<Vec<_>>(), scale);
            if weighted_mean(&have) <= 0.0 {
                continue;
            }
            let k_shared = weighted_mean(&want) / weighted_mean(&have);
            let matched = matched(&shots, &want, &have, k_shared);
            if let Ok(Some((_, d))) = self.render(&matched) {
                if d < best.0 {
                    let space = ParamSpace::from_scene(start);
                    let own_now = matched
                        .iter()
                        .map(|s| s.own_space(&space).json_values(&s.scene))
                        .collect();
                    let shared = match_level_where(start, k_shared, |f| !f.per_shot);
                    best = (d, shared, own_now);
                }
            }
        }
        Ok((best.1, best.2))
    }
}

/// Each shot with its level matched: the shared free intensities scaled
/// by `k_shared`, its own by its own ratio of `want` to `have`. Each
/// shot's scene already holds the start with its own values: the two
/// scalings applied there, no rebuild needed.
fn matched(shots: &[Shot], want: &[(f64, f64)], have: &[(f64, f64)], k_shared: f64) -> Vec<Shot> {
    shots
        .iter()
        .zip(want.iter().zip(have))
        .map(|(s, (w, h))| {
            let k = if h.1 > 0.0 { w.1 / h.1 } else { 1.0 };
            let scene = match_level_where(&s.scene, k_shared, |f| !f.per_shot);
            let scene = match_level_where(&scene, k, |f| {
                f.per_shot && !s.entry.set.contains_key(&f.param)
            });
            Shot { scene, ..s.clone() }
        })
        .collect()
}

/// Each photograph's weight (its pixels) and the level of its image in
/// `images`, on `scale`.
fn levels(inputs: &SetInputs, images: &[&Image], scale: Scale) -> Vec<(f64, f64)> {
    images
        .iter()
        .zip(&inputs.shots)
        .map(|(img, s)| {
            let w = crate::fit::set::counted(&s.target) as f64;
            (w, level(img, s.target.mask.as_ref(), scale))
        })
        .collect()
}

/// How a level is measured: on the linear values of sRGB levels, or on
/// the levels themselves, for a scene whose response writes linear values
/// (there the level scales with the response's output, which the level
/// matching scales through the gamma; decoding such levels as sRGB would
/// bend the dark ones by the curve's linear toe).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Scale {
    Srgb,
    Linear,
}

impl Scale {
    pub(super) fn of(scene: &Scene) -> Scale {
        match scene.camera.response.map(|r| r.encoding) {
            Some(ResponseEncoding::Linear) => Scale::Linear,
            _ => Scale::Srgb,
        }
    }
}

/// The mean value over the mask's channel values, on `scale`.
pub(super) fn level(img: &Image, mask: Option<&Mask>, scale: Scale) -> f64 {
    let lut: Vec<f64> = match scale {
        Scale::Srgb => (0..=255u8).map(crate::render::srgb::decode).collect(),
        Scale::Linear => (0..=255u8).map(|v| v as f64 / 255.0).collect(),
    };
    let raw = img.as_raw();
    let (sum, n) = match mask {
        Some(m) => m.pixels().iter().fold((0.0, 0usize), |(s, n), &p| {
            let i = 3 * p as usize;
            (
                s + lut[raw[i] as usize] + lut[raw[i + 1] as usize] + lut[raw[i + 2] as usize],
                n + 3,
            )
        }),
        None => (raw.iter().map(|&v| lut[v as usize]).sum(), raw.len()),
    };
    sum / n.max(1) as f64
}
