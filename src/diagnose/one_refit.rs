//! The refits of one photograph's diagnosis (`Schedule::One`): each a fit
//! in memory of every free parameter (`crate::fit::run_in_memory`, which
//! writes no files: a refit is never resumed, and its checkpoints would
//! cost more than its renders), optionally after a search of an effect's
//! own parameters; with the budgets of `Refine`.

use super::inputs::Params;
use super::model::Model;
use super::refits::Refits;
use super::selection::sad;
use super::DiagnoseConfig;
use crate::error::Result;
use crate::fit::{self, FitConfig};
use crate::optimize::DeConfig;
use crate::raster::Image;
use crate::scene::{FreeParam, Scene};

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

    /// The warm refit of a model as the unchanged one is refitted: with
    /// the budget of an effect's search and refit together.
    pub fn warm(config: &DiagnoseConfig) -> Refine {
        Refine::close(
            config,
            config.search_generations + config.refine_generations,
        )
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

impl Refits<'_> {
    /// Refits `scene` on the one photograph: with a `search`, first those
    /// entries alone (the unchanged model one individual of their start,
    /// so it cannot end worse), then every parameter around the result.
    pub(super) fn run_one(
        &mut self,
        scene: &Scene,
        search: Option<Search>,
        refine: Refine,
    ) -> Result<Model> {
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
            current = self.fit_one(&only, budget)?.0;
            current.free = scene.free.clone();
        }
        let (scene, image) = self.fit_one(&current, refine)?;
        let target = &self.inputs.shots[0].target;
        let sad = sad(&target.image, &image, target.mask.as_ref());
        Ok(Model {
            scene,
            own: vec![Params::new()],
            images: vec![image],
            sad,
        })
    }

    /// The unchanged model refitted the two ways an effect will be (warm,
    /// with the budget of an effect's search and refit together; and from
    /// scratch), the best of the three kept.
    pub(super) fn unchanged_one(&mut self, model: Model) -> Result<Model> {
        let c = self.config;
        let null = self.run_one(&model.scene, None, Refine::warm(c))?;
        let mut model = model.better(null);
        // After the warm refit, not beside it: its result is one
        // individual of this start.
        if c.restart_generations > 0 {
            let again = self.run_one(&model.scene, None, Refine::restart(c))?;
            model = model.better(again);
        }
        Ok(model)
    }

    /// The one call into `crate::fit` for one photograph: fits `scene`'s
    /// free parameters (the hybrid, ended once settled, its generations a
    /// cap; SHADE for a refit from scratch) and returns the fitted scene
    /// and its image.
    ///
    /// Why SHADE, and its whole budget, from scratch: on the generated
    /// light-falloff case (tests/diagnose.rs) the effect's refits reached
    /// a SAD drop of 99 % with SHADE's 250 generations from scratch, 47–49 %
    /// with the hybrid there (fixed budget, settled, or a first handover
    /// only once the population had its basin) and 30 % with SHADE ended
    /// after 30 generations without improvement: `camera_response` was
    /// then accepted in its place.
    fn fit_one(&mut self, scene: &Scene, refine: Refine) -> Result<(Scene, Image)> {
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
        let target = &self.inputs.shots[0].target;
        let r = fit::run_in_memory(scene, target, self.renderer, &config, &mut ())?;
        self.renders += r.result.evaluations;
        Ok((r.scene, r.image))
    }
}
