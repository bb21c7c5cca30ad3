//! The problem a fit solves: render a batch of candidates (unit-cube points
//! of one phase's parameters over a base scene) and score each against the
//! target, keeping the best image and why failed renders failed.

use super::executor::Problem;
use super::FitTarget;
use crate::metric::{deviation, residuals, Deviation};
use crate::optimize::Evaluation;
use crate::raster::Image;
use crate::render::{RenderResult, RenderSession};
use crate::scene::{ParamSpace, Scene};

pub struct RenderProblem<'a> {
    pub session: Box<dyn RenderSession>,
    pub space: ParamSpace,
    pub base: Scene,
    pub target: &'a FitTarget,
    /// The run's seed: each generation's sampler seed is drawn from it.
    pub seed: u64,
    best: Option<(f64, Image)>,
    failures: Vec<String>,
}

impl<'a> RenderProblem<'a> {
    pub fn new(
        session: Box<dyn RenderSession>,
        space: ParamSpace,
        base: Scene,
        target: &'a FitTarget,
        seed: u64,
    ) -> Self {
        RenderProblem {
            session,
            space,
            base,
            target,
            seed,
            best: None,
            failures: Vec::new(),
        }
    }

    /// Renders the best point once, for its image (a resumed run).
    pub fn adopt_best(&mut self, point: &[f64], fitness: f64) {
        let scene = self.space.scene_at(&self.base, point);
        if let Some(Ok(img)) = self
            .session
            .render_batch(std::slice::from_ref(&scene), 0)
            .pop()
        {
            self.best = Some((fitness, img));
        }
    }

    pub fn into_best_image(self) -> Option<Image> {
        self.best.map(|(_, img)| img)
    }

    fn score(&mut self, i: usize, generation: usize, r: RenderResult, want: bool) -> Evaluation {
        // After Ctrl-C the executor drops the batch: scoring what was
        // rendered before it would only delay the exit
        if crate::exec::cancel::is_cancelled() {
            return Evaluation::failed();
        }
        let t = &self.target.image;
        match r {
            Ok(img) if img.dimensions() == t.dimensions() => {
                let fitness = deviation(t, &img, self.target.mask.as_ref()).fitness();
                let res = want.then(|| residuals(t, &img, self.target.mask.as_ref()));
                if self.best.as_ref().is_none_or(|(f, _)| fitness < *f) {
                    self.best = Some((fitness, img));
                }
                Evaluation {
                    fitness,
                    residuals: res,
                }
            }
            Ok(img) => {
                self.failures.push(format!(
                    "generation {generation} candidate {i}: image is {}x{}, expected {}x{}",
                    img.width(),
                    img.height(),
                    t.width(),
                    t.height()
                ));
                Evaluation::failed()
            }
            Err(f) => {
                self.failures
                    .push(format!("generation {generation} candidate {i}: {f}"));
                Evaluation::failed()
            }
        }
    }
}

impl Problem for RenderProblem<'_> {
    fn evaluate(&mut self, points: &[Vec<f64>], want: bool, generation: usize) -> Vec<Evaluation> {
        self.failures.clear();
        let scenes: Vec<Scene> = points
            .iter()
            .map(|u| self.space.scene_at(&self.base, u))
            .collect();
        let images = self
            .session
            .render_batch(&scenes, render_seed(self.seed, generation));
        images
            .into_iter()
            .enumerate()
            .map(|(i, r)| self.score(i, generation, r, want))
            .collect()
    }

    fn failures(&self) -> &[String] {
        &self.failures
    }

    fn best_image(&self) -> Option<&Image> {
        self.best.as_ref().map(|(_, img)| img)
    }

    fn params(&self, point: &[f64]) -> serde_json::Map<String, serde_json::Value> {
        self.space
            .json_values(&self.space.scene_at(&self.base, point))
    }

    fn best_deviation(&self) -> Deviation {
        self.best
            .as_ref()
            .map(|(_, img)| deviation(&self.target.image, img, self.target.mask.as_ref()))
            .unwrap_or_default()
    }
}

/// The sampler seed of a generation: the same for all its candidates.
pub fn render_seed(seed: u64, generation: usize) -> u64 {
    (seed.wrapping_mul(1_000_003).wrapping_add(generation as u64)) & 0x7fff_ffff
}
