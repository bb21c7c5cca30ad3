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
    // A session may keep what its base scene's camera rays hit (the
    // built-in tracer does when no free entry moves geometry): shots whose
    // cameras or shapes differ (a shot's known `set` camera) were all drawn
    // from the first shot's camera. Those get a session each.
    let rendered = if scenes.iter().all(|s| same_geometry(s, &scenes[0])) {
        renderer
            .session(&scenes[0], varying, jobs)?
            .render_batch(scenes, seed)
    } else {
        let mut out = Vec::with_capacity(scenes.len());
        for s in scenes {
            let mut session = renderer.session(s, varying, jobs)?;
            out.extend(session.render_batch(std::slice::from_ref(s), seed));
        }
        out
    };
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

/// Whether `a` and `b` have the same camera and the same shapes where
/// they are.
fn same_geometry(a: &Scene, b: &Scene) -> bool {
    let geometry = |s: &Scene| {
        let objects: Vec<_> = s.objects.iter().map(|o| (&o.shape, &o.transform)).collect();
        serde_json::to_value((&s.camera, &s.image, objects)).ok()
    };
    geometry(a) == geometry(b)
}
