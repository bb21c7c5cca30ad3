//! Where an effect's search starts: the extended scene or one of the
//! effect's other starts, each also with its level matched to the
//! target's, whichever renders closest.

use super::effects::{match_level, Extension};
use super::selection::sad;
use super::Inputs;
use crate::error::Result;
use crate::metric::Mask;
use crate::raster::Image;
use crate::render::{render_one, Renderer};
use crate::scene::{ResponseEncoding, Scene};

/// The best start of `ext`, and the renders spent choosing it.
pub fn best_start(
    renderer: &dyn Renderer,
    ext: &Extension,
    inputs: &Inputs,
) -> Result<(Scene, usize)> {
    if ext.starts.is_empty() {
        return Ok((ext.scene.clone(), 0));
    }
    let mask = inputs.mask.as_ref();
    let mut best = (f64::INFINITY, ext.scene.clone());
    let mut renders = 0;
    for s in std::iter::once(&ext.scene).chain(&ext.starts) {
        // A start the renderer refuses is no start; the others remain.
        renders += 1;
        let Ok(img) = render_one(renderer, s, 0) else {
            continue;
        };
        let mut candidates = vec![(s.clone(), img.clone())];
        let scale = Scale::of(s);
        let own = level(&img, mask, scale);
        if own > 0.0 {
            let matched = match_level(s, level(&inputs.target, mask, scale) / own);
            renders += 1;
            if let Ok(img) = render_one(renderer, &matched, 0) {
                candidates.push((matched, img));
            }
        }
        for (scene, img) in candidates {
            let d = sad(&inputs.target, &img, mask);
            if d < best.0 {
                best = (d, scene);
            }
        }
    }
    Ok((best.1, renders))
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
