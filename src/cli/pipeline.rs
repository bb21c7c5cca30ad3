//! `scenefit pipeline SCENE --target IMG -o DIR [--stage2 blender|mitsuba|povray] [--mask M]`
//! with each stage's search options (`--stage1-population`, …,
//! `--stage2-generations`, …), the handover's `--stage2-window` and
//! `--stage2-start-radius`, `--stage2-from-scratch`, and stage 2's method
//! (`--stage2-method mapped|de`) with the mapped method's budgets. Writes
//! the report at the end.

use super::fit::interrupt_flag;
use super::progress::Progress;
use super::search::{Search, Stage1, Stage2};
use crate::error::{Error, Result};
use crate::fit::{FitConfig, GenerationReport, Observer};
use crate::pipeline::{self, Iteration, MappedBudget, PipelineConfig, Stage2Method, StageObserver};
use crate::render::{from_spec_with, RenderOptions, Renderer};
use crate::report::{self, ReportOptions};
use crate::scene::memory::Population;
use crate::scene::{load_with, Override, Scene};
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct PipelineArgs {
    #[command(flatten)]
    inputs: super::fit::FitInputs,
    /// The run directory (stage1/, stage2/, comparison.json, report.html).
    #[arg(short, long)]
    output: PathBuf,
    /// Stage-1 renderer: the fast model that searches the full bounds.
    #[arg(long, default_value = "phong")]
    stage1: String,
    /// Stage-2 renderer: blender, mitsuba, povray (or cmd:/worker:).
    #[arg(long, default_value = "blender")]
    stage2: String,
    #[command(flatten)]
    s1: Search<Stage1>,
    #[command(flatten)]
    s2: Search<Stage2>,
    #[command(flatten)]
    render_options: super::renderer_args::RendererArgs,
    /// Stage-2 bounds: the stage-1 value ± this fraction of the original span.
    #[arg(long, default_value_t = 0.15, value_name = "FRACTION", value_parser = super::numbers::number, allow_hyphen_values = true)]
    stage2_window: f64,
    /// Stage-2 start: the population within this radius (unit cube of the
    /// narrowed bounds) of the stage-1 values.
    #[arg(long, default_value_t = 0.1, value_name = "RADIUS", value_parser = super::numbers::number, allow_hyphen_values = true)]
    stage2_start_radius: f64,
    /// A free parameter that keeps its full bounds in stage 2 (repeatable):
    /// for parameters the two renderers' models read differently.
    #[arg(long, value_name = "PARAM")]
    stage2_keep_bounds: Vec<String>,
    /// Stage 2 without the handover: full bounds, uniform start.
    #[arg(long)]
    stage2_from_scratch: bool,
    #[command(flatten)]
    method: Box<MethodArgs>,
    /// Override a scene field: PARAM=JSON.
    #[arg(long = "set", value_name = "PARAM=JSON")]
    set: Vec<Override>,
    /// The TrueType font of the report's figures (default: $SCENEFIT_FONT,
    /// else a system font such as DejaVu Sans).
    #[arg(long, value_name = "PATH")]
    font: Option<PathBuf>,
    /// Do not write report.html (comparison.json is written all the same).
    #[arg(long)]
    no_report: bool,
    /// No progress output.
    #[arg(long, short)]
    quiet: bool,
    /// Continue the pipeline in the output directory: each stage from its
    /// checkpoint, a finished stage kept.
    #[arg(long, conflicts_with = "overwrite")]
    resume: bool,
    /// Replace an earlier pipeline's files in the output directory.
    #[arg(long)]
    overwrite: bool,
}

/// Stage 2's method and the mapped method's budgets (boxed: the command
/// enum's variants stay of similar size).
#[derive(Args, Debug)]
struct MethodArgs {
    /// Stage 2's method: mapped (space mapping: the stage-1 renderer,
    /// corrected by a stage-2 render, searches; the stage-2 renderer checks
    /// each step), de (DE with the stage-2 renderer alone), or both (mapped
    /// as stage 2, DE too into stage2_de/ for comparison).
    #[arg(long, value_enum, default_value_t = Stage2Method::Mapped)]
    stage2_method: Stage2Method,
    /// Mapped stage 2: stage-2 renders at most.
    #[arg(long, default_value_t = MappedBudget::default().fine_renders, value_name = "N", value_parser = super::numbers::positive_count, allow_hyphen_values = true)]
    stage2_fine_renders: usize,
    /// Mapped stage 2: population of each iteration's surrogate fit.
    #[arg(long, default_value_t = MappedBudget::default().surrogate_population, value_name = "N", value_parser = super::numbers::positive_count, allow_hyphen_values = true)]
    stage2_surrogate_population: usize,
    /// Mapped stage 2: generations of each iteration's surrogate fit.
    #[arg(long, default_value_t = MappedBudget::default().surrogate_generations, value_name = "N", value_parser = super::numbers::positive_count, allow_hyphen_values = true)]
    stage2_surrogate_generations: usize,
}

pub fn run(a: PipelineArgs) -> Result<()> {
    super::env::use_font(a.font.clone())?;
    let scene = load_with(&a.inputs.scene, &a.set)?;
    let (target, note) = a.inputs.target(&scene)?;
    let opts = a.render_options.options_in(&a.output)?;
    let r1 = renderer(&a.stage1, "--stage1", &opts)?;
    let r2 = renderer(&a.stage2, "--stage2", &opts)?;
    let interrupt = interrupt_flag();
    let mut stage1 = a.s1.config(r1.default_jobs())?;
    let mut stage2 = a.s2.config(r2.default_jobs())?;
    check_memory(&a, &scene, &stage1, &stage2)?;
    stage1.interrupt = Some(interrupt.clone());
    stage2.interrupt = Some(interrupt);
    let config = PipelineConfig {
        stage1,
        stage2,
        window: a.stage2_window,
        start_radius: a.stage2_start_radius,
        from_scratch: a.stage2_from_scratch,
        keep_bounds: a.stage2_keep_bounds.clone(),
        mode: super::fit::run_mode(a.resume, a.overwrite),
        method: a.method.stage2_method,
        mapped: MappedBudget {
            fine_renders: a.method.stage2_fine_renders,
            surrogate_population: a.method.stage2_surrogate_population,
            surrogate_generations: a.method.stage2_surrogate_generations,
        },
    };
    let mut progress = StageProgress {
        quiet: a.quiet,
        bar: None,
    };
    let c = pipeline::run(
        &scene,
        &target,
        r1.as_ref(),
        r2.as_ref(),
        &config,
        &a.output,
        &mut progress,
    )?;
    if let Some(b) = progress.bar.take() {
        b.finish();
    }
    super::fit::tell(note.as_deref(), a.quiet);
    let report = if a.no_report {
        None
    } else {
        Some(report::write(&a.output, &ReportOptions::default())?)
    };
    if !a.quiet {
        let de = c
            .stage2_de
            .iter()
            .map(|s| ("stage 2, DE for comparison", s));
        for (name, s) in [("stage 1", &c.stage1), ("stage 2", &c.stage2)]
            .into_iter()
            .chain(de)
        {
            let d = s.deviation;
            println!(
                "{name} ({}): deviation %R {:.3} %G {:.3} %B {:.3} average {:.3}; {} renders in {:.1} s",
                s.renderer, d.r, d.g, d.b, d.average, s.evaluations, s.wall_seconds
            );
        }
        match report {
            Some(p) => println!("report: {}", p.display()),
            None => println!("results in {}", a.output.display()),
        }
    }
    Ok(())
}

/// Refuses stages whose populations would not fit in memory, naming the
/// stage's option.
fn check_memory(a: &PipelineArgs, scene: &Scene, s1: &FitConfig, s2: &FitConfig) -> Result<()> {
    let file = a.inputs.scene.display().to_string();
    let size = (scene.image.width, scene.image.height);
    let avail = crate::scene::memory::available();
    for (c, option) in [(s1, "--stage1-population"), (s2, "--stage2-population")] {
        let pop = Population {
            option,
            size: c.de.population,
            copies: 1,
        };
        crate::scene::memory::check_fit(avail, &file, size, pop, c.jobs)?;
    }
    Ok(())
}

/// The renderer named by a stage option; the error names the option.
fn renderer(spec: &str, option: &str, opts: &RenderOptions) -> Result<Box<dyn Renderer>> {
    from_spec_with(spec, opts).map_err(|e| match e {
        Error::Usage(m) => Error::Usage(m.replacen("--renderer", option, 1)),
        other => other,
    })
}

/// A progress display per stage.
struct StageProgress {
    quiet: bool,
    bar: Option<Progress>,
}

impl Observer for StageProgress {
    fn generation(&mut self, r: &GenerationReport) -> Result<()> {
        match &mut self.bar {
            Some(b) => b.generation(r),
            None => Ok(()),
        }
    }
}

impl StageObserver for StageProgress {
    fn iteration(&mut self, it: &Iteration) {
        if !self.quiet {
            eprintln!(
                "  iteration: radius {:.4}, surrogate {:.3} %, stage-2 render {:.3} %, {} ({} stage-2 renders)",
                it.radius,
                it.surrogate_deviation,
                it.deviation,
                if it.accepted { "accepted" } else { "rejected" },
                it.fine_renders
            );
        }
    }

    fn stage(&mut self, stage: u32, renderer: &str, dir: &Path) {
        if let Some(b) = self.bar.take() {
            b.finish();
        }
        if !self.quiet {
            eprintln!("stage {stage}: {renderer} -> {}", dir.display());
        }
        self.bar = Some(Progress::new(self.quiet));
    }
}
