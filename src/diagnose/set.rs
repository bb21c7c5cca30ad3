//! `diagnose` of a set fit (`fit --shots`): the same diagnosis as for one
//! photograph (`mod.rs`, `rounds.rs`), with the evidence pooled over every
//! photograph (each one's R² weighted by its pixels) and every refit a set
//! fit (the shared parameters over all photographs, each photograph's own
//! after them, `Schedule::Set`), so that an effect is accepted on the set:
//! an effect shared by every photograph is weak evidence in one and
//! strong across twenty.
//!
//! A candidate's refit here is warm: it starts from the best of the
//! effect's starts over the set (each also with its level matched, every
//! free light intensity scaled, per-shot ones included) and every block of
//! the set fit searches around the current values. The accepted candidate
//! is then refitted from scratch too (every shared value from the centre
//! of its box), and the better of the two kept: a warm refit keeps what
//! the model had bent to absorb the effect it lacked.

pub use super::diagnosis::{SetDiagnosis, ShotAfter};
pub use super::inputs::SetInputs;

use super::model::Model;
use super::schedule::Schedule;
use super::DiagnoseConfig;
use crate::error::Result;
use crate::metric::Deviation;
use std::path::Path;

/// Runs the diagnosis of a set, writing its files into `out`.
pub fn run(inputs: &SetInputs, out: &Path, config: &DiagnoseConfig) -> Result<SetDiagnosis> {
    let found = super::diagnose(inputs, Schedule::Set, out, config)?;
    let (held_out, held_out_images) = predictions(inputs, &found.model, config)?;
    let d = SetDiagnosis {
        diagnosis: found.diagnosis,
        shots_after: shots_after(inputs, &found.model, &found.before, &found.after),
        held_out,
        held_out_images,
    };
    let (before, after) = &found.residuals;
    super::report::write_set(out, &d, &found.model, inputs, (before, after))?;
    Ok(d)
}

/// Each held-out photograph predicted by the fit's model and by `model`
/// (a step on every photograph after the diagnosis goes here).
fn predictions(
    inputs: &SetInputs,
    model: &Model,
    c: &DiagnoseConfig,
) -> Result<(
    Vec<crate::fit::set::held_out::Compared>,
    Vec<crate::raster::Image>,
)> {
    use crate::fit::set::held_out::{compare, search};
    if inputs.held_out.is_empty() {
        return Ok((Vec::new(), Vec::new()));
    }
    let renderer = crate::render::from_spec_with(&c.renderer, &c.render_options)?;
    let models = (&inputs.scene, &model.scene);
    compare(
        models,
        &inputs.held_out,
        renderer.as_ref(),
        search(c.seed, c.jobs),
    )
}

/// Every photograph's own values after, and its deviations.
fn shots_after(
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
