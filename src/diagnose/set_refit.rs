//! The refits of a set's diagnosis (`Schedule::Set`): set fits
//! (`crate::fit::set`) of the shared parameters over every photograph,
//! each photograph's own values after them, warm around the current
//! values or, for an accepted model, from scratch.

use super::inputs::Params;
use super::model::{shots_of, Model};
use super::refits::Refits;
use super::selection::sad;
use crate::error::Result;
use crate::fit::set::shots::Shot;
use crate::fit::set::{self as setfit, SetConfig};
use crate::fit::FitConfig;
use crate::optimize::{DeConfig, Strategy};
use crate::scene::{ParamSpace, Scene};

/// Shared blocks of an accepted model's refit from scratch (`fit --shots`'s
/// default).
const SCRATCH_ROUNDS: usize = 4;

impl Refits<'_> {
    /// `scene` (with `own` values) refitted over the set.
    pub(super) fn run_set(&mut self, scene: &Scene, own: &[Params]) -> Result<Model> {
        self.run_spread(scene, own, Vec::new())
    }

    /// `scene` refitted over the set from scratch, as `fit --shots` fits
    /// it (the first blocks over the whole box, the fit's own budgets),
    /// but no shared value of `scene` kept, not even as one member of the
    /// first population: each starts at the centre of its box. Why: a warm
    /// refit keeps what the model had bent to absorb the effect it lacked
    /// (on the DiLiGenT set a broad specular lobe standing in for the
    /// camera's response), and its basin with it. A box centred on zero
    /// puts a direction's centre at the zero vector, which is no direction
    /// (a second directional light's): then the start is `scene` as it is,
    /// one member of a first population still spread over the whole box.
    pub(super) fn scratch(&mut self, scene: &Scene, own: &[Params]) -> Result<Model> {
        let shared = ParamSpace::from_scene(scene).shared();
        let centre = shared.scene_at(scene, &vec![0.5; shared.dim()]);
        let (scene, shots) = match shots_of(&centre, self.inputs, own) {
            Ok(shots) => (&centre, shots),
            Err(_) => (scene, shots_of(scene, self.inputs, own)?),
        };
        let config = SetConfig {
            fit: FitConfig {
                de: DeConfig {
                    seed: self.config.seed,
                    strategy: Strategy::Hybrid,
                    ..DeConfig::default()
                },
                jobs: self.jobs,
                snapshot_every: usize::MAX / 2,
                ..FitConfig::default()
            },
            rounds: SCRATCH_ROUNDS,
            warm: false,
            joint: true,
            spread: Vec::new(),
        };
        self.fit_set(scene, &shots, &config)
    }

    /// [`Refits::run_set`] with the shared parameters `spread` names spread
    /// over their radius in the first shared block (an effect's own).
    pub(super) fn run_spread(
        &mut self,
        scene: &Scene,
        own: &[Params],
        spread: Vec<(String, f64)>,
    ) -> Result<Model> {
        let shots = shots_of(scene, self.inputs, own)?;
        let c = self.config;
        let config = SetConfig {
            fit: FitConfig {
                generations: c
                    .restart_generations
                    .max(c.search_generations + c.refine_generations),
                de: DeConfig {
                    population: c.restart_population,
                    seed: c.seed,
                    strategy: Strategy::Hybrid,
                    ..DeConfig::default()
                },
                jobs: self.jobs,
                snapshot_every: usize::MAX / 2,
                ..FitConfig::default()
            },
            rounds: 2,
            warm: true,
            // The joint step moves an effect's shared parameters and every
            // photograph's own together: block by block, a second light's
            // position and each key light trade only a block at a time
            // (tests/shots_diagnose: second_light 0.51 of the deviation
            // before without it, 0.003 with it).
            joint: true,
            spread,
        };
        self.fit_set(scene, &shots, &config)
    }

    /// One set fit of `scene` over `shots` with `config`, as a model.
    fn fit_set(&mut self, scene: &Scene, shots: &[Shot], config: &SetConfig) -> Result<Model> {
        let out = setfit::run_in(scene, shots, self.renderer, config, None, &mut ())?;
        self.renders += out.result.evaluations + shots.len();
        let mut sum = 0.0;
        for (o, s) in out.shots.iter().zip(&self.inputs.shots) {
            sum += sad(&s.target.image, &o.image, s.target.mask.as_ref());
        }
        Ok(Model {
            scene: out.scene,
            own: out.shots.iter().map(|o| o.result.params.clone()).collect(),
            images: out.shots.into_iter().map(|o| o.image).collect(),
            sad: sum,
        })
    }
}
