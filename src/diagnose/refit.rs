//! The refits of a diagnosis, and the one place that calls into
//! `crate::fit`: [`Refits::fit`] runs a fit in memory and takes its fitted
//! scene and best image from the outcome (a refit writes no files: it is
//! never resumed, and its checkpoints would cost more than its renders).

use super::selection::sad;
use super::{Candidate, DiagnoseConfig, Inputs};
use crate::error::Result;
use crate::fit::{self, FitConfig, FitTarget};
use crate::metric::deviation;
use crate::optimize::DeConfig;
use crate::raster::Image;
use crate::render::Renderer;
use crate::scene::{FreeParam, Scene};

/// A model and how close it renders to the target.
pub struct Model {
    pub scene: Scene,
    pub image: Image,
    /// Sum of absolute differences from the target.
    pub sad: f64,
}

impl Model {
    /// `scene` rendered as `image`, scored against the inputs' target.
    pub fn new(scene: Scene, image: Image, inputs: &Inputs) -> Model {
        let sad = sad(&inputs.target, &image, inputs.mask.as_ref());
        Model { scene, image, sad }
    }

    /// Whichever of the two is closer to the target (self on a tie).
    pub fn better(self, other: Model) -> Model {
        if other.sad < self.sad {
            other
        } else {
            self
        }
    }
}

/// How a refit of every parameter runs.
#[derive(Clone, Copy, Debug)]
pub struct Refine {
    pub generations: usize,
    /// Unit-cube radius around the current values (1: from scratch, the
    /// current values one individual of the start).
    pub radius: f64,
    pub population: usize,
    /// A refit from scratch, which exists to find another basin: SHADE
    /// for all its generations. The others run the hybrid, ended once it
    /// has settled.
    pub explore: bool,
}

impl Refine {
    /// A refit from scratch: uniform over the bounds.
    pub fn restart(config: &DiagnoseConfig) -> Refine {
        Refine {
            generations: config.restart_generations,
            radius: 1.0,
            population: config.restart_population,
            explore: true,
        }
    }

    /// The short refit, close to the current values, that compares effects.
    pub fn close(config: &DiagnoseConfig, generations: usize) -> Refine {
        Refine {
            generations,
            radius: config.start_radius,
            population: config.population,
            explore: false,
        }
    }

    /// The refit of an accepted model.
    pub fn polish(config: &DiagnoseConfig) -> Refine {
        Refine {
            generations: config.polish_generations,
            radius: config.polish_radius,
            population: config.search_population,
            explore: false,
        }
    }
}

/// A new effect's own search before the refit of every parameter: the
/// entries searched (its own, and those it trades with) and the spread of
/// the start.
pub struct Search {
    pub params: Vec<FreeParam>,
    pub radius: f64,
}

/// Runs the refits of one diagnosis and counts the renders spent (starts'
/// renders included, through `renders`).
pub struct Refits<'a> {
    renderer: &'a dyn Renderer,
    pub inputs: &'a Inputs,
    pub config: &'a DiagnoseConfig,
    target: FitTarget,
    /// Renders at once in each of its fits (its lane's share, `lanes.rs`).
    jobs: usize,
    pub renders: usize,
}

impl<'a> Refits<'a> {
    pub fn new(
        renderer: &'a dyn Renderer,
        inputs: &'a Inputs,
        config: &'a DiagnoseConfig,
    ) -> Refits<'a> {
        let target = FitTarget {
            image: inputs.target.clone(),
            levels: None,
            mask: inputs.mask.clone(),
            path: None,
            encoding: None,
        };
        Refits {
            renderer,
            inputs,
            config,
            target,
            jobs: config.jobs,
            renders: 0,
        }
    }

    pub fn renderer(&self) -> &'a dyn Renderer {
        self.renderer
    }

    /// The unchanged model refitted the two ways an effect will be (warm,
    /// with the budget of an effect's search and refit together; and from
    /// scratch), the best of the three kept.
    pub fn unchanged(&mut self, model: Model) -> Result<Model> {
        let c = self.config;
        let warm = Refine::close(c, c.search_generations + c.refine_generations);
        let null = self.run(&model.scene, None, warm)?;
        let mut model = model.better(null);
        // After the warm refit, not beside it: its result is one
        // individual of this start.
        if c.restart_generations > 0 {
            let again = self.run(&model.scene, None, Refine::restart(c))?;
            model = model.better(again);
        }
        Ok(model)
    }

    /// Refits `scene`: with a `search`, first those entries
    /// alone (the unchanged model one individual of their start, so it
    /// cannot end worse), then every parameter around the result.
    pub fn run(&mut self, scene: &Scene, search: Option<Search>, refine: Refine) -> Result<Model> {
        let mut current = scene.clone();
        if let Some(search) = search {
            let mut only = scene.clone();
            only.free = search.params;
            let budget = Refine {
                generations: self.config.search_generations,
                radius: search.radius,
                population: self.config.search_population,
                explore: false,
            };
            current = self.fit(&only, budget)?.0;
            current.free = scene.free.clone();
        }
        let (scene, image) = self.fit(&current, refine)?;
        Ok(Model::new(scene, image, self.inputs))
    }

    /// The one call into `crate::fit`: fits `scene`'s free parameters
    /// (the hybrid, ended once settled, its generations a cap; SHADE for a
    /// refit from scratch) and returns the fitted scene and its image.
    ///
    /// Why SHADE, and its whole budget, from scratch: on the generated
    /// light-falloff case (tests/diagnose.rs) the effect's refits reached
    /// a SAD drop of 99 % with SHADE's 250 generations from scratch, 47–49 %
    /// with the hybrid there (fixed budget, settled, or a first handover
    /// only once the population had its basin) and 30 % with SHADE ended
    /// after 30 generations without improvement: `camera_response` was
    /// then accepted in its place.
    fn fit(&mut self, scene: &Scene, refine: Refine) -> Result<(Scene, Image)> {
        let config = FitConfig {
            generations: refine.generations,
            start_radius: Some(refine.radius),
            de: DeConfig {
                population: refine.population,
                seed: self.config.seed,
                // Every refit starts from a good point: SHADE's
                // current-to-pbest exploits it, and the local phase does
                // the last digits in a few Jacobians where SHADE spent
                // most of a fixed budget (DE/rand/1 spent whole polishes
                // without improving on their start).
                strategy: if refine.explore {
                    crate::optimize::Strategy::Shade
                } else {
                    crate::optimize::Strategy::Hybrid
                },
                ..DeConfig::default()
            },
            jobs: self.jobs,
            snapshot_every: usize::MAX / 2,
            // A refit costs what it needs: it ends when the local phase
            // converges, so refits compared by the criterion each reach
            // their minimum rather than spend one fixed budget.
            settle: true,
            ..FitConfig::default()
        };
        let r = fit::run_in_memory(scene, &self.target, self.renderer, &config, &mut ())?;
        self.renders += r.result.evaluations;
        Ok((r.scene, r.image))
    }
}

impl super::backward::Models for Refits<'_> {
    type Model = Model;

    fn scene<'m>(&self, m: &'m Model) -> &'m Scene {
        &m.scene
    }

    fn score(&self, m: &Model) -> (f64, usize) {
        (m.sad, crate::scene::ParamSpace::from_scene(&m.scene).dim())
    }

    /// Each scene refitted as the unchanged model is, warm.
    fn refit_all(&mut self, scenes: Vec<Scene>, _from: &Model) -> Result<Vec<Model>> {
        let c = self.config;
        let warm = Refine::close(c, c.search_generations + c.refine_generations);
        super::lanes::side_by_side(self, &scenes, |f, s| f.run(s, None, warm))
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
            target: self.target.clone(),
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

impl Candidate {
    /// The candidate of an effect whose refit of `model` gave `fitted`
    /// with `added` more free values: its deviation and gain on one
    /// photograph; evidence and BIC change left for the round.
    pub(super) fn scored(
        effect: &str,
        round: usize,
        inputs: &Inputs,
        model: &Model,
        fitted: &Model,
        added: usize,
        refit: &str,
    ) -> Candidate {
        Candidate {
            effect: effect.to_string(),
            evidence: 0.0,
            deviation_after: Some(deviation(
                &inputs.target,
                &fitted.image,
                inputs.mask.as_ref(),
            )),
            round,
            delta_bic: None,
            overdispersion: None,
            gain: Some(1.0 - fitted.sad / model.sad.max(1e-9)),
            added_params: added,
            accepted: false,
            refit: refit.into(),
        }
    }
}
