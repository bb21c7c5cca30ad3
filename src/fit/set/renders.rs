//! Every photograph of a set rendered once, in one render session, each
//! render checked against its photograph's size: what the end of a set fit
//! and the set diagnosis's scoring of a model share.

use super::shots::Shot;
use crate::error::Result;
use crate::raster::Image;
use crate::render::Renderer;
use crate::scene::{ParamSpace, Scene};

/// `scenes` (one per shot, in order) rendered in one session over
/// `varying` with sampler seed `seed`: each shot's image, or why it has
/// none (the render failed, or has the wrong size).
pub fn render_shots(
    renderer: &dyn Renderer,
    scenes: &[Scene],
    shots: &[Shot],
    varying: &ParamSpace,
    jobs: usize,
    seed: u64,
) -> Result<Vec<std::result::Result<Image, String>>> {
    let mut session = renderer.session(&scenes[0], varying, jobs)?;
    let rendered = session.render_batch(scenes, seed);
    Ok(rendered
        .into_iter()
        .zip(shots)
        .map(|(r, s)| match r {
            Ok(img) if img.dimensions() == s.target.image.dimensions() => Ok(img),
            Ok(img) => Err(format!(
                "has the wrong size ({}x{}, the photograph is {}x{})",
                img.width(),
                img.height(),
                s.target.image.width(),
                s.target.image.height()
            )),
            Err(f) => Err(format!("failed: {f}")),
        })
        .collect())
}
