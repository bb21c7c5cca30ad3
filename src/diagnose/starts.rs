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
use crate::scene::Scene;

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
    let target_level = level(&inputs.target, mask);
    let mut best = (f64::INFINITY, ext.scene.clone());
    let mut renders = 0;
    for s in std::iter::once(&ext.scene).chain(&ext.starts) {
        // A start the renderer refuses is no start; the others remain.
        renders += 1;
        let Ok(img) = render_one(renderer, s, 0) else {
            continue;
        };
        let mut candidates = vec![(s.clone(), img.clone())];
        let own = level(&img, mask);
        if own > 0.0 {
            let matched = match_level(s, target_level / own);
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

/// The mean linear value over the mask's channel values.
pub(super) fn level(img: &Image, mask: Option<&Mask>) -> f64 {
    let lut: Vec<f64> = (0..=255u8).map(crate::render::srgb::decode).collect();
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
