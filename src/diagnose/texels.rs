//! The closed-form solve of `albedo_map` and `specular_map`: a texture in
//! each object's frame, a multiplier of its diffuse colour per texel and
//! channel, or of its specular strength per texel (one value for the
//! three channels: a highlight takes the light's colour), from every
//! photograph that sees the texel, whatever its camera and light (a fixed
//! camera is the case where each texel's pixels lie at one place in every
//! photograph). A render is linear in the map
//! (`lit` with it at 1, `dark` at 0: target = dark + m (lit - dark) in
//! linear values, m the map's bilinear lookup where the pixel sees the
//! object: the surface pass, `render::surface_coords`), so the map is a
//! linear least-squares problem (`texel_fit.rs`). A specular map's
//! evidence is the highlights: a texel is solved only where highlights of
//! `MIN_PHOTOGRAPHS` photographs fall on it (one photograph's highlight
//! is as well explained by a misplaced light), else it keeps the scalar
//! strength.
//!
//! Everything is measured in the file's levels, where the criterion
//! measures the fit: a sample is evidence when the map moves it (the lit
//! render at least one level above the dark one) and neither the target
//! nor the lit render is saturated (255); its ratios are taken in linear
//! values (the file's encoding and a declared `camera.response` undone)
//! and weighed by the levels a unit of the map moves it.
//!
//! Memory: one 64-byte sample per counted pixel of every photograph that
//! sees a covered object (a specular map's too: its three channels are
//! fitted together, `texel_fit::fit_channels`), 16 bytes more for the texels' lists, besides the maps
//! (`texel_layout.rs` caps their side).

use super::texel_fit::{fit_channels, Fitted, Levels, Sample};
use super::texel_layout::Layout;
use crate::metric::Mask;
use crate::raster::Image;
use crate::render::SurfaceCoords;
use crate::scene::texture::MapKind;
use crate::scene::Response;
use std::ops::Range;

/// Photographs an object's map needs in view: in one photograph a map
/// matches its pixels whatever made them darker (a stain or a shadow the
/// model lacks, a light misplaced), since the map and the shading are the
/// same unknown there (on noise-free photographs the BIC accepted such a
/// map on one photograph). With two or more, the texels several see pin
/// each photograph's shading, and a texel only one sees is solved
/// against it.
const MIN_PHOTOGRAPHS: usize = 2;

/// The fits of a colour map: each channel its own values.
const PER_CHANNEL: &[Range<usize>] = &[0..1, 1..2, 2..3];
/// The fit of a scalar map: one value per texel for the three channels.
const ALL_CHANNELS: Range<usize> = 0..3;
const SCALAR: &[Range<usize>] = &[ALL_CHANNELS];

/// The photographs among `samples` (in photograph order).
fn photographs(samples: &[Sample]) -> usize {
    samples.chunk_by(|a, b| a.photo == b.photo).count()
}

/// One photograph's evidence: its target and mask, its model rendered
/// with the maps at 1 and at 0, and what each pixel sees.
pub struct Evidence<'a> {
    pub target: &'a Image,
    pub mask: Option<&'a Mask>,
    pub lit: Image,
    pub dark: Image,
    pub coords: SurfaceCoords,
}

/// One object's solved map: multipliers per texel, RGB, rows top to
/// bottom (1 where nothing was solved), and the values solved.
pub struct ObjectMap {
    pub object: usize,
    pub layout: Layout,
    pub values: Vec<f32>,
    pub count: usize,
    /// Each texel's cell's SAD in levels over the three channels, as the
    /// map predicts it (`texel_fit::Fitted::cell_sad`).
    pub cell_sad: Vec<f64>,
}

/// Per laid-out object, its samples in photograph and pixel order, one
/// per pixel; and the criterion's N and SAD of the model without the
/// maps over every counted pixel.
pub(super) fn samples(
    evidence: &[Evidence],
    layouts: &[Option<Layout>],
) -> (Vec<Vec<Sample>>, f64, f64) {
    let mut out = vec![Vec::new(); layouts.len()];
    let (mut n, mut sad) = (0.0_f64, 0.0);
    for (k, e) in evidence.iter().enumerate() {
        let (w, h) = e.target.dimensions();
        let inside = Mask::counted(e.mask, (w * h) as usize);
        let (t, l, d) = (e.target.as_raw(), e.lit.as_raw(), e.dark.as_raw());
        for p in (0..(w * h) as usize).filter(|&p| inside[p]) {
            for i in 3 * p..3 * p + 3 {
                n += 1.0;
                sad += t[i].abs_diff(l[i]) as f64;
            }
            let Some(Some(sp)) = e.coords.points.get(p) else {
                continue;
            };
            let o = sp.object as usize;
            let Some(Some(layout)) = layouts.get(o) else {
                continue;
            };
            let uv = sp.uv.map(f64::from);
            let (texels, weights) = layout.bilinear(uv);
            let c = |c: usize| [t[3 * p + c], l[3 * p + c], d[3 * p + c]];
            out[o].push(Sample {
                photo: k as u16,
                texels,
                weights,
                nearest: layout.texel(uv) as u32,
                levels: [c(0), c(1), c(2)],
            });
        }
    }
    (out, n, sad)
}

/// The criterion's N (channel values counted over every photograph) and
/// the SAD of the model without the maps over them.
pub fn totals(evidence: &[Evidence]) -> (f64, f64) {
    let (_, n, sad) = samples(evidence, &[]);
    (n, sad)
}

/// What a solved value costs in levels of SAD, by the criterion over `n`
/// channel values whose SAD without the maps is `sad`: `ln N SAD / 2N`
/// (infinite with nothing counted; `solve` says why).
pub fn value_cost(n: f64, sad: f64) -> f64 {
    if n > 1.0 {
        sad * n.ln() / (2.0 * n)
    } else {
        f64::INFINITY
    }
}

/// Solves each laid-out object's map of `kind` from every photograph's
/// evidence: a colour map per channel, a specular map one value per texel
/// for the three (written grey).
/// A value is kept only when it earns its place in the criterion:
/// `BIC = 2N ln(SAD/N) + k ln N` falls by adding it when the SAD of the
/// samples in its texel falls by more than `ln N SAD / 2N` (SAD and N
/// those of the model without the map over every photograph); the rest
/// stay 1 and are not counted.
pub fn solve(
    evidence: &[Evidence],
    layouts: &[Option<Layout>],
    response: Option<Response>,
    kind: MapKind,
) -> Vec<ObjectMap> {
    let (samples, n, sad) = samples(evidence, layouts);
    solve_samples(&samples, layouts, (n, sad), &Levels::new(response), kind)
}

/// `solve` from the samples of each object, with the criterion's N and
/// SAD (`totals`) that price a value.
pub(super) fn solve_samples(
    samples: &[Vec<Sample>],
    layouts: &[Option<Layout>],
    (n, sad): (f64, f64),
    levels: &Levels,
    kind: MapKind,
) -> Vec<ObjectMap> {
    let scalar = kind == MapKind::Specular;
    // A colour map's texel is pinned by its object's other texels (seen
    // by two photographs or more); a highlight is pinned only by another.
    // A scalar map's one value is fitted to the three channels together.
    let (fits, per_texel) = if scalar {
        (SCALAR, MIN_PHOTOGRAPHS)
    } else {
        (PER_CHANNEL, 1)
    };
    let cost = value_cost(n, sad);
    let mut maps = Vec::new();
    for (object, (layout, samples)) in layouts.iter().zip(samples).enumerate() {
        let Some(layout) = *layout else { continue };
        if photographs(samples) < MIN_PHOTOGRAPHS {
            continue;
        }
        let texels = (layout.side * layout.side) as usize;
        let mut values = vec![1.0_f32; 3 * texels];
        let mut count = 0;
        let mut cell_sad = vec![0.0; texels];
        for channels in fits {
            let rule = (cost, per_texel);
            let fitted = fit_channels(samples, channels.clone(), texels, levels, rule);
            let Fitted { m, kept, .. } = &fitted;
            for (a, b) in cell_sad.iter_mut().zip(&fitted.cell_sad) {
                *a += b;
            }
            // One value counted per texel and fit: a scalar map's is one.
            for k in (0..texels).filter(|&k| kept[k]) {
                values[3 * k..3 * k + 3][channels.clone()].fill(m[k] as f32);
                count += 1;
            }
        }
        if count > 0 {
            maps.push(ObjectMap {
                object,
                layout,
                values,
                count,
                cell_sad,
            });
        }
    }
    maps
}
