//! `scenefit fit SCENE --target IMG [--mask M] -o DIR [--renderer R] ...`

use super::progress::Progress;
use super::search::{self, Search};
use crate::error::{Error, Result};
use crate::fit::{self, FitTarget};
use crate::raster::Encoding;
use crate::render::from_spec_with;
use crate::rundir::Mode;
use crate::scene::memory::Population;
use crate::scene::{load_with, Override, Scene};
use clap::Args;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// What every fitting command reads: the scene, the photograph, the mask
/// (or a set of photographs, each with its own mask).
#[derive(Args, Debug)]
pub struct FitInputs {
    /// The scene file (JSON) with its "free" parameters.
    pub scene: PathBuf,
    /// The photograph (or rendered target) to fit, the scene's image size.
    #[arg(long, required_unless_present = "shots")]
    pub target: Option<PathBuf>,
    /// Pixels that count: white in an image of the same size.
    #[arg(long, conflicts_with = "shots")]
    pub mask: Option<PathBuf>,
    /// A set of photographs of the scene (a shots file, format
    /// scenefit-shots/1): fitted jointly, free parameters marked
    /// "per_shot" get one value per photograph.
    #[arg(long, conflicts_with = "target", value_name = "SHOTS.json")]
    pub shots: Option<PathBuf>,
    /// How the photograph encodes light: srgb (default; linear for
    /// OpenEXR) or linear.
    #[arg(long, value_name = "srgb|linear", conflicts_with = "shots")]
    pub encoding: Option<Encoding>,
}

impl FitInputs {
    /// The photograph and mask, checked against the scene's image size,
    /// and a line saying how many saturated pixels were left out (said once
    /// the run has succeeded: a refused run says only why).
    pub fn target(&self, scene: &Scene) -> Result<(FitTarget, Option<String>)> {
        let Some(target) = &self.target else {
            return Err(Error::Usage(
                "--shots: this command fits one photograph; give --target".into(),
            ));
        };
        let size = (scene.image.width, scene.image.height);
        let mask = self.mask.as_deref().map(|m| (m, "--mask"));
        FitTarget::from_photo(target, "--target", mask, self.encoding, size)
    }
}

/// Says `note` on stderr unless `quiet`.
pub fn tell(note: Option<&str>, quiet: bool) {
    if let (Some(n), false) = (note, quiet) {
        eprintln!("{n}");
    }
}

#[derive(Args, Debug)]
pub struct FitArgs {
    #[command(flatten)]
    inputs: FitInputs,
    /// The run directory.
    #[arg(short, long)]
    output: PathBuf,
    /// phong, povray, blender, mitsuba, cmd:TEMPLATE or worker:COMMAND.
    #[arg(long, default_value = "phong")]
    renderer: String,
    #[command(flatten)]
    search: Search<search::Fit>,
    #[command(flatten)]
    render_options: super::renderer_args::RendererArgs,
    /// Continue the run in the output directory from its checkpoint.
    #[arg(long, conflicts_with = "overwrite")]
    resume: bool,
    /// Replace an earlier run's files in the output directory (refused
    /// without this or --resume).
    #[arg(long)]
    overwrite: bool,
    /// Override a scene field: PARAM=JSON.
    #[arg(long = "set", value_name = "PARAM=JSON")]
    set: Vec<Override>,
    /// Free a photograph's nuisance parameters too: exposure (0.25-4),
    /// white_balance (0.5-2 per channel).
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    nuisance: Vec<crate::scene::Nuisance>,
    /// A set of photographs (--shots): alternations of the shared and the
    /// per-shot blocks at most [default: 4].
    #[arg(long, value_parser = super::numbers::positive_count, allow_hyphen_values = true)]
    rounds: Option<usize>,
    /// A set of photographs (--shots): end with one Levenberg–Marquardt
    /// block over the shared and every photograph's own values at once.
    #[arg(long)]
    joint: bool,
    /// No progress output.
    #[arg(long, short)]
    quiet: bool,
}

pub fn run(a: FitArgs) -> Result<()> {
    if a.inputs.shots.is_none() && (a.joint || a.rounds.is_some()) {
        let flag = if a.joint { "--joint" } else { "--rounds" };
        return Err(Error::Usage(format!(
            "{flag}: applies to a set of photographs; give --shots SHOTS.json"
        )));
    }
    let mut scene = load_with(&a.inputs.scene, &a.set)?;
    crate::scene::nuisance::add(&mut scene, &a.nuisance);
    if let Some(shots) = &a.inputs.shots {
        let (shots, notes) = crate::fit::set::shots::load(shots, &scene)?;
        run_set(&a, &scene, &shots)?;
        let note = notes.first().map(|first| {
            format!(
                "--shots: saturated pixels left out of the fit in {} of {} photographs (first: {first})",
                notes.len(),
                shots.len()
            )
        });
        tell(note.as_deref(), a.quiet);
        return Ok(());
    }
    let (target, note) = a.inputs.target(&scene)?;
    let renderer = from_spec_with(&a.renderer, &a.render_options.options_in(&a.output)?)?;
    let mut config = a.search.config(renderer.default_jobs())?;
    let file = a.inputs.scene.display().to_string();
    let (w, h) = (scene.image.width, scene.image.height);
    let avail = crate::scene::memory::available();
    let pop = Population {
        option: "--population",
        size: config.de.population,
        copies: 1,
    };
    crate::scene::memory::check_fit(avail, &file, (w, h), pop, config.jobs)?;
    config.mode = run_mode(a.resume, a.overwrite);
    if let Some(m) = &a.inputs.mask {
        config.inputs.push(("--mask".into(), m.clone()));
    }
    config
        .inputs
        .push(("the scene".into(), a.inputs.scene.clone()));
    config.interrupt = Some(interrupt_flag());
    let mut progress = Progress::new(a.quiet);
    let outcome = fit::run(
        &scene,
        &target,
        renderer.as_ref(),
        &config,
        &a.output,
        &mut progress,
    )?;
    progress.finish();
    tell(note.as_deref(), a.quiet);
    let result = outcome.result;
    if !a.quiet {
        let d = result.deviation;
        println!(
            "deviation %R {:.3} %G {:.3} %B {:.3} average {:.3}; {} renders in {:.1} s ({}); results in {}",
            d.r,
            d.g,
            d.b,
            d.average,
            result.evaluations,
            result.wall_seconds,
            result.stop_reason,
            a.output.display()
        );
    }
    Ok(())
}

/// `fit --shots`: one fit of every photograph of a set.
fn run_set(a: &FitArgs, scene: &Scene, shots: &[crate::fit::set::shots::Shot]) -> Result<()> {
    let renderer = from_spec_with(&a.renderer, &a.render_options.options_in(&a.output)?)?;
    let mut config = a.search.config(renderer.default_jobs())?;
    let file = a.inputs.scene.display().to_string();
    let (w, h) = (scene.image.width, scene.image.height);
    let avail = crate::scene::memory::available();
    let pop = Population {
        option: "--population",
        size: config.de.population,
        copies: shots.len(),
    };
    crate::scene::memory::check_fit(avail, &file, (w, h), pop, config.jobs)?;
    config.mode = run_mode(a.resume, a.overwrite);
    config.interrupt = Some(interrupt_flag());
    config
        .inputs
        .push(("the scene".into(), a.inputs.scene.clone()));
    if let Some(s) = &a.inputs.shots {
        config.inputs.push(("--shots".into(), s.clone()));
    }
    let set = fit::set::SetConfig {
        spread: Vec::new(),
        fit: config,
        rounds: a.rounds.unwrap_or(4),
        warm: false,
        joint: a.joint,
    };
    let mut progress = Progress::new(a.quiet);
    let outcome = fit::set::run(
        scene,
        shots,
        renderer.as_ref(),
        &set,
        &a.output,
        &mut progress,
    )?;
    progress.finish();
    if !a.quiet {
        let r = &outcome.result;
        let worst = outcome
            .shots
            .iter()
            .map(|s| s.result.deviation.average)
            .fold(0.0, f64::max);
        println!(
            "{} photographs: average deviation {:.3} (worst photograph {:.3}); {} renders in {:.1} s ({}); results in {}",
            shots.len(),
            r.deviation.average,
            worst,
            r.evaluations,
            r.wall_seconds,
            r.stop_reason,
            a.output.display()
        );
    }
    Ok(())
}

/// The run directory's mode from `--resume` and `--overwrite`.
pub fn run_mode(resume: bool, overwrite: bool) -> Mode {
    match (resume, overwrite) {
        (true, _) => Mode::Resume,
        (false, true) => Mode::Overwrite,
        (false, false) => Mode::Fresh,
    }
}

/// Set on Ctrl-C: the run stops after the current generation, checkpoint written.
pub fn interrupt_flag() -> Arc<AtomicBool> {
    let flag = Arc::new(AtomicBool::new(false));
    let f = flag.clone();
    let _ = ctrlc::set_handler(move || {
        f.store(true, std::sync::atomic::Ordering::SeqCst);
        crate::exec::cancel::cancel(); // kills the renders in flight
    });
    flag
}
