//! `scenefit fit SCENE (--target IMG [--mask M] | --shots SHOTS.json) -o DIR [--renderer R] ...`:
//! one photograph or a set, both through `api::fit` as a list of shots.

use super::progress::Progress;
use super::search::{self, Search};
use crate::api::{self, FitRequest, Fitted, Photographs};
use crate::error::{Error, Result};
use crate::fit::FitTarget;
use crate::raster::Encoding;
use crate::rundir::Mode;
use crate::scene::{load_with, Override, Scene};
use clap::Args;
use std::path::{Path, PathBuf};
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

    /// The photographs to fit: the shots file's, or `--target` as a list
    /// of one; with the line on saturated pixels left out.
    pub fn photographs(&self, scene: &Scene) -> Result<(Photographs, Option<String>)> {
        let Some(file) = &self.shots else {
            let (target, note) = self.target(scene)?;
            return Ok((Photographs::one(scene, target), note));
        };
        let (shots, notes) = crate::fit::set::shots::load(file, scene)?;
        let note = notes.first().map(|first| {
            format!(
                "--shots: saturated pixels left out of the fit in {} of {} photographs (first: {first})",
                notes.len(),
                shots.len()
            )
        });
        let photos = Photographs {
            shots,
            file: Some(file.clone()),
        };
        Ok((photos, note))
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
    /// A set of photographs (--shots): leave these shots (names as in the
    /// shots file) out of the fit and predict them from the fitted model
    /// (result.json's held_out), besides those the file marks "hold_out".
    #[arg(long, value_delimiter = ',', value_name = "NAME,...")]
    hold_out: Vec<String>,
    /// No progress output.
    #[arg(long, short)]
    quiet: bool,
}

pub fn run(a: FitArgs) -> Result<()> {
    let set_only = [
        ("--joint", a.joint),
        ("--rounds", a.rounds.is_some()),
        ("--hold-out", !a.hold_out.is_empty()),
    ];
    if let (None, Some((flag, _))) = (&a.inputs.shots, set_only.iter().find(|f| f.1)) {
        return Err(Error::Usage(format!(
            "{flag}: applies to a set of photographs; give --shots SHOTS.json"
        )));
    }
    let mut scene = load_with(&a.inputs.scene, &a.set)?;
    crate::scene::nuisance::add(&mut scene, &a.nuisance);
    let renderer = api::renderer(&a.renderer, &a.render_options.options_in(&a.output)?)?;
    let mut config = a.search.config(renderer.default_jobs())?;
    config.mode = run_mode(a.resume, a.overwrite);
    config.interrupt = Some(interrupt_flag());
    let request = FitRequest {
        scene: &scene,
        scene_file: &a.inputs.scene,
        inputs: a
            .inputs
            .mask
            .iter()
            .map(|m| ("--mask".into(), m.clone()))
            .collect(),
        renderer: renderer.as_ref(),
        config,
        rounds: a.rounds.unwrap_or(4),
        joint: a.joint,
    };
    // Before any photograph is decoded: an image too large for this
    // machine is refused at once, not after seconds of decoding.
    api::check_memory(&request, 1)?;
    let (mut photos, note) = a.inputs.photographs(&scene)?;
    crate::fit::set::held_out::mark(&mut photos.shots, &a.hold_out, "--hold-out")?;
    let mut progress = Progress::new(a.quiet);
    let fitted = api::fit(request, &photos, &a.output, &mut progress)?;
    progress.finish();
    tell(note.as_deref(), a.quiet);
    if !a.quiet {
        let fitted_shots = photos.shots.iter().filter(|s| !s.entry.hold_out);
        println!("{}", summary(&fitted, fitted_shots.count(), &a.output));
    }
    Ok(())
}

/// The line a fit ends with: the deviation (over every photograph, and the
/// worst one's, for a set), renders, time, why it stopped, where it wrote.
fn summary(fitted: &Fitted, photographs: usize, dir: &Path) -> String {
    let r = fitted.result();
    let d = r.deviation;
    let head = match fitted.worst() {
        None => format!(
            "deviation %R {:.3} %G {:.3} %B {:.3} average {:.3}",
            d.r, d.g, d.b, d.average
        ),
        Some(worst) => format!(
            "{photographs} photographs: average deviation {:.3} (worst photograph {worst:.3}){}",
            d.average,
            held_out(r)
        ),
    };
    format!(
        "{head}; {} renders in {:.1} s ({}); results in {}",
        r.evaluations,
        r.wall_seconds,
        r.stop_reason,
        dir.display()
    )
}

/// The held-out photographs' predictions, as the summary says them.
fn held_out(r: &crate::fit::FitResult) -> String {
    let devs: Vec<f64> = r.held_out.iter().map(|h| h.deviation_fit.average).collect();
    if devs.is_empty() {
        return String::new();
    }
    let worst = devs.iter().copied().fold(0.0, f64::max);
    let mean = devs.iter().sum::<f64>() / devs.len() as f64;
    format!(
        "; {} held out, predicted at {mean:.3} on average (worst {worst:.3})",
        devs.len()
    )
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
