//! What a diagnosis reports of every photograph once its model is
//! settled: each fitted photograph's own values and deviations before and
//! after (diagnosis.json's `shots_after`), and each held-out photograph
//! predicted by the improved model beside the fit's prediction (`held_out`,
//! `fit::set::held_out`).

use super::diagnosis::ShotAfter;
use super::inputs::SetInputs;
use super::model::Model;
use super::DiagnoseConfig;
use crate::error::Result;
use crate::fit::set::held_out::{compare, search, Compared};
use crate::metric::Deviation;
use crate::raster::Image;
use crate::render::Renderer;

/// Each held-out photograph predicted by `model`, beside the fit's
/// prediction (taken from result.json where the fit made it), drawn by
/// the diagnosis's own `renderer`.
pub fn held_out(
    inputs: &SetInputs,
    model: &Model,
    c: &DiagnoseConfig,
    renderer: &dyn Renderer,
) -> Result<(Vec<Compared>, Vec<Image>)> {
    if inputs.held_out.is_empty() {
        return Ok((Vec::new(), Vec::new()));
    }
    compare(
        (&inputs.scene, &model.scene),
        &inputs.held_out,
        &inputs.fit_held_out,
        renderer,
        search(c.seed, c.jobs),
    )
}

/// Every fitted photograph's own values after, and its deviations.
pub fn shots_after(
    inputs: &SetInputs,
    model: &Model,
    before: &[Deviation],
    after: &[Deviation],
) -> Vec<ShotAfter> {
    inputs
        .shots
        .iter()
        .enumerate()
        .map(|(i, s)| ShotAfter {
            name: s.name.clone(),
            params: model.own[i].clone(),
            deviation_before: before[i],
            deviation_after: after[i],
        })
        .collect()
}
