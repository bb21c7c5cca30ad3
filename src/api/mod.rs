//! The library's front door (`scenefit::api`): render a scene, fit it to
//! photographs (one or a set, always as a list of shots), diagnose a fit,
//! write a run's report. Every option is a typed value: nothing here reads
//! an environment variable (the command line does that, `cli/env.rs`) or
//! prints. The `scenefit` commands are thin shells over these functions,
//! and a binding for another language would call the same ones.

mod diagnose;
mod fit;
mod report;

pub use crate::diagnose::Diagnosis;
pub use diagnose::{diagnose, DiagnoseRequest};
pub use fit::{check_memory, fit, FitRequest, Fitted, Photographs};
pub use report::{report, ReportRequest};

pub use crate::diagnose::DiagnoseConfig;
pub use crate::fit::set::shots::Shot;
pub use crate::fit::{FitConfig, FitTarget, Observer};
pub use crate::raster::Image;
pub use crate::render::{RenderOptions, Renderer};
pub use crate::scene::{load_with as load_scene, Override, Scene};

use crate::error::Result;
use crate::scene::memory::Population;

/// The renderer named `spec` (`phong`, `povray`, `blender`, `mitsuba`,
/// `cmd:TEMPLATE`, `worker:COMMAND`) with `options`.
pub fn renderer(spec: &str, options: &RenderOptions) -> Result<Box<dyn Renderer>> {
    crate::render::from_spec_with(spec, options)
}

/// One image of `scene` (named `label` in messages, e.g. its file) drawn
/// by `renderer` with sampler seed `seed`, once the memory it needs has
/// been checked.
pub fn render(scene: &Scene, label: &str, renderer: &dyn Renderer, seed: u64) -> Result<Image> {
    let size = (scene.image.width, scene.image.height);
    // one image with one job
    crate::scene::memory::check(label, size, Population::SINGLE, 1)?;
    crate::render::render_one(renderer, scene, seed)
}
