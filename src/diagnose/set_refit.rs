//! The refits of a set diagnosis: a model of the whole set (`SetModel`),
//! each photograph as a shot of a shared scene, and `SetRefits`, which runs
//! set fits of extended scenes and counts their renders.

use super::effects;
use super::inputs::{Params, SetInputs};
use super::residual::Residual;
use super::selection::sad;
use super::DiagnoseConfig;
use crate::error::{Error, Result};
use crate::fit::set::shots::Shot;
use crate::fit::set::{self as setfit, SetConfig};
use crate::fit::FitConfig;
use crate::metric::{deviation, Deviation};
use crate::optimize::{DeConfig, Strategy};
use crate::raster::Image;
use crate::render::Renderer;
use crate::scene::load::with_overrides;
use crate::scene::{Override, ParamSpace, Scene};
use std::path::Path;

/// Shared blocks of an accepted model's refit from scratch (`fit --shots`'s
/// default).
const SCRATCH_ROUNDS: usize = 4;

/// A model of the whole set: the shared scene, each photograph's own
/// values, its renders, and the sum of absolute differences over all.
#[derive(Clone)]
pub struct SetModel {
    pub scene: Scene,
    pub own: Vec<Params>,
    pub images: Vec<Image>,
    pub sad: f64,
}

impl SetModel {
    pub(super) fn better(self, other: SetModel) -> SetModel {
        if other.sad < self.sad {
            other
        } else {
            self
        }
    }

    /// Free coordinates: the shared ones and every photograph's own.
    pub(super) fn dim(&self, inputs: &SetInputs) -> usize {
        let space = ParamSpace::from_scene(&self.scene);
        space.shared().dim()
            + inputs
                .shots
                .iter()
                .map(|s| s.own_space(&space).dim())
                .sum::<usize>()
    }

    pub(super) fn deviations(&self, inputs: &SetInputs) -> Vec<Deviation> {
        self.images
            .iter()
            .zip(&inputs.shots)
            .map(|(img, s)| deviation(&s.target.image, img, s.target.mask.as_ref()))
            .collect()
    }

    pub(super) fn residuals(&self, inputs: &SetInputs) -> Vec<Residual> {
        self.images
            .iter()
            .zip(&inputs.shots)
            .map(|(img, s)| Residual::new(&s.target.image, img, s.target.mask.as_ref()))
            .collect()
    }
}

/// Each photograph as a shot of `scene`: its `set` values and then its
/// own values `own` in place.
pub(super) fn shots_of(scene: &Scene, inputs: &SetInputs, own: &[Params]) -> Result<Vec<Shot>> {
    inputs
        .shots
        .iter()
        .zip(own)
        .map(|(s, own)| {
            let overrides: Vec<Override> = s
                .entry
                .set
                .iter()
                .chain(own.iter())
                .map(|(k, v)| Override {
                    path: k.clone(),
                    value: v.clone(),
                })
                .collect();
            let scene = with_overrides(scene, &overrides, "(diagnosis)", &s.name)?;
            Ok(Shot { scene, ..s.clone() })
        })
        .collect()
}

/// Runs the refits of a set diagnosis and counts their renders.
pub(super) struct SetRefits<'a> {
    pub(super) renderer: &'a dyn Renderer,
    pub(super) inputs: &'a SetInputs,
    pub(super) config: &'a DiagnoseConfig,
    /// Renders at once (its lane's share, `lanes.rs`).
    pub(super) jobs: usize,
    pub(super) renders: usize,
    /// The diagnosis's directory (closed-form effects write their maps there).
    pub(super) out: &'a Path,
}

impl super::backward::Models for SetRefits<'_> {
    type Model = SetModel;

    fn scene<'m>(&self, m: &'m SetModel) -> &'m Scene {
        &m.scene
    }

    fn score(&self, m: &SetModel) -> (f64, usize) {
        (m.sad, m.dim(self.inputs))
    }

    /// Each scene refitted over the set, warm, every photograph's own
    /// values those of `from` that the scene still frees.
    fn refit_all(&mut self, scenes: Vec<Scene>, from: &SetModel) -> Result<Vec<SetModel>> {
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
            f.run(s, &own)
        })
        .into_iter()
        .collect()
    }
}

impl super::lanes::Lanes for SetRefits<'_> {
    fn jobs(&self) -> usize {
        self.jobs
    }

    fn lanes(&self) -> usize {
        super::lanes::lanes_for(self.config, self.jobs)
    }

    fn lane(&self, jobs: usize) -> Self {
        SetRefits {
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

impl SetRefits<'_> {
    /// Renders every photograph's scene in `shots`: the images and the
    /// set's sum of absolute differences (None: a render failed).
    pub(super) fn render(&mut self, shots: &[Shot]) -> Result<Option<(Vec<Image>, f64)>> {
        let scored = score(self.renderer, shots, self.jobs)?;
        self.renders += shots.len();
        Ok(scored
            .into_iter()
            .collect::<std::result::Result<Vec<_>, _>>()
            .ok()
            .map(|v| {
                let sad = v.iter().map(|x| x.1).sum();
                (v.into_iter().map(|x| x.0).collect(), sad)
            }))
    }

    /// The best of an extension's starts on the set (the extended scene
    /// included): each start's shared values with every photograph's own
    /// values, and again with its level matched to the photographs': the
    /// shared free intensities scaled by the set's pooled ratio, and each
    /// photograph's own free intensities by its own ratio (a new gamma
    /// changes each photograph's level by its own amount). The start's
    /// scene and own values.
    pub(super) fn best_start(
        &mut self,
        ext: &effects::Extension,
        own: &[Params],
    ) -> Result<(Scene, Vec<Params>)> {
        if ext.starts.is_empty() {
            return Ok((ext.scene.clone(), own.to_vec()));
        }
        let inputs = self.inputs;
        let levels = |images: &[&Image], scale| -> Vec<(f64, f64)> {
            images
                .iter()
                .zip(&inputs.shots)
                .map(|(img, s)| {
                    let w = crate::fit::set::counted(&s.target) as f64;
                    (w, super::starts::level(img, s.target.mask.as_ref(), scale))
                })
                .collect()
        };
        let pooled = |l: &[(f64, f64)]| {
            let n: f64 = l.iter().map(|x| x.0).sum();
            l.iter().map(|x| x.0 * x.1).sum::<f64>() / n.max(1.0)
        };
        let targets: Vec<&Image> = inputs.shots.iter().map(|s| &s.target.image).collect();
        let mut best = (f64::INFINITY, ext.scene.clone(), own.to_vec());
        for start in std::iter::once(&ext.scene).chain(&ext.starts) {
            let scale = super::starts::Scale::of(start);
            let want = levels(&targets, scale);
            let shots = shots_of(start, inputs, own)?;
            let Some((images, d)) = self.render(&shots)? else {
                continue;
            };
            if d < best.0 {
                best = (d, start.clone(), own.to_vec());
            }
            let have = levels(&images.iter().collect::<Vec<_>>(), scale);
            if pooled(&have) <= 0.0 {
                continue;
            }
            let k_shared = pooled(&want) / pooled(&have);
            let shared = effects::edit::match_level_where(start, k_shared, |f| !f.per_shot);
            let space = ParamSpace::from_scene(start);
            // Each shot's scene already holds the start with its own values:
            // the same two scalings applied there, no rebuild needed.
            let matched: Vec<Shot> = shots
                .iter()
                .zip(want.iter().zip(&have))
                .map(|(s, (w, h))| {
                    let k = if h.1 > 0.0 { w.1 / h.1 } else { 1.0 };
                    let scene =
                        effects::edit::match_level_where(&s.scene, k_shared, |f| !f.per_shot);
                    let scene = effects::edit::match_level_where(&scene, k, |f| {
                        f.per_shot && !s.entry.set.contains_key(&f.param)
                    });
                    Shot { scene, ..s.clone() }
                })
                .collect();
            if let Some((_, d)) = self.render(&matched)? {
                if d < best.0 {
                    let own_now = matched
                        .iter()
                        .map(|s| s.own_space(&space).json_values(&s.scene))
                        .collect();
                    best = (d, shared, own_now);
                }
            }
        }
        Ok((best.1, best.2))
    }

    /// `scene` (with `own` values) refitted over the set.
    pub(super) fn run(&mut self, scene: &Scene, own: &[Params]) -> Result<SetModel> {
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
    pub(super) fn scratch(&mut self, scene: &Scene, own: &[Params]) -> Result<SetModel> {
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
        self.fit(scene, &shots, &config)
    }

    /// [`SetRefits::run`] with the shared parameters `spread` names spread
    /// over their radius in the first shared block (an effect's own).
    pub(super) fn run_spread(
        &mut self,
        scene: &Scene,
        own: &[Params],
        spread: Vec<(String, f64)>,
    ) -> Result<SetModel> {
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
        self.fit(scene, &shots, &config)
    }

    /// One set fit of `scene` over `shots` with `config`, as a model.
    fn fit(&mut self, scene: &Scene, shots: &[Shot], config: &SetConfig) -> Result<SetModel> {
        let out = setfit::run_in(scene, shots, self.renderer, config, None, &mut ())?;
        self.renders += out.result.evaluations + shots.len();
        let mut sum = 0.0;
        for (o, s) in out.shots.iter().zip(&self.inputs.shots) {
            sum += sad(&s.target.image, &o.image, s.target.mask.as_ref());
        }
        Ok(SetModel {
            scene: out.scene,
            own: out.shots.iter().map(|o| o.result.params.clone()).collect(),
            images: out.shots.into_iter().map(|o| o.image).collect(),
            sad: sum,
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
    let images = setfit::renders::render_shots(renderer, &scenes, shots, &space, jobs, 0)?;
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

/// The renders of the fitted model `scene` as it stands.
pub(super) fn initial(
    renderer: &dyn Renderer,
    inputs: &SetInputs,
    scene: Scene,
    jobs: usize,
) -> Result<SetModel> {
    let shots = shots_of(&scene, inputs, &inputs.own)?;
    let mut images = Vec::with_capacity(shots.len());
    let mut total = 0.0;
    for (r, s) in score(renderer, &shots, jobs)?.into_iter().zip(&shots) {
        let (img, d) = r.map_err(|why| {
            Error::Run(format!(
                "{}: the render of shot {} {why}",
                renderer.name(),
                s.name
            ))
        })?;
        total += d;
        images.push(img);
    }
    Ok(SetModel {
        scene,
        own: inputs.own.clone(),
        images,
        sad: total,
    })
}
