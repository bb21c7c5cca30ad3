//! `scenefit diagnose FIT_DIR -o DIR`: find the effect a fit's model lacks,
//! add it, refit, report before and after (src/diagnose/). The output
//! directory follows the run-directory rule (`rundir`): locked while the
//! diagnosis runs, fresh unless `--overwrite`, no input inside it
//! replaced; a diagnosis refits in memory and saves no state, so it
//! cannot be resumed.

use crate::diagnose::set::SetInputs;
use crate::diagnose::{self, DiagnoseConfig, Inputs};
use crate::error::{Error, Result};
use crate::rundir::{Kind, Mode, RunDir, SHOTS};
use crate::scene::memory::Population;
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct DiagnoseArgs {
    /// A directory written by `scenefit fit`.
    fit_dir: PathBuf,
    /// Where the diagnosis goes.
    #[arg(short, long)]
    output: PathBuf,
    /// The target (default: the one named in FIT_DIR/result.json).
    #[arg(long)]
    target: Option<PathBuf>,
    /// Pixels that count (default: FIT_DIR/mask.png when present).
    #[arg(long)]
    mask: Option<PathBuf>,
    /// The renderer of the refits.
    #[arg(long, default_value = "phong")]
    renderer: String,
    /// DE population of each refit.
    #[arg(long, default_value_t = 16, value_parser = super::numbers::positive_count, allow_hyphen_values = true)]
    population: usize,
    /// Generations of each refit (searching the effect, then refining all).
    #[arg(long, default_value_t = 80, value_parser = super::numbers::positive_count, allow_hyphen_values = true)]
    generations: usize,
    /// Generations of each refit from scratch (population 40; 0: none, about
    /// six times fewer renders, but effects that other parameters can fake
    /// are then missed).
    #[arg(long, default_value_t = 250, value_parser = super::numbers::whole, allow_hyphen_values = true)]
    restart_generations: usize,
    /// Effects accepted at most.
    #[arg(long, default_value_t = 3, value_parser = super::numbers::whole, allow_hyphen_values = true)]
    max_effects: usize,
    #[arg(long, default_value_t = 1, value_parser = super::numbers::seed, allow_hyphen_values = true)]
    seed: u64,
    /// Refit the shared free parameters that move geometry (object shapes,
    /// the camera's placement) as well; by default they are held where the
    /// fit put them, which saves re-tracing every camera ray.
    #[arg(long)]
    refit_geometry: bool,
    /// Renders at once (default: the number of cores).
    #[arg(long, value_parser = super::numbers::positive_count, allow_hyphen_values = true)]
    jobs: Option<usize>,
    #[command(flatten)]
    render_options: super::renderer_args::RendererArgs,
    /// Replace an earlier diagnosis in the output directory (refused
    /// without it).
    #[arg(long)]
    overwrite: bool,
    /// Refused: a diagnosis refits in memory and saves no state to resume
    /// from (run it again with --overwrite).
    #[arg(long, conflicts_with = "overwrite")]
    resume: bool,
}

/// What the fit directory holds: a set of photographs, or one.
enum Fitted {
    Set(diagnose::set::SetInputs),
    One(Inputs),
}

pub fn run(a: DiagnoseArgs) -> Result<()> {
    if a.population < 4 || a.generations < 2 {
        return Err(Error::Usage(
            "--population must be at least 4 and --generations at least 2".into(),
        ));
    }
    if a.jobs == Some(0) {
        return Err(Error::Usage("--jobs: expected 1 or more".into()));
    }
    let set = diagnose::set::SetInputs::from_fit_dir(&a.fit_dir)?;
    if set.is_some() && (a.target.is_some() || a.mask.is_some()) {
        return Err(Error::Usage(format!(
            "--target/--mask: the fit directory holds a set of photographs; each one's target and mask come from its {SHOTS}"
        )));
    }
    let mut config = DiagnoseConfig {
        renderer: a.renderer.clone(),
        render_options: a.render_options.options_in(&a.output)?,
        population: a.population,
        search_generations: a.generations / 2,
        refine_generations: a.generations - a.generations / 2,
        max_rounds: a.max_effects,
        restart_generations: a.restart_generations,
        seed: a.seed,
        refit_geometry: a.refit_geometry,
        ..DiagnoseConfig::default()
    };
    if let Some(j) = a.jobs {
        config.jobs = j;
    }
    check_memory(&a.fit_dir, &config, set.as_ref())?;
    // The output is held and checked before the photograph is read: a
    // refused diagnosis says only why.
    let out = open_output(&a)?;
    refuse_inputs(&out, &a, set.as_ref())?;
    let fitted = match set {
        Some(s) => Fitted::Set(s),
        None => Fitted::One(Inputs::from_fit_dir(
            &a.fit_dir,
            a.target.as_deref(),
            a.mask.as_deref(),
        )?),
    };
    // An earlier diagnosis's files go only once this one has its inputs.
    if a.overwrite {
        out.clear()?;
    }
    let d = match fitted {
        Fitted::Set(set) => diagnose::set::run(&set, &a.output, &config)?.diagnosis,
        Fitted::One(inputs) => diagnose::run(&inputs, &a.output, &config)?,
    };
    println!(
        "deviation {:.3} % -> {:.3} %; accepted: {}; {} renders in {:.1} s; results in {}",
        d.deviation_before.average,
        d.deviation_after.average,
        if d.accepted.is_empty() {
            "none".into()
        } else {
            d.accepted.join(", ")
        },
        d.renders,
        d.wall_seconds,
        a.output.display()
    );
    Ok(())
}

/// The output directory, locked, by the run-directory rule; never the fit
/// directory itself (the diagnosis's report.html would replace the fit's).
fn open_output(a: &DiagnoseArgs) -> Result<RunDir> {
    if a.resume {
        return Err(Error::Usage(format!(
            "--resume: a diagnosis cannot be resumed (its refits run in memory and save no state); run it again with --overwrite to replace {}",
            a.output.display()
        )));
    }
    let same = |p: &Path| p.canonicalize().ok();
    if same(&a.output).is_some() && same(&a.output) == same(&a.fit_dir) {
        return Err(Error::Usage(format!(
            "-o {}: this is the fit directory; give the diagnosis a directory of its own",
            a.output.display()
        )));
    }
    let mode = if a.overwrite {
        Mode::Overwrite
    } else {
        Mode::Fresh
    };
    RunDir::open_as(&a.output, mode, Kind::Named(crate::rundir::diagnosis_owns))
}

/// Refuses an input (the target, the mask, a shot's photograph or mask)
/// that the diagnosis would overwrite in its output directory.
fn refuse_inputs(
    out: &RunDir,
    a: &DiagnoseArgs,
    set: Option<&diagnose::set::SetInputs>,
) -> Result<()> {
    let mut inputs: Vec<(String, &Path)> = [("--target", &a.target), ("--mask", &a.mask)]
        .into_iter()
        .filter_map(|(what, p)| p.as_deref().map(|p| (what.to_string(), p)))
        .collect();
    for s in set.iter().flat_map(|s| &s.shots) {
        inputs.push((format!("shot {}'s target", s.name), &s.entry.target));
        if let Some(m) = &s.entry.mask {
            inputs.push((format!("shot {}'s mask", s.name), m));
        }
    }
    inputs
        .into_iter()
        .try_for_each(|(what, p)| out.refuse_overwritten_input(p, &what))
}

/// Refuses a diagnosis that would not fit in memory. Its refits run side
/// by side, up to one per job and no more than a round's refits (each
/// effect and the unchanged model, warm and from scratch), each with the
/// largest of its populations and each candidate drawn once per
/// photograph: counted as that many images of each candidate at once.
/// Checked before a single fit's target is read, from its fitted scene.
fn check_memory(fit_dir: &Path, c: &DiagnoseConfig, set: Option<&SetInputs>) -> Result<()> {
    let file = fit_dir.join(crate::rundir::FITTED_SCENE);
    let (scene, shots) = match set {
        Some(s) => (s.scene.clone(), s.shots.len()),
        None => (crate::scene::load(&file)?, 1),
    };
    let lanes = c.jobs.min(2 * (crate::diagnose::effects::ALL.len() + 1));
    let pop = Population {
        option: "--population",
        size: c
            .population
            .max(c.search_population)
            .max(c.restart_population),
        copies: lanes.saturating_mul(shots),
    };
    let size = (scene.image.width, scene.image.height);
    crate::scene::memory::check(&file.display().to_string(), size, pop, c.jobs)
}
