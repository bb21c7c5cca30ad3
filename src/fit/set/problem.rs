//! The shared block of a set fit as a `Problem`: one candidate is one point
//! of the shared parameters, drawn once per photograph (each with its own
//! per-shot values and `set` fields in place) and scored over all of them.

use crate::fit::executor::Problem;
use crate::fit::render_seed;
use crate::fit::FitTarget;
use crate::metric::{deviation, residuals, Deviation};
use crate::optimize::Evaluation;
use crate::raster::Image;
use crate::render::RenderSession;
use crate::scene::{ParamSpace, Scene};

pub struct SetProblem<'a> {
    pub session: &'a mut dyn RenderSession,
    /// The shared parameters.
    pub space: ParamSpace,
    /// Each photograph's scene with its own values in place.
    pub bases: Vec<Scene>,
    pub targets: Vec<&'a FitTarget>,
    pub seed: u64,
    /// The best candidate's fitness and images, one per photograph.
    best: Option<(f64, Vec<Image>)>,
    failures: Vec<String>,
    failed_renders: usize,
}

impl<'a> SetProblem<'a> {
    pub fn new(
        session: &'a mut dyn RenderSession,
        space: ParamSpace,
        bases: Vec<Scene>,
        targets: Vec<&'a FitTarget>,
        seed: u64,
    ) -> Self {
        SetProblem {
            session,
            space,
            bases,
            targets,
            seed,
            best: None,
            failures: Vec::new(),
            failed_renders: 0,
        }
    }

    /// Candidates that failed so far (a render crashed, hung or was wrong).
    pub fn failed_renders(&self) -> usize {
        self.failed_renders
    }

    /// Scores one candidate's images (one per photograph): the deviation
    /// over every counted pixel of every photograph, as one fitness.
    fn score(&mut self, i: usize, generation: usize, images: Vec<Image>, want: bool) -> Evaluation {
        let mut res = Vec::new();
        let mut parts = Vec::with_capacity(images.len());
        for (img, t) in images.iter().zip(&self.targets) {
            if img.dimensions() != t.image.dimensions() {
                self.failed_renders += 1;
                self.failures.push(format!(
                    "generation {generation} candidate {i}: image is {}x{}, expected {}x{}",
                    img.width(),
                    img.height(),
                    t.image.width(),
                    t.image.height()
                ));
                return Evaluation::failed();
            }
            parts.push((deviation(&t.image, img, t.mask.as_ref()), counted(t)));
            if want {
                res.extend(residuals(&t.image, img, t.mask.as_ref()));
            }
        }
        let fitness = Deviation::pooled(&parts).fitness();
        if self.best.as_ref().is_none_or(|(f, _)| fitness < *f) {
            self.best = Some((fitness, images));
        }
        Evaluation {
            fitness,
            residuals: want.then_some(res),
        }
    }
}

/// Pixels of a target that count.
pub fn counted(t: &FitTarget) -> usize {
    t.mask
        .as_ref()
        .map_or((t.image.width() * t.image.height()) as usize, |m| {
            m.pixels().len()
        })
}

impl Problem for SetProblem<'_> {
    fn evaluate(&mut self, points: &[Vec<f64>], want: bool, generation: usize) -> Vec<Evaluation> {
        self.failures.clear();
        let n = self.bases.len();
        let scenes: Vec<Scene> = points
            .iter()
            .flat_map(|u| self.bases.iter().map(|b| self.space.scene_at(b, u)))
            .collect();
        let mut rendered = self
            .session
            .render_batch(&scenes, render_seed(self.seed, generation))
            .into_iter();
        let mut out = Vec::with_capacity(points.len());
        for i in 0..points.len() {
            let mut images = Vec::with_capacity(n);
            let mut failed = None;
            for s in 0..n {
                match rendered.next() {
                    Some(Ok(img)) => images.push(img),
                    Some(Err(f)) => failed = failed.or(Some(format!("shot {s}: {f}"))),
                    None => failed = failed.or(Some(format!("shot {s}: no image"))),
                }
            }
            out.push(match failed {
                Some(why) => {
                    self.failed_renders += 1;
                    self.failures
                        .push(format!("generation {generation} candidate {i}: {why}"));
                    Evaluation::failed()
                }
                None => self.score(i, generation, images, want),
            });
        }
        out
    }

    fn failures(&self) -> &[String] {
        &self.failures
    }

    fn best_image(&self) -> Option<&Image> {
        self.best.as_ref().and_then(|(_, v)| v.first())
    }

    fn params(&self, point: &[f64]) -> serde_json::Map<String, serde_json::Value> {
        self.space
            .json_values(&self.space.scene_at(&self.bases[0], point))
    }

    fn best_deviation(&self) -> Deviation {
        let Some((_, images)) = &self.best else {
            return Deviation::default();
        };
        let parts: Vec<(Deviation, usize)> = images
            .iter()
            .zip(&self.targets)
            .map(|(img, t)| (deviation(&t.image, img, t.mask.as_ref()), counted(t)))
            .collect();
        Deviation::pooled(&parts)
    }
}
