//! A shininess per texel beside a solved specular map
//! (`material.shininess_map`): where the highlights' widths vary over a
//! surface (a varnished print beside matte paper, polished metal beside
//! brushed), a strength per texel cannot draw a narrow highlight in one
//! place and a broad one in another.
//!
//! A render is not linear in the exponent, so the exponent is not solved
//! like the strength (`texels.rs`): the strength map is solved again with
//! the scalar exponent moved over a grid around its value (× 2^(j/2),
//! `STEPS` each way), one set of lit renders per grid value (the dark
//! renders and surface passes, blind to the exponent, drawn once), and each
//! texel takes the grid value whose solve predicts its own pixels best,
//! charged for its values as `texels.rs` charges a strength (an exponent
//! other than the scalar is one value more). The texels that keep the
//! scalar exponent hold it in the map. The maps are then drawn, and the
//! shininess map kept only when the criterion pays for its values; the
//! caller (`albedo::solved`) weighs the effect on that model.

use super::effects::covered;
use super::map_evidence::{evidence, rendered, with_maps, without_maps};
use super::model::Model;
use super::refits::Refits;
use super::selection::{delta_bic, overdispersion_of};
use super::texel_layout::Layout;
use super::texels::{self, ObjectMap};
use crate::error::Result;
use crate::scene::texture::MapKind;
use crate::scene::Scene;

/// Grid steps each way from the scalar exponent, each a factor √2: from
/// a quarter to four times it, the range over which a lobe's width is
/// told apart from its strength by a few highlights.
const STEPS: i32 = 4;

/// The exponents a renderer draws (`material.shininess`'s own bounds).
const EXPONENT: (f64, f64) = (1.0, 10_000.0);

/// The grid's exponent `j` steps from `scalar`.
fn exponent(scalar: f64, j: i32) -> f64 {
    (scalar * 2f64.powf(j as f64 / 2.0)).clamp(EXPONENT.0, EXPONENT.1)
}

/// `model` (its specular maps solved at `layouts`, which `before` lacked)
/// with a shininess map beside each, its strength solved again texel by
/// texel at the exponent chosen there, files named by `tag`; the model
/// and the values its maps hold. None: no texel chose another exponent,
/// or the criterion did not pay for the values they add.
pub(super) fn beside(
    fits: &mut Refits,
    model: &Model,
    before: &Scene,
    layouts: &[Option<Layout>],
    (count, tag): (usize, &str),
) -> Result<Option<(Model, usize)>> {
    let kind = MapKind::Specular;
    let bare = without_maps(&model.scene, &model.scene, before, kind);
    let mapped: Vec<bool> = covered(&bare, kind)
        .iter()
        .zip(layouts)
        .map(|(&c, l)| c && l.is_some())
        .collect();
    if !mapped.contains(&true) {
        return Ok(None);
    }
    let response = bare.camera.response;
    let at = |j: i32| {
        let mut scene = bare.clone();
        for (o, _) in mapped.iter().enumerate().filter(|m| *m.1) {
            let m = &mut scene.objects[o].material;
            m.shininess = exponent(bare.objects[o].material.shininess, j);
        }
        scene
    };
    // The dark renders (strength 0) and the surface passes do not see the
    // exponent: drawn once, at the scalar; each step redraws only the lit.
    let mut ev = evidence(fits, &at(0), &model.own, &mapped, None, kind)?;
    let totals = texels::totals(&ev);
    let mut centre = texels::solve(&ev, layouts, response, kind);
    let mut solves: Vec<Vec<ObjectMap>> = Vec::new();
    for j in -STEPS..=STEPS {
        if j == 0 {
            solves.push(std::mem::take(&mut centre));
            continue;
        }
        let (_, lit) = rendered(fits, &at(j), &model.own, kind)?;
        ev.iter_mut().zip(lit).for_each(|(e, lit)| e.lit = lit);
        solves.push(texels::solve(&ev, layouts, response, kind));
    }
    let cost = texels::value_cost(totals.0, totals.1);
    let chosen = choose(&solves, cost, &bare);
    if chosen.iter().all(|(_, shine)| shine.count == 0) {
        return Ok(None);
    }
    let mut strength_refs = Vec::new();
    let mut shine_refs = Vec::new();
    let mut values = 0;
    for (strength, shine) in &chosen {
        let (o, side) = (strength.object, strength.layout.side);
        let path = super::map_file::path(fits.out, kind, tag, o, side)?;
        strength_refs.push((o, super::map_file::write(&path, strength)?));
        let path = super::map_file::path(fits.out, MapKind::Shininess, tag, o, side)?;
        shine_refs.push((o, super::map_file::write(&path, shine)?));
        values += strength.count + shine.count;
    }
    let scene = with_maps(&bare, &strength_refs, kind);
    let scene = with_maps(&scene, &shine_refs, MapKind::Shininess);
    let Some(m) = fits.model_of(scene, &model.own)? else {
        return Ok(None);
    };
    let c = overdispersion_of(&m, fits.inputs);
    let added = values.saturating_sub(count);
    let pays = delta_bic(model.sad, m.sad, totals.0, added, c) < 0.0;
    Ok(pays.then_some((m, values)))
}

/// Each object's strength map and shininess map, texel by texel from the
/// grid's solves (`solves[j]`: the strength solved at exponent step
/// `j - STEPS`), the step whose cell SAD plus the cost of its values is
/// least (a tie keeps the step nearer the scalar). A shininess map's
/// `count` is its texels off the scalar exponent.
fn choose(solves: &[Vec<ObjectMap>], cost: f64, bare: &Scene) -> Vec<(ObjectMap, ObjectMap)> {
    let centre = STEPS as usize;
    let mut out = Vec::new();
    for base in &solves[centre] {
        let o = base.object;
        let scalar = bare.objects[o].material.shininess;
        let texels = base.cell_sad.len();
        let maps: Vec<Option<&ObjectMap>> = solves
            .iter()
            .map(|s| s.iter().find(|m| m.object == o))
            .collect();
        let mut strength = vec![1.0_f32; 3 * texels];
        let mut shine = vec![scalar as f32; 3 * texels];
        let (mut strength_count, mut shine_count) = (0, 0);
        for t in 0..texels {
            // (score, step, strength) of the best step so far.
            let mut best: Option<(f64, usize, f32)> = None;
            for j in order(solves.len()) {
                let Some(map) = maps[j] else { continue };
                let value = map.values[3 * t];
                let held = usize::from(value != 1.0) + usize::from(j != centre);
                let score = map.cell_sad[t] + cost * held as f64;
                if best.is_none_or(|b| score < b.0) {
                    best = Some((score, j, value));
                }
            }
            let Some((_, j, value)) = best else { continue };
            strength[3 * t..3 * t + 3].fill(value);
            strength_count += usize::from(value != 1.0);
            if j != centre {
                let e = exponent(scalar, j as i32 - STEPS);
                shine[3 * t..3 * t + 3].fill(e as f32);
                shine_count += 1;
            }
        }
        let map = |values, count| ObjectMap {
            object: o,
            layout: base.layout,
            values,
            count,
            cell_sad: Vec::new(),
        };
        out.push((map(strength, strength_count), map(shine, shine_count)));
    }
    out
}

/// The grid's steps from the scalar outwards (0, -1, 1, -2, 2, …), as
/// indices of `n` solves centred on the scalar: a tie keeps the nearer.
fn order(n: usize) -> impl Iterator<Item = usize> {
    let centre = n / 2;
    (0..n).map(move |i| {
        let d = i.div_ceil(2);
        match i % 2 {
            1 => centre - d,
            _ => centre + d,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_steps_go_out_from_the_scalar() {
        let steps: Vec<usize> = order(9).collect();
        assert_eq!(steps, vec![4, 3, 5, 2, 6, 1, 7, 0, 8]);
    }

    fn solve(object: usize, values: &[f32], cell_sad: &[f64]) -> ObjectMap {
        ObjectMap {
            object,
            layout: Layout {
                side: 1,
                scale: [1.0, 1.0],
            },
            values: values.iter().flat_map(|&v| [v; 3]).collect(),
            count: values.iter().filter(|&&v| v != 1.0).count(),
            cell_sad: cell_sad.to_vec(),
        }
    }

    fn bare(shininess: f64) -> Scene {
        let material =
            format!(r#""color": [0.5, 0.5, 0.5], "specular": 0.5, "shininess": {shininess}"#);
        crate::scene::test_scene::ball(&material, "")
    }

    /// Two texels: the first predicted best at the scalar exponent, the
    /// second two steps up (twice the exponent), by more than a value's
    /// cost; each takes its own, and only the second is counted.
    #[test]
    fn each_texel_takes_the_exponent_that_predicts_its_pixels() {
        let solves: Vec<Vec<ObjectMap>> = (0..9)
            .map(|j| {
                let first = if j == 4 { 10.0 } else { 50.0 };
                let second = if j == 6 { 5.0 } else { 80.0 };
                vec![solve(0, &[1.5, 0.8], &[first, second])]
            })
            .collect();
        let chosen = choose(&solves, 2.0, &bare(20.0));
        let (strength, shine) = &chosen[0];
        assert_eq!(shine.values[0], 20.0);
        assert!((shine.values[3] - 40.0).abs() < 1e-3, "{:?}", shine.values);
        assert_eq!(shine.count, 1);
        assert_eq!(strength.values[0], 1.5);
        assert_eq!(strength.count, 2);
    }

    /// A step that predicts better by less than the cost of its value
    /// does not take the texel from the scalar exponent.
    #[test]
    fn a_gain_that_does_not_pay_keeps_the_scalar_exponent() {
        let solves: Vec<Vec<ObjectMap>> = (0..9)
            .map(|j| {
                let sad = if j == 2 { 9.0 } else { 10.0 };
                vec![solve(0, &[1.2], &[sad])]
            })
            .collect();
        let chosen = choose(&solves, 2.0, &bare(30.0));
        assert_eq!(chosen[0].1.count, 0);
        assert_eq!(chosen[0].1.values[0], 30.0);
    }
}
