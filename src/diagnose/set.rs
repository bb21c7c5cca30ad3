//! `diagnose` of a set fit (`fit --shots`): the same rounds as for one
//! photograph, with the evidence pooled over every photograph (each one's
//! R² weighted by its pixels) and every refit a set fit (the shared
//! parameters over all photographs, each photograph's own after them), so
//! that an effect is accepted on the set: an effect shared by every
//! photograph is weak evidence in one and strong across twenty.
//!
//! A candidate's refit here is warm: it starts from the best of the
//! effect's starts over the set (each also with its level matched, every
//! free light intensity scaled, per-shot ones included) and every block of
//! the set fit searches around the current values. The accepted candidate
//! is then refitted from scratch too (every shared value from the centre
//! of its box), and the better of the two kept: a warm refit keeps what
//! the model had bent to absorb the effect it lacked.

use super::effects::{self, Effect};
use super::residual::Residual;
use super::selection::{choose, overdispersion, sad, samples, weigh};
use super::{Candidate, DiagnoseConfig, Diagnosis, UNEXPLAINED};
use crate::error::{Error, Result};
use crate::fit::set::shots::Shot;
use crate::fit::set::{self as setfit, SetConfig};
use crate::fit::{FitConfig, FitResult};
use crate::metric::{deviation, Deviation};
use crate::optimize::{DeConfig, Strategy};
use crate::raster::Image;
use crate::render::{from_spec_with, Renderer};
use crate::rundir::{RunDir, FITTED_SCENE, SHOTS};
use crate::scene::load::with_overrides;
use crate::scene::{Override, ParamSpace, Scene};
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

pub(super) type Params = serde_json::Map<String, serde_json::Value>;

/// Shared blocks of an accepted model's refit from scratch (`fit --shots`'s
/// default).
const SCRATCH_ROUNDS: usize = 4;

/// A set fit's outputs, as a diagnosis starts from them.
pub struct SetInputs {
    /// The shared model.
    pub scene: Scene,
    pub shots: Vec<Shot>,
    /// Each photograph's own fitted values.
    pub own: Vec<Params>,
}

impl SetInputs {
    /// The set fit in `dir`, or None when `dir` holds a fit of one photograph.
    pub fn from_fit_dir(dir: &Path) -> Result<Option<SetInputs>> {
        if !dir.join(crate::rundir::RESULT).is_file() {
            return Ok(None); // the one-photograph path says what is missing
        }
        let run = RunDir::existing(dir)?;
        let result = FitResult::load(&run)?;
        let Some(results) = result.shots else {
            return Ok(None);
        };
        let scene = crate::scene::load(&dir.join(FITTED_SCENE))?;
        let (shots, _) = crate::fit::set::shots::load(&dir.join(SHOTS), &scene)?;
        let own = shots
            .iter()
            .map(|s| {
                results
                    .iter()
                    .find(|r| r.name == s.name)
                    .map(|r| r.params.clone())
                    .ok_or_else(|| {
                        Error::invalid(
                            run.file(crate::rundir::RESULT).display().to_string(),
                            "shots",
                            format!("expected a result for shot {}", s.name),
                        )
                    })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Some(SetInputs { scene, shots, own }))
    }
}

/// One photograph after the diagnosis (diagnosis.json's `shots_after`).
#[derive(Clone, Debug, Serialize)]
pub struct ShotAfter {
    pub name: String,
    pub params: Params,
    pub deviation_before: Deviation,
    pub deviation_after: Deviation,
}

/// diagnosis.json of a set.
#[derive(Clone, Debug, Serialize)]
pub struct SetDiagnosis {
    #[serde(flatten)]
    pub diagnosis: Diagnosis,
    pub shots_after: Vec<ShotAfter>,
}

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
    fn better(self, other: SetModel) -> SetModel {
        if other.sad < self.sad {
            other
        } else {
            self
        }
    }

    /// Free coordinates: the shared ones and every photograph's own.
    fn dim(&self, inputs: &SetInputs) -> usize {
        let space = ParamSpace::from_scene(&self.scene);
        space.shared().dim()
            + inputs
                .shots
                .iter()
                .map(|s| s.own_space(&space).dim())
                .sum::<usize>()
    }

    fn deviations(&self, inputs: &SetInputs) -> Vec<Deviation> {
        self.images
            .iter()
            .zip(&inputs.shots)
            .map(|(img, s)| deviation(&s.target.image, img, s.target.mask.as_ref()))
            .collect()
    }

    fn residuals(&self, inputs: &SetInputs) -> Vec<Residual> {
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
    renderer: &'a dyn Renderer,
    pub(super) inputs: &'a SetInputs,
    config: &'a DiagnoseConfig,
    /// Renders at once (its lane's share, `lanes.rs`).
    jobs: usize,
    renders: usize,
    /// The diagnosis's directory (closed-form effects write their maps there).
    pub(super) out: &'a Path,
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
    fn best_start(
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
    /// camera's response), and its basin with it.
    fn scratch(&mut self, scene: &Scene, own: &[Params]) -> Result<SetModel> {
        let shared = ParamSpace::from_scene(scene).shared();
        let scene = &shared.scene_at(scene, &vec![0.5; shared.dim()]);
        let shots = shots_of(scene, self.inputs, own)?;
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
    fn run_spread(
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
fn initial(
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

/// Pooled evidence: each photograph's R² weighted by its pixels.
fn evidence(residuals: &[Residual], effect: &dyn Effect) -> f64 {
    let total: usize = residuals.iter().map(|r| r.pixels.len()).sum();
    residuals
        .iter()
        .map(|r| r.evidence(effect) * r.pixels.len() as f64)
        .sum::<f64>()
        / total.max(1) as f64
}

/// Runs the diagnosis of a set, writing its files into `out`.
pub fn run(inputs: &SetInputs, out: &Path, config: &DiagnoseConfig) -> Result<SetDiagnosis> {
    let started = Instant::now();
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    let renderer = from_spec_with(&config.renderer, &config.render_options)?;
    let (scene, held) = super::held::split(&inputs.scene, config.refit_geometry);
    let model0 = initial(renderer.as_ref(), inputs, scene, config.jobs)?;
    let before = model0.deviations(inputs);
    let residuals_before = model0.residuals(inputs);
    let mut fits = SetRefits {
        renderer: renderer.as_ref(),
        inputs,
        config,
        jobs: config.jobs,
        renders: inputs.shots.len(),
        out,
    };
    let null = fits.run(&model0.scene, &model0.own)?;
    let mut model = model0.clone().better(null);
    let refined = pooled(&model.deviations(inputs), inputs);
    let n: f64 = inputs
        .shots
        .iter()
        .map(|s| samples(&s.target.image, s.target.mask.as_ref()))
        .sum();
    let (candidates, mut accepted) = rounds(&mut fits, &mut model, n)?;
    if !accepted.is_empty() {
        // The last refit stopped where block descent slows: along a valley
        // where shared and per-shot values trade. A warm refit from there
        // goes on down it.
        let polished = fits.run(&model.scene, &model.own)?;
        model = model.better(polished);
    }
    let residuals_after = model.residuals(inputs);
    let structured = residuals_after.iter().filter(|r| r.structured()).count();
    let unexplained = 2 * structured > residuals_after.len();
    if unexplained {
        accepted.push(UNEXPLAINED.into());
    }
    let after = model.deviations(inputs);
    model.scene = super::held::restore(&model.scene, &held);
    let space = ParamSpace::from_scene(&model.scene);
    let diagnosis = Diagnosis {
        deviation_before: pooled(&before, inputs),
        deviation_after: pooled(&after, inputs),
        candidates,
        accepted,
        params_after: space.shared().json_values(&model.scene),
        deviation_refined: refined,
        unexplained,
        renders: fits.renders,
        wall_seconds: started.elapsed().as_secs_f64(),
        held: super::held::paths(&held),
    };
    let d = SetDiagnosis {
        diagnosis,
        shots_after: shots_after(inputs, &model, &before, &after),
    };
    super::albedo::prune(out, &model.scene);
    super::report::write_set(
        out,
        &d,
        &model,
        inputs,
        (&residuals_before, &residuals_after),
    )?;
    Ok(d)
}

/// Every photograph's own values after, and its deviations.
fn shots_after(
    inputs: &SetInputs,
    model: &SetModel,
    before: &[Deviation],
    after: &[Deviation],
) -> Vec<ShotAfter> {
    inputs
        .shots
        .iter()
        .enumerate()
        .map(|(i, s)| ShotAfter {
            name: s.name.clone(),
            params: model.own[i].clone(),
            deviation_before: before[i],
            deviation_after: after[i],
        })
        .collect()
}

/// The rounds: every effect not yet accepted tried on the set, the
/// criterion choosing; `model` becomes the accepted one. The candidates
/// of every round and the effects accepted.
fn rounds(
    fits: &mut SetRefits,
    model: &mut SetModel,
    n: f64,
) -> Result<(Vec<Candidate>, Vec<String>)> {
    let inputs = fits.inputs;
    let mut candidates = Vec::new();
    let mut accepted: Vec<String> = Vec::new();
    for round in 1..=fits.config.max_rounds {
        let residuals = model.residuals(inputs);
        let k0 = model.dim(inputs);
        let open: Vec<&dyn Effect> = effects::ALL
            .iter()
            .copied()
            .filter(|e| !accepted.iter().any(|a| a == e.name()))
            .collect();
        // The searched effects' refits side by side (`lanes.rs`).
        let searched: Vec<&dyn Effect> =
            open.iter().copied().filter(|e| !e.closed_form()).collect();
        let best = refit_effects(fits, model, &searched)?;
        let mut refitted = best.into_iter();
        let mut tried: Vec<(Candidate, SetModel)> = Vec::new();
        for effect in open {
            let (fitted, k) = if effect.closed_form() {
                let solved = match effect.applies(&model.scene) {
                    true => super::albedo::set_model(fits, model, round)?,
                    false => None,
                };
                let Some((fitted, values)) = solved else {
                    continue;
                };
                let k = fitted.dim(inputs) + values;
                (fitted, k)
            } else {
                let Some(fitted) = refitted.next().expect("one result per searched effect") else {
                    continue;
                };
                let k = fitted.dim(inputs);
                (fitted, k)
            };
            let candidate = Candidate {
                effect: effect.name().to_string(),
                evidence: evidence(&residuals, effect),
                deviation_after: Some(pooled(&fitted.deviations(inputs), inputs)),
                round,
                delta_bic: None,
                overdispersion: None,
                gain: Some(1.0 - fitted.sad / model.sad.max(1e-9)),
                added_params: k.saturating_sub(k0),
                accepted: false,
                refit: "warm (set)".into(),
            };
            tried.push((candidate, fitted));
        }
        tried.sort_by(|a, b| b.0.evidence.total_cmp(&a.0.evidence));
        let (mut found, models): (Vec<Candidate>, Vec<SetModel>) = tried.into_iter().unzip();
        weigh_round(&mut found, &models, model.sad, n, inputs);
        let chosen = choose(&found, fits.config);
        if let Some(i) = chosen {
            found[i].accepted = true;
            accepted.push(found[i].effect.clone());
            let warm = models.into_iter().nth(i).expect("chosen from these");
            let scratch = fits.scratch(&warm.scene, &warm.own)?;
            if scratch.sad < warm.sad {
                found[i].refit = "warm (set), then from scratch (set)".into();
                found[i].deviation_after = Some(pooled(&scratch.deviations(inputs), inputs));
                *model = scratch;
            } else {
                *model = warm;
            }
        }
        candidates.extend(found);
        if chosen.is_none() {
            break;
        }
    }
    Ok((candidates, accepted))
}

/// The round's criterion changes from a model with SAD `sad0`, the
/// overdispersion measured over every photograph.
fn weigh_round(
    found: &mut [Candidate],
    models: &[SetModel],
    sad0: f64,
    n: f64,
    inputs: &SetInputs,
) {
    let sads: Vec<f64> = models.iter().map(|m| m.sad).collect();
    weigh(found, &sads, sad0, n, |i| {
        let pairs = models[i].images.iter().zip(&inputs.shots);
        overdispersion(pairs.map(|(img, s)| (&s.target.image, img, s.target.mask.as_ref())))
    });
}

/// Every form of every effect in `searched` added to `model` and refitted
/// over the set, side by side (`lanes.rs`); each effect's best form (None:
/// it does not apply).
fn refit_effects(
    fits: &mut SetRefits,
    model: &SetModel,
    searched: &[&dyn Effect],
) -> Result<Vec<Option<SetModel>>> {
    let forms: Vec<(usize, effects::Extension)> = searched
        .iter()
        .enumerate()
        .flat_map(|(i, &e)| {
            effects::forms(e, &model.scene)
                .into_iter()
                .map(move |x| (i, x))
        })
        .collect();
    let done = super::lanes::side_by_side(fits, &forms, |f, (i, ext)| {
        let (start, own) = f.best_start(ext, &model.own)?;
        // The effect's own parameters spread as its refit for one
        // photograph spreads them: they hold a neutral guess, not a fit.
        let radius = searched[*i].trades().radius;
        let spread = ext
            .added
            .iter()
            .map(|a| (a.param.clone(), radius))
            .collect();
        f.run_spread(&start, &own, spread)
    });
    let mut best: Vec<Option<SetModel>> = searched.iter().map(|_| None).collect();
    for ((i, _), fitted) in forms.iter().zip(done) {
        let fitted = fitted?;
        best[*i] = Some(match best[*i].take() {
            Some(b) => b.better(fitted),
            None => fitted,
        });
    }
    Ok(best)
}

/// The deviation over every photograph.
fn pooled(devs: &[Deviation], inputs: &SetInputs) -> Deviation {
    let parts: Vec<(Deviation, usize)> = devs
        .iter()
        .zip(&inputs.shots)
        .map(|(d, s)| (*d, crate::fit::set::counted(&s.target)))
        .collect();
    Deviation::pooled(&parts)
}
