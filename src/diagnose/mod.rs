//! `scenefit diagnose`: trace the residual of a finished fit to the effect
//! the model lacks, add it, refit, and report the error before and after
//! (docs/diagnose.md).
//!
//! One photograph is a set of one (`SetInputs::one`): it takes the same
//! path as a set (`diagnose` here, `rounds.rs`), only its refits differ
//! (`Schedule`, `schedule.rs`, dispatched in `trials.rs`). Each round
//! scores every applicable effect (`effects/`) by how much of the residual
//! its feature maps explain (`residual.rs`, pooled over the photographs),
//! then confirms each by refits with the effect added: for one
//! photograph a warm one (from the best of the effect's starts,
//! `starts.rs`, its own parameters and those it trades with searched, then
//! everything refined around the result) and one from scratch (every
//! parameter over its bounds), the better counting (`one_refit.rs`); for
//! a set a warm set fit (`set_refit.rs`). An effect is accepted when its
//! refit lowers the Bayesian information criterion by more than a margin
//! and the sum of absolute differences by at least `min_gain`
//! (`selection.rs`), against the unchanged model refitted the same ways,
//! so that neither further convergence nor a better basin is credited to
//! an effect. An accepted model is settled (polished, or for a set
//! refitted from scratch) before the next round. Rounds repeat until
//! nothing is accepted; `unexplained` is reported when smooth structure
//! remains in the residual. Inputs come from a fit directory
//! (`inputs.rs`); the files written are named in `rundir`.

mod albedo;
mod backward;
mod config;
mod diagnosis;
pub mod effects;
pub mod features;
mod footing;
mod gloss;
mod held;
mod imitations;
mod inputs;
mod lanes;
mod map_evidence;
mod map_file;
mod map_side;
mod map_solve;
mod model;
mod one_refit;
pub mod photo;
mod predictions;
mod refits;
pub mod report;
pub mod residual;
mod rounds;
mod schedule;
mod selection;
mod set_refit;
mod starts;
mod texel_fit;
mod texel_layout;
mod texels;
mod trials;

pub use config::DiagnoseConfig;
pub use diagnosis::{Candidate, Diagnosis, SetDiagnosis, ShotAfter, UNEXPLAINED};
pub use inputs::{Inputs, SetInputs};
pub use texel_layout::MAX_MAP_SIDE;

use crate::error::{Error, Result};
use crate::metric::Deviation;
use crate::render::{from_spec_with, Renderer};
use model::{pooled, Model};
use refits::Refits;
use residual::Residual;
use rounds::{rounds, Rounds};
use schedule::Schedule;
use std::path::Path;
use std::time::Instant;

/// Runs the diagnosis of a fit, one photograph (a set of one) or a set,
/// writing its files into `out`; held-out photographs are predicted after
/// it by the same renderer.
pub fn run(inputs: &SetInputs, out: &Path, config: &DiagnoseConfig) -> Result<SetDiagnosis> {
    let renderer = from_spec_with(&config.renderer, &config.render_options)?;
    let found = diagnose(inputs, Schedule::of(inputs), out, config, renderer.as_ref())?;
    let (held_out, held_out_images) =
        predictions::held_out(inputs, &found.model, config, renderer.as_ref())?;
    let d = SetDiagnosis {
        shots_after: predictions::shots_after(inputs, &found.model, &found.before, &found.after),
        diagnosis: found.diagnosis,
        held_out,
        held_out_images,
    };
    let (before, after) = &found.residuals;
    report::write(out, &d, &found.model, inputs, (before, after))?;
    Ok(d)
}

/// What a diagnosis found, before its files are written: diagnosis.json's
/// common part, the final model (its scene with the held entries free
/// again), and every photograph's deviations and residuals before and
/// after.
struct Outcome {
    diagnosis: Diagnosis,
    model: Model,
    before: Vec<Deviation>,
    after: Vec<Deviation>,
    residuals: (Vec<Residual>, Vec<Residual>),
}

/// The one diagnosis of one photograph or a set: the fitted model
/// rendered, the unchanged model refitted, the rounds, and the model
/// after them; maps `out` holds that the final model does not name are
/// removed.
fn diagnose(
    inputs: &SetInputs,
    schedule: Schedule,
    out: &Path,
    config: &DiagnoseConfig,
    renderer: &dyn Renderer,
) -> Result<Outcome> {
    let started = Instant::now();
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    let (scene, held) = held::split(&inputs.scene, config.refit_geometry);
    let mut fits = Refits {
        renderer,
        inputs,
        config,
        schedule,
        jobs: config.jobs,
        renders: 0,
        out,
    };
    let model0 = fits.initial(scene)?;
    let before = model0.deviations(inputs);
    let residuals_before = model0.residuals(inputs);
    let mut model = fits.unchanged(model0)?;
    let refined = model.deviation(inputs);
    let n = selection::channel_values(inputs);
    let Rounds {
        candidates,
        mut accepted,
        removed,
        imitations,
    } = rounds(&mut fits, &mut model, n)?;
    model = fits.finish(model, !accepted.is_empty())?;
    let residuals_after = model.residuals(inputs);
    // Smooth structure left in most photographs.
    let structured = residuals_after.iter().filter(|r| r.structured()).count();
    let unexplained = 2 * structured > residuals_after.len();
    if unexplained {
        accepted.push(UNEXPLAINED.into());
    }
    let after = model.deviations(inputs);
    model.scene = held::restore(&model.scene, &held);
    let diagnosis = Diagnosis {
        deviation_before: pooled(&before, inputs),
        deviation_after: pooled(&after, inputs),
        candidates,
        accepted,
        params_after: schedule.values(&model.scene),
        deviation_refined: refined,
        unexplained,
        renders: fits.renders,
        wall_seconds: started.elapsed().as_secs_f64(),
        min_gain: config.min_gain,
        held: held::paths(&held),
        removed,
        imitations,
    };
    albedo::prune(out, &model.scene);
    Ok(Outcome {
        diagnosis,
        model,
        before,
        after,
        residuals: (residuals_before, residuals_after),
    })
}
