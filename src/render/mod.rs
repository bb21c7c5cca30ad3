//! Renderers: the `Renderer` trait every backend implements, and the choice
//! of backend from a name (`phong`, `povray`, `blender`, `mitsuba`,
//! `cmd:TEMPLATE`, `worker:COMMAND`) through the list of backends
//! (`registry`), which also says what each cannot draw. Nothing outside
//! this module knows which backend runs.

pub mod camera_effects;
pub mod phong;
pub mod srgb;

pub mod backend;
pub mod blender;
pub mod command;
pub mod external;
pub mod layer;
pub mod maps;
pub mod mitsuba;
pub mod near_lights;
pub mod pbr_fields;
pub mod pov_bumps;
pub mod pov_maps;
pub mod pov_mesh_bumps;
pub mod pov_sdl;
pub mod povray;
mod recent;
#[cfg(test)]
mod refusal_table;
pub mod registry;
pub mod worker_start;

use crate::error::{Error, Result};
use crate::scene::{ParamSpace, Scene};

pub use crate::exec::{RenderFailure, RenderOptions, RenderResult};
pub use crate::raster::Image;
pub use phong::uv_pass::{surface_coords, SurfaceCoords, SurfacePoint};
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
