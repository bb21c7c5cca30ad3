//! `scenefit diagnose FIT_DIR -o DIR`: find the effect a fit's model lacks,
//! add it, refit, report before and after (src/diagnose/). The output
//! directory follows the run-directory rule (`rundir`): locked while the
//! diagnosis runs, fresh unless `--overwrite`, no input inside it
//! replaced; a diagnosis refits in memory and saves no state, so it
//! cannot be resumed.

use crate::api::{self, DiagnoseConfig, DiagnoseRequest};
use crate::error::{Error, Result};
use clap::Args;
use std::path::PathBuf;

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
    /// Least fraction by which an effect must lower the sum of absolute
    /// differences to be accepted, beside the criterion (docs/diagnose.md,
    /// "The least gain").
    #[arg(long, default_value_t = DiagnoseConfig::default().min_gain, value_parser = super::numbers::fraction, allow_hyphen_values = true)]
    min_gain: f64,
    /// Try only these effects (names as in docs/diagnose.md's table), e.g.
    /// `albedo_map` alone for a per-texel Lambertian baseline; default:
    /// every effect.
    #[arg(long, value_delimiter = ',', value_name = "NAME,...")]
    effects: Vec<String>,
    #[arg(long, default_value_t = 1, value_parser = super::numbers::seed, allow_hyphen_values = true)]
    seed: u64,
    /// Refit the shared free parameters that move geometry (object shapes,
    /// the camera's placement) as well; by default they are held where the
    /// fit put them, which saves re-tracing every camera ray.
    #[arg(long)]
    refit_geometry: bool,
    /// The side, in texels, of the colour maps the `albedo_map` effect
    /// solves in each object's frame (default: chosen from how many pixels
    /// see the object; at most 1024).
    #[arg(long, value_name = "N", value_parser = super::numbers::map_size, allow_hyphen_values = true)]
    map_size: Option<u32>,
    /// A set of photographs: leave these shots (names as in the fit's
    /// shots file) out of the diagnosis too, and predict them before and
    /// after (diagnosis.json's held_out); the fit's held-out ones always are.
    #[arg(long, value_delimiter = ',', value_name = "NAME,...")]
    hold_out: Vec<String>,
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

pub fn run(a: DiagnoseArgs) -> Result<()> {
    if a.population < 4 || a.generations < 2 {
        return Err(Error::Usage(
            "--population must be at least 4 and --generations at least 2".into(),
        ));
    }
    if a.jobs == Some(0) {
        return Err(Error::Usage("--jobs: expected 1 or more".into()));
    }
    if a.resume {
        return Err(Error::Usage(format!(
            "--resume: a diagnosis cannot be resumed (its refits run in memory and save no state); run it again with --overwrite to replace {}",
            a.output.display()
        )));
    }
    let mut config = DiagnoseConfig {
        renderer: a.renderer.clone(),
        render_options: a.render_options.options_in(&a.output)?,
        population: a.population,
        search_generations: a.generations / 2,
        refine_generations: a.generations - a.generations / 2,
        max_rounds: a.max_effects,
        min_gain: a.min_gain,
        restart_generations: a.restart_generations,
        seed: a.seed,
        refit_geometry: a.refit_geometry,
        map_size: a.map_size,
        effects: (!a.effects.is_empty()).then_some(a.effects),
        ..DiagnoseConfig::default()
    };
    if let Some(j) = a.jobs {
        config.jobs = j;
    }
    let d = api::diagnose(&DiagnoseRequest {
        fit_dir: a.fit_dir,
        output: a.output.clone(),
        target: a.target,
        mask: a.mask,
        overwrite: a.overwrite,
        hold_out: a.hold_out,
        config,
    })?;
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
