//! The two-stage fit: the built-in Phong tracer fits
//! the scene over its full bounds (stage 1), then a physically based
//! renderer refines the fit in narrowed bounds around the stage-1 values
//! (stage 2). A Phong render costs microseconds and a Cycles render a tenth
//! of a second, so the cheap model does the global search and the
//! expensive one only the local correction its extra physics calls for.
//!
//! Writes into DIR:
//! - `stage1/`: a fit (as `scenefit fit`) with the stage-1 renderer;
//! - `stage2/input_scene.json`: the handover (see `handover.rs`);
//! - `stage2/`: stage 2 and `handover.png` (the stage-1 values as the
//!   stage-2 renderer draws them). Stage 2 runs by one of two methods:
//!   `mapped` (the default, `spacemap.rs`): output space mapping, the
//!   stage-1 renderer as a corrected surrogate of the stage-2 one, a few
//!   dozen stage-2 renders; `de`: a DE fit with the stage-2 renderer,
//!   seeded around the stage-1 values (`start_radius`) in narrowed bounds;
//! - `stageN/trace.tsv` (see `trace.rs`);
//! - `target.png` (and `mask.png`): what both stages were compared with;
//! - `comparison.json` (see `comparison.rs`).

pub mod comparison;
pub mod handover;
pub mod moves;
pub mod spacemap;
pub mod trace;

pub use comparison::{Comparison, Handover, StageSummary};
pub use spacemap::Iteration;

use crate::error::{Error, Result};
use crate::fit::{self, FitConfig, FitOutcome, FitResult, FitTarget, Observer};
use crate::metric::{deviation, Mask};
use crate::raster::Image;
use crate::render::{render_one, Renderer};
use crate::rundir::{
    Kind, Mode, RunDir, CHECKPOINT, COMPARISON, HANDOVER, INPUT_SCENE, MASK, STAGE1, STAGE2,
    STAGE2_DE, TARGET,
};
use crate::scene::Scene;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::time::Instant;

/// How the two stages run.
#[derive(Clone, Debug)]
pub struct PipelineConfig {
    pub stage1: FitConfig,
    pub stage2: FitConfig,
    /// Stage-2 bounds: the stage-1 value ± `window` × the original span.
    pub window: f64,
    /// Stage-2 start: a population within this radius (unit cube of the
    /// narrowed bounds) of the stage-1 values, which are individual 0.
    pub start_radius: f64,
    /// Stage 2 ignores stage 1: full bounds, uniform start (for measuring
    /// what the handover is worth).
    pub from_scratch: bool,
    /// Free parameters that keep their original bounds in stage 2 (still
    /// seeded at their stage-1 values).
    pub keep_bounds: Vec<String>,
    /// What to do with what is already in the pipeline's directory.
    pub mode: Mode,
    /// How stage 2 searches.
    pub method: Stage2Method,
    /// The mapped method's budgets.
    pub mapped: MappedBudget,
}

/// How stage 2 searches: by space mapping (a few stage-2 renders, the
/// stage-1 renderer as the corrected surrogate) or by DE with the stage-2
/// renderer alone.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Stage2Method {
    #[default]
    Mapped,
    De,
    /// Mapped as stage 2, and DE as well into stage2_de/, for comparing
    /// the two (the report draws both).
    Both,
}

impl std::fmt::Display for Stage2Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Stage2Method::Mapped => "mapped",
            Stage2Method::De => "de",
            Stage2Method::Both => "both",
        })
    }
}

/// The mapped stage 2's budgets.
#[derive(Clone, Debug)]
pub struct MappedBudget {
    /// Stage-2 renders at most (the handover render not counted).
    pub fine_renders: usize,
    /// Each iteration's surrogate fit with the stage-1 renderer.
    pub surrogate_population: usize,
    pub surrogate_generations: usize,
}

impl Default for MappedBudget {
    fn default() -> Self {
        MappedBudget {
            fine_renders: 30,
            surrogate_population: 16,
            surrogate_generations: 20,
        }
    }
}

impl Default for PipelineConfig {
    fn default() -> Self {
        let stage2 = FitConfig {
            generations: 30,
            de: crate::optimize::DeConfig {
                population: 24,
                ..Default::default()
            },
            ..FitConfig::default()
        };
        PipelineConfig {
            stage1: FitConfig::default(),
            stage2,
            window: 0.15,
            start_radius: 0.1,
            from_scratch: false,
            keep_bounds: Vec::new(),
            mode: Mode::Fresh,
            method: Stage2Method::default(),
            mapped: MappedBudget::default(),
        }
    }
}

/// Progress of a pipeline: each stage's start, then its generations.
pub trait StageObserver: Observer {
    fn stage(&mut self, _stage: u32, _renderer: &str, _dir: &Path) {}
    /// An iteration of the mapped stage 2.
    fn iteration(&mut self, _iteration: &Iteration) {}
}

impl StageObserver for () {}

/// Runs both stages of `scene` against `target`, writing into `dir`.
pub fn run(
    scene: &Scene,
    target: &FitTarget,
    stage1_renderer: &dyn Renderer,
    stage2_renderer: &dyn Renderer,
    config: &PipelineConfig,
    dir: &Path,
    observer: &mut dyn StageObserver,
) -> Result<Comparison> {
    check(scene, config)?;
    let run_dir = RunDir::open_as(dir, config.mode, Kind::Pipeline)?;
    let mask_file = write_inputs(&run_dir, target, config.mode)?;

    // Stage 1: the global search, with the stage's own config as given.
    let (r1, wall1, stage1_config) =
        run_stage1(scene, target, stage1_renderer, config, &run_dir, observer)?;

    // Handover.
    let stage2_dir = run_dir.sub(STAGE2)?;
    let fitted = &r1.scene;
    let (input, bounds, stage2_config) = stage2_input(scene, fitted, config, &stage2_dir)?;
    let at_handover = handover_render(stage2_renderer, fitted, target, &stage2_dir);

    // Stage 2: the local refinement with the physically based renderer.
    observer.stage(2, &stage2_renderer.name(), stage2_dir.path());
    let start = if config.from_scratch { scene } else { fitted };
    let renderers = (stage1_renderer, stage2_renderer);
    let handover_img = at_handover.as_ref().map(|(img, _)| img);
    let (r2, scene2, wall2) = match config.method {
        Stage2Method::De => {
            let stage = (&stage2_config, &stage2_dir);
            let (r2, wall2) =
                run_stage(&input, target, stage2_renderer, stage.0, stage.1, observer)?;
            (r2.result, r2.scene, wall2)
        }
        _ => run_mapped(
            start,
            target,
            renderers,
            config,
            handover_img,
            &stage2_dir,
            observer,
        )?,
    };
    // The DE stage 2 beside the mapped one, for comparison.
    let stage2_de = match config.method {
        Stage2Method::Both => Some(de_beside(
            &run_dir,
            &input,
            target,
            stage2_renderer,
            config,
            stage2_config.start_radius,
            observer,
        )?),
        _ => None,
    };
    let moves = moves::of(scene, start, &scene2);
    let r1 = r1.result;
    let stage2 = stage2_summary(&r2, wall2, &stage2_config, config);

    let comparison = Comparison {
        stage1: summary(&r1, wall1, &stage1_config, STAGE1),
        stage2,
        handover: handover_summary(
            config,
            stage2_config.start_radius,
            at_handover.map(|(_, d)| d),
            bounds,
        ),
        moves,
        stage2_de,
        target: TARGET.into(),
        mask: mask_file,
    };
    run_dir.write_json(COMPARISON, &comparison)?;
    Ok(comparison)
}

/// Stage 1 in its directory: its outcome, wall-clock seconds and config.
fn run_stage1(
    scene: &Scene,
    target: &FitTarget,
    renderer: &dyn Renderer,
    config: &PipelineConfig,
    run_dir: &RunDir,
    observer: &mut dyn StageObserver,
) -> Result<(FitOutcome, f64, FitConfig)> {
    let dir = run_dir.sub(STAGE1)?;
    observer.stage(1, &renderer.name(), dir.path());
    let stage1_config = stage_config(&config.stage1, config.mode, &dir);
    let (r1, wall1) = run_stage(scene, target, renderer, &stage1_config, &dir, observer)?;
    Ok((r1, wall1, stage1_config))
}

/// comparison.json's `handover`.
fn handover_summary(
    config: &PipelineConfig,
    start_radius: Option<f64>,
    deviation_at_handover: Option<crate::metric::Deviation>,
    bounds: Vec<handover::Narrowed>,
) -> Handover {
    Handover {
        seeded: !config.from_scratch,
        window: (!config.from_scratch).then_some(config.window),
        start_radius,
        deviation_at_handover,
        bounds,
    }
}

/// The mapped stage 2: its result, fitted scene and wall-clock seconds.
fn run_mapped(
    start: &Scene,
    target: &FitTarget,
    (coarse, fine): (&dyn Renderer, &dyn Renderer),
    config: &PipelineConfig,
    handover: Option<&Image>,
    dir: &RunDir,
    observer: &mut dyn StageObserver,
) -> Result<(FitResult, Scene, f64)> {
    let started = Instant::now();
    let m = spacemap::run(
        start,
        target,
        coarse,
        fine,
        &mapped_config(config),
        handover,
        dir,
        &mut |it| observer.iteration(it),
    )?;
    Ok((m.result, m.scene, started.elapsed().as_secs_f64()))
}

/// The DE stage 2 run into stage2_de/ beside the mapped one, seeded as
/// the DE method would be; its summary.
fn de_beside(
    run_dir: &RunDir,
    input: &Scene,
    target: &FitTarget,
    renderer: &dyn Renderer,
    config: &PipelineConfig,
    start_radius: Option<f64>,
    observer: &mut dyn StageObserver,
) -> Result<StageSummary> {
    let de_dir = run_dir.sub(STAGE2_DE)?;
    let mut de_config = stage_config(&config.stage2, config.mode, &de_dir);
    de_config.start_radius = start_radius;
    observer.stage(2, &renderer.name(), de_dir.path());
    let (r, wall) = run_stage(input, target, renderer, &de_config, &de_dir, observer)?;
    let mut s = summary(&r.result, wall, &de_config, STAGE2_DE);
    s.method = Some(Stage2Method::De.to_string());
    Ok(s)
}

/// The mapped stage 2's settings from the pipeline's: its first trust
/// region is the DE method's window, its surrogate fits start within the
/// same start radius, and it draws from stage 2's seed.
fn mapped_config(config: &PipelineConfig) -> spacemap::MappedConfig {
    spacemap::MappedConfig {
        fine_renders: config.mapped.fine_renders,
        radius: config.window,
        surrogate_population: config.mapped.surrogate_population,
        surrogate_generations: config.mapped.surrogate_generations,
        coarse_jobs: config.stage1.jobs,
        start_radius: config.start_radius,
        seed: config.stage2.de.seed,
        mode: config.mode,
        interrupt: config.stage2.interrupt.clone(),
    }
}

/// Refuses to overwrite the target with itself, clears the directory when
/// asked, and writes the target and mask (whose file name is returned).
fn write_inputs(run_dir: &RunDir, target: &FitTarget, mode: Mode) -> Result<Option<String>> {
    if let Some(p) = &target.path {
        run_dir.refuse_overwritten_input(p, "the target")?;
    }
    if mode == Mode::Overwrite {
        run_dir.clear()?;
    }
    run_dir.write_image(TARGET, &target.image)?;
    match &target.mask {
        Some(m) => {
            run_dir.write_image(MASK, &mask_image(m))?;
            Ok(Some(MASK.to_string()))
        }
        None => Ok(None),
    }
}

/// Stage 2's scene, narrowed bounds and config: seeded at the stage-1 fit
/// within a window, or the original scene when it starts from scratch.
fn stage2_input(
    scene: &Scene,
    fitted: &Scene,
    config: &PipelineConfig,
    stage2_dir: &RunDir,
) -> Result<(Scene, Vec<handover::Narrowed>, FitConfig)> {
    let mut stage2_config = stage_config(&config.stage2, config.mode, stage2_dir);
    let (input, bounds) = if config.from_scratch {
        stage2_config.start_radius = None;
        (scene.clone(), Vec::new())
    } else {
        stage2_config.start_radius = Some(config.start_radius);
        handover::narrow(fitted, config.window, &config.keep_bounds)?
    };
    stage2_dir.write_json(INPUT_SCENE, &input)?;
    Ok((input, bounds, stage2_config))
}

/// Checks the pipeline's own options against the scene.
fn check(scene: &Scene, config: &PipelineConfig) -> Result<()> {
    if !(config.start_radius >= 0.0 && config.start_radius.is_finite()) {
        return Err(Error::Usage(format!(
            "--stage2-start-radius: expected a radius >= 0 in the unit cube, got {}",
            config.start_radius
        )));
    }
    let window_ok = config.window > 0.0 && config.window.is_finite();
    let mapped = config.method != Stage2Method::De;
    if (!config.from_scratch || mapped) && !window_ok {
        return Err(Error::Usage(format!(
            "--stage2-window: expected a fraction of the span > 0, got {}",
            config.window
        )));
    }
    if mapped {
        let m = &config.mapped;
        let min = crate::optimize::MIN_POPULATION;
        if m.fine_renders < 2 {
            return Err(Error::Usage(format!(
                "--stage2-fine-renders: expected at least 2 (the first render and one trial), got {}",
                m.fine_renders
            )));
        }
        if m.surrogate_population < min {
            return Err(Error::Usage(format!(
                "--stage2-surrogate-population: expected at least {min}, got {}",
                m.surrogate_population
            )));
        }
        if m.surrogate_generations == 0 {
            return Err(Error::Usage(
                "--stage2-surrogate-generations: expected at least 1, got 0".into(),
            ));
        }
    }
    if let Some(k) = config
        .keep_bounds
        .iter()
        .find(|k| !scene.free.iter().any(|f| f.param == **k))
    {
        return Err(Error::Usage(format!(
            "--stage2-keep-bounds {k}: not a free parameter of the scene (free: {})",
            scene
                .free
                .iter()
                .map(|f| f.param.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    Ok(())
}

/// One stage: a fit with its trace recorded; returns the result and the
/// stage's wall-clock seconds (renderer start-up included).
fn run_stage(
    scene: &Scene,
    target: &FitTarget,
    renderer: &dyn Renderer,
    config: &FitConfig,
    dir: &RunDir,
    observer: &mut dyn StageObserver,
) -> Result<(FitOutcome, f64)> {
    let started = Instant::now();
    let mut recorder = trace::Recorder::new(dir, config.mode == Mode::Resume, observer)?;
    let outcome = fit::run_in(scene, target, renderer, config, Some(dir), &mut recorder)?;
    Ok((outcome, started.elapsed().as_secs_f64()))
}

/// A stage's config: a resumed pipeline resumes a stage that has a
/// checkpoint and starts one that has none (an overwriting pipeline has
/// removed its stages already).
fn stage_config(config: &FitConfig, mode: Mode, dir: &RunDir) -> FitConfig {
    let mut c = config.clone();
    c.mode = match mode {
        Mode::Resume if dir.file(CHECKPOINT).is_file() => Mode::Resume,
        _ => Mode::Fresh,
    };
    c
}

/// The stage-1 values rendered by the stage-2 renderer, written as
/// stage2/handover.png. A failure here costs only this figure: stage 2
/// reports its own render failures.
fn handover_render(
    renderer: &dyn Renderer,
    fitted: &Scene,
    target: &FitTarget,
    dir: &RunDir,
) -> Option<(Image, crate::metric::Deviation)> {
    let img = render_one(renderer, fitted, 0).ok()?;
    if img.dimensions() != target.image.dimensions() {
        return None;
    }
    dir.write_image(HANDOVER, &img).ok()?;
    let d = deviation(&target.image, &img, target.mask.as_ref());
    Some((img, d))
}

/// Stage 2's summary, with its method (the mapped one's population is
/// its surrogate fits').
fn stage2_summary(
    r: &FitResult,
    wall: f64,
    stage2_config: &FitConfig,
    config: &PipelineConfig,
) -> StageSummary {
    let mut s = summary(r, wall, stage2_config, STAGE2);
    let method = match config.method {
        Stage2Method::De => Stage2Method::De,
        _ => Stage2Method::Mapped,
    };
    s.method = Some(method.to_string());
    if method == Stage2Method::Mapped {
        s.population = config.mapped.surrogate_population;
    }
    s
}

fn summary(r: &FitResult, wall: f64, config: &FitConfig, dir: &str) -> StageSummary {
    StageSummary {
        renderer: r.renderer.clone(),
        deviation: r.deviation,
        evaluations: r.evaluations,
        wall_seconds: wall,
        fit_seconds: r.wall_seconds,
        generations: r.generations,
        population: config.de.population,
        strategy: r.strategy.clone(),
        seed: r.seed,
        stop_reason: r.stop_reason.clone(),
        dir: dir.into(),
        method: None,
    }
}

/// A mask as an image: white where pixels count.
fn mask_image(m: &Mask) -> Image {
    let (w, h) = m.size();
    let mut img = Image::new(w, h);
    for &p in m.pixels() {
        img.put_pixel(p % w.max(1), p / w.max(1), image::Rgb([255, 255, 255]));
    }
    img
}
