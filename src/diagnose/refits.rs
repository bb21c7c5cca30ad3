//! What runs a diagnosis's refits, for one photograph and a set alike:
//! the renderer, the photographs, how models are refitted (`schedule.rs`)
//! and the renders counted. It renders models over every photograph, and
//! is what the backward step (`backward.rs`) and the lanes (`lanes.rs`)
//! refit with. The refits themselves: `one_refit.rs` (one photograph) and
//! `set_refit.rs` (a set).

use super::inputs::{Params, SetInputs};
use super::model::{shots_of, Model};
use super::schedule::Schedule;
use super::selection::sad;
use super::DiagnoseConfig;
use crate::error::{Error, Result};
use crate::fit::set::shots::Shot;
use crate::raster::Image;
use crate::render::Renderer;
use crate::scene::{ParamSpace, Scene};
use std::path::Path;

/// Runs the refits of one diagnosis and counts their renders.
pub(super) struct Refits<'a> {
    pub(super) renderer: &'a dyn Renderer,
    pub(super) inputs: &'a SetInputs,
    pub(super) config: &'a DiagnoseConfig,
    /// How models are refitted: as one photograph's, or as a set's.
    pub(super) schedule: Schedule,
    /// Renders at once (its lane's share, `lanes.rs`).
    pub(super) jobs: usize,
    pub(super) renders: usize,
    /// The diagnosis's directory (closed-form effects write their maps there).
    pub(super) out: &'a Path,
}

impl super::backward::Models for Refits<'_> {
    type Model = Model;

    fn scene<'m>(&self, m: &'m Model) -> &'m Scene {
        &m.scene
    }

    fn score(&self, m: &Model) -> (f64, usize) {
        (m.sad, m.dim(self.inputs))
    }

    /// Each scene refitted warm, every photograph's own values those of
    /// `from` that the scene still frees.
    fn refit_all(&mut self, scenes: Vec<Scene>, from: &Model) -> Result<Vec<Model>> {
        super::lanes::side_by_side(self, &scenes, |f, s| {
            let own: Vec<Params> = from
                .own
                .iter()
                .map(|o| {
                    let kept = o
                        .iter()
                        .filter(|(k, _)| s.free.iter().any(|p| &p.param == *k));
                    kept.map(|(k, v)| (k.clone(), v.clone())).collect()
                })
                .collect();
            f.warm(s, &own)
        })
        .into_iter()
        .collect()
    }
}

impl super::lanes::Lanes for Refits<'_> {
    fn jobs(&self) -> usize {
        self.jobs
    }

    fn lanes(&self) -> usize {
        super::lanes::lanes_for(self.config, self.jobs)
    }

    fn lane(&self, jobs: usize) -> Self {
        Refits {
            jobs,
            renders: 0,
            ..*self
        }
    }

    fn renders(&self) -> usize {
        self.renders
    }

    fn add_renders(&mut self, n: usize) {
        self.renders += n;
    }
}

impl Refits<'_> {
    /// Renders every photograph's scene in `shots`, each counted: the
    /// images and the sum of absolute differences over all (None: a
    /// render failed).
    pub(super) fn render(&mut self, shots: &[Shot]) -> Result<Option<(Vec<Image>, f64)>> {
        self.renders += shots.len();
        let scored = score(self.renderer, shots, self.jobs)?;
        Ok(scored
            .into_iter()
            .collect::<std::result::Result<Vec<_>, _>>()
            .ok()
            .map(|v| {
                let sad = v.iter().map(|x| x.1).sum();
                (v.into_iter().map(|x| x.0).collect(), sad)
            }))
    }

    /// `scene` with `own` values rendered over every photograph, as a
    /// model (None: a render failed).
    pub(super) fn model_of(&mut self, scene: Scene, own: &[Params]) -> Result<Option<Model>> {
        let shots = shots_of(&scene, self.inputs, own)?;
        Ok(self.render(&shots)?.map(|(images, sad)| Model {
            scene,
            own: own.to_vec(),
            images,
            sad,
        }))
    }

    /// The fitted model `scene` as it stands, with the fit's own values;
    /// an error naming the photograph whose render failed.
    pub(super) fn initial(&mut self, scene: Scene) -> Result<Model> {
        let inputs = self.inputs;
        let shots = shots_of(&scene, inputs, &inputs.own)?;
        self.renders += shots.len();
        let mut images = Vec::with_capacity(shots.len());
        let mut total = 0.0;
        for (r, s) in score(self.renderer, &shots, self.jobs)?
            .into_iter()
            .zip(&shots)
        {
            let (img, d) = r.map_err(|why| {
                let name = self.renderer.name();
                Error::Run(format!("{name}: the render of shot {} {why}", s.name))
            })?;
            total += d;
            images.push(img);
        }
        Ok(Model {
            scene,
            own: inputs.own.clone(),
            images,
            sad: total,
        })
    }
}

/// Each photograph's scene in `shots` rendered once (in one session) and
/// scored against it: its image and sum of absolute differences, or why
/// it has none.
fn score(
    renderer: &dyn Renderer,
    shots: &[Shot],
    jobs: usize,
) -> Result<Vec<std::result::Result<(Image, f64), String>>> {
    let scenes: Vec<Scene> = shots.iter().map(|s| s.scene.clone()).collect();
    let space = ParamSpace::from_scene(&scenes[0]);
    let images = crate::fit::set::renders::render_shots(renderer, &scenes, shots, &space, jobs, 0)?;
    Ok(images
        .into_iter()
        .zip(shots)
        .map(|(img, s)| {
            img.map(|img| {
                let d = sad(&s.target.image, &img, s.target.mask.as_ref());
                (img, d)
            })
        })
        .collect())
}
