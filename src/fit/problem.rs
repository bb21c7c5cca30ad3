//! The problem a fit solves, for one photograph or a set: a candidate is a
//! unit-cube point of the parameters searched, drawn once per photograph
//! over that photograph's base scene (its own values and `set` fields in
//! place) and scored over all of them as one fitness. It keeps the best
//! candidate's images and why failed renders failed.

use super::executor::Problem;
use super::FitTarget;
use crate::metric::{
    blurred_levels, blurred_residuals_with, blurred_weight, deviation, residuals, Deviation,
};
use crate::optimize::Evaluation;
use crate::raster::Image;
use crate::render::RenderSession;
use crate::scene::{ParamSpace, Scene};

/// One photograph's side of a blurred comparison at one blur: its
/// blurred levels, and the blurred weight of its mask (the divisor of
/// every render's blur, the same for each).
struct Blurred {
    levels: Vec<f32>,
    weight: Vec<f32>,
}

pub struct ShotsProblem<'a> {
    session: Box<dyn RenderSession>,
    /// The parameters searched.
    pub space: ParamSpace,
    /// Each photograph's scene with everything not searched in place.
    pub bases: Vec<Scene>,
    pub targets: Vec<&'a FitTarget>,
    /// The run's (or block's) seed: each generation's sampler seed is
    /// drawn from it.
    pub seed: u64,
    /// The best candidate's fitness and images, one per photograph.
    best: Option<(f64, Vec<Image>)>,
    failures: Vec<String>,
    failed_renders: usize,
    /// Each target's blurred levels and blurred mask weight at the blur
    /// last asked for (a local search asks for one blur over many
    /// batches).
    blurred: Option<(u64, Vec<Blurred>)>,
}

impl<'a> ShotsProblem<'a> {
    pub fn new(
        session: Box<dyn RenderSession>,
        space: ParamSpace,
        bases: Vec<Scene>,
        targets: Vec<&'a FitTarget>,
        seed: u64,
    ) -> Self {
        debug_assert_eq!(bases.len(), targets.len());
        ShotsProblem {
            session,
            space,
            bases,
            targets,
            seed,
            best: None,
            failures: Vec::new(),
            failed_renders: 0,
            blurred: None,
        }
    }

    /// Renders the best point once, for its images (a resumed run).
    pub fn adopt_best(&mut self, point: &[f64], fitness: f64) {
        let scenes = self.scenes_at(point);
        let images: Option<Vec<Image>> = self
            .session
            .render_batch(&scenes, 0)
            .into_iter()
            .map(|r| r.ok())
            .collect();
        if let Some(images) = images.filter(|v| v.len() == scenes.len()) {
            self.best = Some((fitness, images));
        }
    }

    /// The best candidate's images, one per photograph.
    pub fn into_best_images(self) -> Option<Vec<Image>> {
        self.best.map(|(_, images)| images)
    }

    /// Candidates that failed so far (a render crashed, hung or was wrong).
    pub fn failed_renders(&self) -> usize {
        self.failed_renders
    }

    fn scenes_at(&self, point: &[f64]) -> Vec<Scene> {
        self.bases
            .iter()
            .map(|b| self.space.scene_at(b, point))
            .collect()
    }

    fn fail(&mut self, i: usize, generation: usize, why: String) -> Evaluation {
        self.failed_renders += 1;
        self.failures
            .push(format!("generation {generation} candidate {i}: {why}"));
        Evaluation::failed()
    }

    /// Every target's levels and mask weight blurred by `sigma` pixels,
    /// computed once per blur.
    fn blurred_targets(&mut self, sigma: f64) -> &[Blurred] {
        if self
            .blurred
            .as_ref()
            .is_none_or(|(s, _)| *s != sigma.to_bits())
        {
            let levels = self
                .targets
                .iter()
                .map(|t| {
                    let (w, h) = t.image.dimensions();
                    Blurred {
                        levels: blurred_levels(&t.image, t.mask.as_ref(), sigma),
                        weight: blurred_weight(w, h, t.mask.as_ref(), sigma),
                    }
                })
                .collect();
            self.blurred = Some((sigma.to_bits(), levels));
        }
        self.blurred.as_ref().map_or(&[], |(_, v)| v)
    }

    /// One photograph's residuals at the view asked for (see
    /// `Problem::evaluate`).
    fn residuals_of(&mut self, shot: usize, img: &Image, blur: f64) -> Vec<f32> {
        let t = self.targets[shot];
        if blur > 0.0 {
            let b = &self.blurred_targets(blur)[shot];
            blurred_residuals_with((&b.levels, &b.weight), img, t.mask.as_ref(), blur)
        } else {
            residuals(&t.image, img, t.mask.as_ref())
        }
    }

    /// Scores one candidate's images (one per photograph): the deviation
    /// over every counted pixel of every photograph, as one fitness.
    fn score(
        &mut self,
        i: usize,
        generation: usize,
        images: Vec<Image>,
        want: Option<f64>,
    ) -> Evaluation {
        let mut res = Vec::new();
        let mut parts = Vec::with_capacity(images.len());
        for (shot, img) in images.iter().enumerate() {
            let t = self.targets[shot];
            if img.dimensions() != t.image.dimensions() {
                let why = format!(
                    "image is {}x{}, expected {}x{}",
                    img.width(),
                    img.height(),
                    t.image.width(),
                    t.image.height()
                );
                return self.fail(i, generation, why);
            }
            parts.push((deviation(&t.image, img, t.mask.as_ref()), counted(t)));
            if let Some(blur) = want {
                res.extend(self.residuals_of(shot, img, blur));
            }
        }
        let fitness = over(&parts).fitness();
        if self.best.as_ref().is_none_or(|(f, _)| fitness < *f) {
            self.best = Some((fitness, images));
        }
        Evaluation {
            fitness,
            residuals: want.map(|_| res),
        }
    }
}

/// The deviation over every photograph: one photograph's own, exactly
/// (the pooled weights of one part would round it), or the pooled one.
pub fn over(parts: &[(Deviation, usize)]) -> Deviation {
    match parts {
        [(d, _)] => *d,
        _ => Deviation::pooled(parts),
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

impl Problem for ShotsProblem<'_> {
    fn evaluate(
        &mut self,
        points: &[Vec<f64>],
        want: Option<f64>,
        generation: usize,
    ) -> Vec<Evaluation> {
        self.failures.clear();
        let n = self.bases.len();
        let scenes: Vec<Scene> = points.iter().flat_map(|u| self.scenes_at(u)).collect();
        let mut rendered = self
            .session
            .render_batch(&scenes, render_seed(self.seed, generation))
            .into_iter();
        let mut out = Vec::with_capacity(points.len());
        for i in 0..points.len() {
            let mut images = Vec::with_capacity(n);
            let mut failed = None;
            for s in 0..n {
                // A set names the photograph; one photograph needs no name.
                let shot = if n > 1 {
                    format!("shot {s}: ")
                } else {
                    String::new()
                };
                match rendered.next() {
                    Some(Ok(img)) => images.push(img),
                    Some(Err(f)) => failed = failed.or(Some(format!("{shot}{f}"))),
                    None => failed = failed.or(Some(format!("{shot}no image"))),
                }
            }
            // After Ctrl-C the executor drops the batch: scoring what was
            // rendered before it would only delay the exit.
            out.push(match failed {
                _ if crate::exec::cancel::is_cancelled() => Evaluation::failed(),
                Some(why) => self.fail(i, generation, why),
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
        over(&parts)
    }
}

/// The sampler seed of a generation: the same for all its candidates.
pub fn render_seed(seed: u64, generation: usize) -> u64 {
    (seed.wrapping_mul(1_000_003).wrapping_add(generation as u64)) & 0x7fff_ffff
}
