//! The closed-form effect `albedo_map`: a map of the diffuse colour's
//! multipliers shared by every photograph, one value per pixel and
//! channel, which no search could fit. A render is linear in the map
//! (`lit` with the map at 1, `dark` with it at 0: target = dark + m (lit -
//! dark) in linear values), so each pixel's channel is solved on its own
//! over the photographs: the weighted median of (target - dark) / (lit -
//! dark), weighted by the 8-bit levels between lit and dark, which
//! minimises the sum of absolute differences of the levels (the fit's
//! metric). Values with evidence in fewer than two photographs stay 1 and
//! are not counted, so on a single photograph nothing is solved and the
//! effect is no candidate; nor are values whose drop of the SAD does not
//! pay for them in the criterion (`solve`).
//!
//! The map is solved, the model's other free parameters refitted with it
//! in the scene, and the map solved once more against the refitted model
//! (the better of the two kept). Its parameters for the criterion are the
//! values solved, ln N each.

use super::inputs::Params;
use super::model::{shots_of, Model};
use super::refits::Refits;
use crate::error::{Error, Result};
use crate::fit::set::shots::Shot;
use crate::metric::Mask;
use crate::raster::Image;
use crate::render::camera_effects;
use crate::scene::albedo_map::{self, AlbedoMap};
use crate::scene::{Response, Scene};
use std::path::{Path, PathBuf};

/// Photographs with evidence a value needs.
const MIN_PHOTOGRAPHS: usize = 2;

/// Multipliers are clamped to this (a pixel lit far less than the model
/// says, e.g. a shadow the model misses, is not a map).
const MAX_MULTIPLIER: f64 = 8.0;

/// One photograph's evidence: its target and mask, and its model rendered
/// with the map at 1 and at 0.
pub struct Evidence<'a> {
    pub target: &'a Image,
    pub mask: Option<&'a Mask>,
    pub lit: Image,
    pub dark: Image,
}

/// A solved map and the values it solved (the rest stayed 1).
pub struct Solved {
    pub map: AlbedoMap,
    pub count: usize,
}

/// `scene` with every object's map at `path`.
pub fn with_map(scene: &Scene, path: Option<&Path>) -> Scene {
    let mut s = scene.clone();
    for o in &mut s.objects {
        o.material.albedo_map = path.map(|p| p.display().to_string());
    }
    s
}

/// The file of the zero map (the `dark` probe), written into `out`.
fn zero_map(scene: &Scene, out: &Path) -> Result<PathBuf> {
    let path = out.join("albedo_map_zero.exr");
    let (w, h) = (scene.image.width, scene.image.height);
    albedo_map::write(&path, AlbedoMap::uniform(w, h, 0.0))?;
    Ok(std::path::absolute(&path).unwrap_or(path))
}

/// The camera between the linear values the renderer shades and the
/// 8-bit levels of the file, as the image-space pass writes them
/// (`render/camera_effects.rs`): the curve `black + gain v^gamma`, then
/// the sRGB encoding or, for a response whose `encoding` is `linear`, the
/// level as it is. Without a declared response, the sRGB encoding alone.
struct Levels {
    response: Response,
    /// Each level's linear value, the curve undone.
    linear: Vec<f64>,
}

impl Levels {
    fn new(response: Option<Response>) -> Levels {
        let response = response.unwrap_or_default();
        let linear = (0..=255u8)
            .map(|v| camera_effects::linear(&response, v))
            .collect();
        Levels { response, linear }
    }

    /// The level written for the linear value `x`.
    fn level(&self, x: f64) -> u8 {
        camera_effects::level(&self.response, x)
    }
}

/// Solves the map from every photograph's evidence; a value needs
/// evidence in at least two photographs: from one, a value would match
/// its pixel exactly whatever caused the difference (a stain or a shadow
/// the model lacks), which no criterion over those pixels can tell from a
/// texture (on noise-free photographs the BIC accepted such a map on one
/// photograph).
///
/// Everything is measured in the file's levels, where the criterion
/// measures the fit: a photograph is evidence at a pixel's channel when
/// the map moves it (the lit render at least one level above the dark
/// one) and neither the target nor the lit render is saturated (255).
/// The ratios (target - dark) / (lit - dark) are taken in linear values
/// (the file's encoding and a declared `camera.response` undone: a
/// `linear` response's levels were once sRGB-decoded, which bent the
/// ratios and made a solved map raise the SAD by 15 %), and
/// their median weighted by the levels between lit and dark: the levels
/// a unit of the map moves the pixel, so that the weighted sum of
/// absolute differences is the levels' (an absolute threshold in linear
/// values instead, 0.01, left photographs that store linear values in an
/// sRGB-declared file, darker than 0.01 almost everywhere, without a
/// value; and linear weights favour the bright photographs, which the
/// sRGB levels compress).
///
/// A value is then kept only when it earns its place in the criterion:
/// `BIC = 2N ln(SAD/N) + k ln N` falls by adding it when the SAD of its
/// pixel's channel over the photographs, the level its value predicts
/// against the lit render's, falls by more than `ln N SAD / 2N` (SAD and
/// N those of the model without the map over every photograph). The rest
/// stay 1 and are not counted: without this every pixel with evidence
/// was counted, ln N each, and a texture that lowered the SAD by a fifth
/// still raised the BIC (a textured ball photographed by Mitsuba: 11,538
/// values, SAD -22 %, BIC about +26,000; kept by the criterion, 2,029 values,
/// SAD -17 %, BIC -58,000).
pub fn solve(evidence: &[Evidence], response: Option<Response>) -> Solved {
    let (w, h) = evidence[0].target.dimensions();
    let levels = Levels::new(response);
    let lin = &levels.linear;
    let mut map = AlbedoMap::uniform(w, h, 1.0);
    let mut count = 0;
    // Which pixels each photograph counts.
    let inside: Vec<Vec<bool>> = evidence
        .iter()
        .map(|e| Mask::counted(e.mask, (w * h) as usize))
        .collect();
    // The criterion's N and SAD for the model without the map.
    let (mut n, mut sad) = (0.0_f64, 0.0);
    for (e, inside) in evidence.iter().zip(&inside) {
        let (t, l) = (e.target.as_raw(), e.lit.as_raw());
        for p in (0..(w * h) as usize).filter(|&p| inside[p]) {
            for i in 3 * p..3 * p + 3 {
                n += 1.0;
                sad += t[i].abs_diff(l[i]) as f64;
            }
        }
    }
    let cost = if n > 1.0 {
        sad * n.ln() / (2.0 * n)
    } else {
        f64::INFINITY
    };
    let mut ratios: Vec<(f64, f64)> = Vec::with_capacity(evidence.len());
    let mut seen: Vec<(u8, u8, u8)> = Vec::with_capacity(evidence.len());
    for p in 0..(w * h) as usize {
        for c in 0..3 {
            ratios.clear();
            seen.clear();
            let i = 3 * p + c;
            for (e, inside) in evidence.iter().zip(&inside) {
                if !inside[p] {
                    continue;
                }
                let (t, l, d) = (e.target.as_raw()[i], e.lit.as_raw()[i], e.dark.as_raw()[i]);
                seen.push((t, l, d));
                if t == 255 || l == 255 || l <= d {
                    continue;
                }
                let (tl, ll, dl) = (lin[t as usize], lin[l as usize], lin[d as usize]);
                if ll <= dl {
                    continue;
                }
                ratios.push(((tl - dl) / (ll - dl), (l - d) as f64));
            }
            if ratios.len() < MIN_PHOTOGRAPHS {
                continue;
            }
            let m = weighted_median(&mut ratios).clamp(0.0, MAX_MULTIPLIER);
            let drop: f64 = seen
                .iter()
                .map(|&(t, l, d)| {
                    let (ll, dl) = (lin[l as usize], lin[d as usize]);
                    let predicted = levels.level(dl + m * (ll - dl));
                    t.abs_diff(l) as f64 - t.abs_diff(predicted) as f64
                })
                .sum();
            if drop > cost {
                map.values[i] = m as f32;
                count += 1;
            }
        }
    }
    Solved { map, count }
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

/// The probes of `scene`: its maps removed (at 1), and every map at 0.
fn probes(scene: &Scene, zero: &Path) -> (Scene, Scene) {
    (with_map(scene, None), with_map(scene, Some(zero)))
}

/// The map file of round `round` (`first`: before the refit).
fn map_path(out: &Path, round: usize, first: bool) -> PathBuf {
    let name = if first {
        format!("albedo_map_round{round}_first.exr")
    } else {
        format!("albedo_map_round{round}.exr")
    };
    let p = out.join(name);
    std::path::absolute(&p).unwrap_or(p)
}

/// Removes the map file a model no longer names.
fn discard(path: &Path) {
    let _ = std::fs::remove_file(path);
}

/// Removes from `out` every map file the diagnosis wrote that `kept` (its
/// final model) does not name: the maps of rejected candidates and the
/// probe, which would otherwise read as results.
pub fn prune(out: &Path, kept: &Scene) {
    let named: Vec<PathBuf> = kept
        .objects
        .iter()
        .filter_map(|o| o.material.albedo_map.as_deref().map(PathBuf::from))
        .collect();
    let Ok(entries) = std::fs::read_dir(out) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if !(name.starts_with("albedo_map_") && name.ends_with(".exr")) {
            continue;
        }
        let path = e.path();
        let absolute = std::path::absolute(&path).unwrap_or(path.clone());
        if !named.iter().any(|n| n == &absolute || n == &path) {
            discard(&path);
        }
    }
}

/// The map solved for `scene` with each photograph's `own` values,
/// written to `path`; None when no value could be solved.
fn solve_for(
    fits: &mut Refits,
    scene: &Scene,
    own: &[Params],
    path: &Path,
) -> Result<Option<(Scene, usize)>> {
    let zero = zero_map(scene, fits.out)?;
    let (lit, dark) = probes(scene, &zero);
    let inputs = fits.inputs;
    let rendered = |fits: &mut Refits, s: &Scene| -> Result<Vec<Image>> {
        let shots: Vec<Shot> = shots_of(s, inputs, own)?;
        fits.render(&shots)?
            .map(|(images, _)| images)
            .ok_or_else(|| Error::Run("albedo_map: a render of the photographs failed".into()))
    };
    let lit = rendered(fits, &lit)?;
    let dark = rendered(fits, &dark)?;
    discard(&zero);
    let evidence: Vec<Evidence> = inputs
        .shots
        .iter()
        .zip(lit.into_iter().zip(dark))
        .map(|(s, (lit, dark))| Evidence {
            target: &s.target.image,
            mask: s.target.mask.as_ref(),
            lit,
            dark,
        })
        .collect();
    let solved = solve(&evidence, scene.camera.response);
    if solved.count == 0 {
        return Ok(None);
    }
    albedo_map::write(path, solved.map)?;
    Ok(Some((with_map(scene, Some(path)), solved.count)))
}

/// The model with `albedo_map`: solved, the others refitted
/// (`Refits::after_solve`), solved again, the better of the two kept; the
/// model and the values solved (None: nothing could be solved).
pub(super) fn solved(
    fits: &mut Refits,
    model: &Model,
    round: usize,
) -> Result<Option<(Model, usize)>> {
    let out = fits.out;
    let (first, second) = (map_path(out, round, true), map_path(out, round, false));
    let Some((scene, count1)) = solve_for(fits, &model.scene, &model.own, &first)? else {
        return Ok(None);
    };
    // The losing map stays on disk until the diagnosis prunes every map
    // its final model does not name (`prune`).
    let (mut fitted, mut count) = (fits.after_solve(&scene, &model.own)?, count1);
    if let Some((again, count2)) = solve_for(fits, &fitted.scene, &fitted.own, &second)? {
        let own = fitted.own.clone();
        if let Some(m) = fits.model_of(again, &own)? {
            if m.sad < fitted.sad {
                (fitted, count) = (m, count2);
            }
        }
    }
    Ok(Some((fitted, count)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::ResponseEncoding;

    #[test]
    fn the_weighted_median_follows_the_weights() {
        let mut v = [(1.0, 1.0), (5.0, 3.0), (2.0, 1.0)];
        assert_eq!(weighted_median(&mut v), 5.0);
        let mut v = [(1.0, 3.0), (5.0, 1.0), (2.0, 1.0)];
        assert_eq!(weighted_median(&mut v), 1.0);
    }

    #[test]
    fn a_map_planted_in_linear_values_is_solved_where_there_is_evidence() {
        // Two photographs: lit and dark renders, a target = dark + m (lit -
        // dark) with m = 0.5 at pixel 0, 1 elsewhere; pixel 3 unlit.
        let (w, h) = (2, 2);
        let code = |x: f64| crate::render::srgb::encode(x);
        let make = |f: &dyn Fn(usize) -> f64| {
            Image::from_fn(w, h, |x, y| {
                let v = code(f((y * w + x) as usize));
                image::Rgb([v, v, v])
            })
        };
        let lit_v = |p: usize| if p == 3 { 0.0_f64 } else { 0.6 };
        let dark_v = |_: usize| 0.05_f64;
        let m = |p: usize| if p == 0 { 0.5_f64 } else { 1.0 };
        let mut evidence = Vec::new();
        let target = make(&|p| dark_v(p) + m(p) * (lit_v(p) - dark_v(p)).max(0.0));
        for _ in 0..2 {
            evidence.push((make(&lit_v), make(&dark_v)));
        }
        let ev: Vec<Evidence> = evidence
            .into_iter()
            .map(|(lit, dark)| Evidence {
                target: &target,
                mask: None,
                lit,
                dark,
            })
            .collect();
        let s = solve(&ev, None);
        assert_eq!(s.count, 3, "pixel 0's three channels");
        assert!((s.map.at(0)[0] - 0.5).abs() < 0.02, "{:?}", s.map.at(0));
        assert_eq!(s.map.at(1), [1.0; 3], "nothing to explain: left at 1");
        assert_eq!(s.map.at(3), [1.0; 3], "no evidence: left at 1");
    }

    #[test]
    fn a_map_is_solved_in_dark_photographs_that_store_linear_levels() {
        // Eight photographs of a camera writing linear levels (a declared
        // linear response), all below level 40 (linear 0.16): the map
        // moves a pixel by a few levels only. A stain (m = 0.5) at pixels
        // 0 and 1 is solved; pixel 2 (m = 1, one level of noise) and pixel 3
        // (no light: lit = dark) are left at 1 and not counted. With the
        // sRGB decoding and an absolute threshold of 0.01 in linear
        // values, nothing was solved.
        let (w, h) = (2, 2);
        let linear = Response {
            encoding: ResponseEncoding::Linear,
            ..Response::default()
        };
        let level = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
        let make = |f: &dyn Fn(usize) -> f64| {
            Image::from_fn(w, h, |x, y| {
                let v = level(f((y * w + x) as usize));
                image::Rgb([v, v, v])
            })
        };
        let m = |p: usize| if p < 2 { 0.5_f64 } else { 1.0 };
        let shots: Vec<(Image, Image, Image)> = (0..8)
            .map(|k| {
                let lit = |p: usize| {
                    if p == 3 {
                        0.01
                    } else {
                        0.06 + 0.012 * k as f64
                    }
                };
                let dark = |_: usize| 0.01_f64;
                let noise = if k % 2 == 0 { 1.0 } else { -1.0 } / 255.0;
                let target = |p: usize| {
                    dark(p) + m(p) * (lit(p) - dark(p)) + if p == 2 { noise } else { 0.0 }
                };
                (make(&target), make(&lit), make(&dark))
            })
            .collect();
        let ev: Vec<Evidence> = shots
            .iter()
            .map(|(target, lit, dark)| Evidence {
                target,
                mask: None,
                lit: lit.clone(),
                dark: dark.clone(),
            })
            .collect();
        let s = solve(&ev, Some(linear));
        assert_eq!(s.count, 6, "pixels 0 and 1, three channels each");
        for p in 0..2 {
            assert!((s.map.at(p)[1] - 0.5).abs() < 0.05, "{:?}", s.map.at(p));
        }
        assert_eq!(s.map.at(2), [1.0; 3], "noise: left at 1");
        assert_eq!(s.map.at(3), [1.0; 3], "no evidence: left at 1");
    }
}
