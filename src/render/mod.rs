//! Renderers: the `Renderer` trait every backend implements, and the choice
//! of backend from a name (`phong`, `povray`, `blender`, `mitsuba`,
//! `cmd:TEMPLATE`, `worker:COMMAND`; `registry.rs`). Nothing outside this
//! module knows which backend runs.

pub mod camera_effects;
pub mod phong;
pub mod srgb;

pub mod blender;
pub mod command;
pub mod external;
pub mod mitsuba;
pub mod near_lights;
pub mod pbr_fields;
pub mod pov_sdl;
pub mod povray;
mod registry;

use crate::error::{Error, Result};
use crate::exec::{ExecOverrides, Executor};
use crate::scene::{ParamSpace, Scene};
use std::path::PathBuf;
use std::time::Duration;

pub use crate::exec::{RenderFailure, RenderResult};
pub use crate::raster::Image;
pub use registry::{from_spec, from_spec_with};

/// A backend. `session` prepares it to render many variants of one scene.
pub trait Renderer: Send + Sync {
    /// The name given on the command line, e.g. `phong`.
    fn name(&self) -> String;

    /// Renders at once when the user does not say (`--jobs`): the number of
    /// cores for CPU-bound renderers; more for those that mostly wait.
    fn default_jobs(&self) -> usize {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    }

    /// Prepares to render variants of `base` in which only the parameters
    /// of `varying` change, with up to `jobs` renders at once.
    fn session(
        &self,
        base: &Scene,
        varying: &ParamSpace,
        jobs: usize,
    ) -> Result<Box<dyn RenderSession>>;
}

/// A prepared renderer: renders batches of scene variants.
pub trait RenderSession: Send {
    /// The renderer and its version, for result.json.
    fn describe(&self) -> String;

    /// Renders every scene; `seed` seeds sampling backends, the same for the
    /// whole batch so that candidates are not told apart by noise.
    fn render_batch(&mut self, scenes: &[Scene], seed: u64) -> Vec<RenderResult>;
}

/// How the process-backed renderers run, over their defaults. Each field
/// left None falls back to its environment variable
/// (`SCENEFIT_RENDER_TIMEOUT`, `SCENEFIT_WORKER_MAX_RENDERS`,
/// `SCENEFIT_PYTHON`), then to the backend's default.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderOptions {
    /// One render may take this long; then its process is killed.
    pub render_timeout: Option<Duration>,
    /// A persistent worker is restarted after this many renders.
    pub worker_max_renders: Option<usize>,
    /// The Python that runs the Mitsuba worker.
    pub python: Option<PathBuf>,
    /// Renderer processes or workers at once, over the session's number.
    pub workers: Option<usize>,
    /// Where renderer processes run (local, or Slurm tasks).
    pub executor: Executor,
    /// The run directory's record of its Slurm jobs (`rundir::SLURM_JOBS`).
    pub slurm_ledger: Option<PathBuf>,
}

impl RenderOptions {
    /// The part the process layer applies.
    pub fn exec(&self) -> ExecOverrides {
        ExecOverrides {
            render_timeout: self.render_timeout,
            max_renders: self.worker_max_renders,
            workers: self.workers,
            executor: self.executor.clone(),
            slurm_ledger: self.slurm_ledger.clone(),
        }
    }
}

/// Renders one scene once (for `scenefit render`).
pub fn render_one(renderer: &dyn Renderer, scene: &Scene, seed: u64) -> Result<Image> {
    let mut session = renderer.session(scene, &ParamSpace::default(), 1)?;
    session
        .render_batch(std::slice::from_ref(scene), seed)
        .pop()
        .unwrap_or_else(|| {
            Err(RenderFailure {
                message: "no image".into(),
                stderr: String::new(),
            })
        })
        .map_err(|f| Error::Run(format!("{}: render failed: {f}", renderer.name())))
}
