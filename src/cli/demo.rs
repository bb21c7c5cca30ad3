//! `scenefit demo [-o DIR]`: the paper's Table II experiment on built-in
//! data. For each of the paper's six sphere colours, a target is rendered
//! from the built-in `paper_box.json` with hidden values (the "photograph"),
//! fitted with the paper's budget (population 80, 500 generations), and the
//! deviation is printed in the paper's table format with the error of every
//! recovered parameter.

use super::fit::interrupt_flag;
use super::progress::Progress;
use super::search::{self, Search, SearchArgs};
use crate::error::{Error, Result};
use crate::fit::{self, FitTarget};
use crate::render::{from_spec, render_one};
use crate::rundir::{Mode, RunDir, TARGET};
use crate::scene::memory::Population;
use crate::scene::{parse, ParamSpace, Scene, Value};
use clap::Args;
use std::path::PathBuf;

/// The built-in scene: the paper's acquisition box.
pub const PAPER_BOX: &str = include_str!("../../scenes/paper_box.json");

/// How the built-in scene is named in messages.
const BUILT_IN: &str = "scenes/paper_box.json (built in)";

/// The paper's six sphere colours (Table II), as linear RGB.
pub const COLOURS: [(&str, [f64; 3]); 6] = [
    ("red", [0.70, 0.06, 0.05]),
    ("green", [0.08, 0.55, 0.10]),
    ("blue", [0.06, 0.12, 0.65]),
    ("yellow", [0.80, 0.62, 0.05]),
    ("brown", [0.30, 0.14, 0.05]),
    ("pink", [0.85, 0.35, 0.45]),
];

/// The hidden values every target is rendered with (besides the sphere's colour).
pub const HIDDEN: [(&str, &str); 7] = [
    ("lights.led_left.position", "[-0.035, 0.138, 0.045]"),
    ("lights.led_left.intensity", "0.016"),
    ("lights.led_right.position", "[0.05, 0.128, 0.025]"),
    ("lights.led_right.intensity", "0.011"),
    ("objects.floor.material.color", "[0.50, 0.52, 0.45]"),
    ("objects.sphere.material.specular", "0.35"),
    ("objects.sphere.material.shininess", "35"),
];

#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Where to write each colour's target and fit.
    #[arg(short, long, default_value = "demo_out")]
    output: PathBuf,
    /// Only these colours (comma-separated), e.g. red,blue.
    #[arg(long, value_delimiter = ',')]
    colours: Option<Vec<String>>,
    #[command(flatten)]
    search: Search<search::Demo>,
    /// No progress output, only the tables.
    #[arg(long, short)]
    quiet: bool,
}

/// One colour's outcome.
struct Row {
    name: String,
    deviation: crate::metric::Deviation,
    evaluations: usize,
    seconds: f64,
    errors: Vec<(String, f64, String)>,
}

pub fn run(a: DemoArgs) -> Result<()> {
    let base = parse(PAPER_BOX, BUILT_IN, &[])?;
    let space = ParamSpace::from_scene(&base);
    let selected: Vec<(&str, [f64; 3])> = match &a.colours {
        None => COLOURS.to_vec(),
        Some(names) => names
            .iter()
            .map(|n| {
                COLOURS.iter().find(|(c, _)| c.eq_ignore_ascii_case(n)).copied().ok_or_else(|| {
                    Error::Usage(format!("--colours: unknown colour \"{n}\"; expected some of red, green, blue, yellow, brown, pink"))
                })
            })
            .collect::<Result<_>>()?,
    };
    let renderer = from_spec("phong")?;
    let mut config = a.search.config(renderer.default_jobs())?;
    let pop = Population {
        option: "--population",
        size: config.de.population,
        copies: 1,
    };
    let size = (base.image.width, base.image.height);
    crate::scene::memory::check(BUILT_IN, size, pop, config.jobs)?;
    config.interrupt = Some(interrupt_flag());
    let mut rows = Vec::new();
    for (name, rgb) in selected {
        let truth = hidden_scene(&base, rgb)?;
        let dir = a.output.join(name);
        // The demo's own directories: a second demo replaces the first.
        let run_dir = RunDir::open(&dir, Mode::Overwrite)?;
        run_dir.clear()?;
        let image = render_one(renderer.as_ref(), &truth, 0)?;
        run_dir.write_image(TARGET, &image)?;
        if !a.quiet {
            eprintln!(
                "{name}: fitting {} parameters ({} coordinates) to a hidden-truth target",
                space.specs.len(),
                space.dim()
            );
        }
        let target = FitTarget {
            image,
            levels: None,
            mask: None,
            path: Some(run_dir.file(TARGET)),
            encoding: None,
        };
        let mut progress = Progress::new(a.quiet);
        let outcome = fit::run_in(
            &base,
            &target,
            renderer.as_ref(),
            &config,
            Some(&run_dir),
            &mut progress,
        )?;
        progress.finish();
        let result = &outcome.result;
        rows.push(Row {
            name: name.to_string(),
            deviation: result.deviation,
            evaluations: result.evaluations,
            seconds: result.wall_seconds,
            errors: parameter_errors(&space, &truth, &outcome.scene),
        });
    }
    print_tables(&rows, &a.search);
    println!(
        "Targets, fits and their files are in {}",
        a.output.display()
    );
    Ok(())
}

/// The built-in scene with the hidden values and the sphere colour `rgb`.
fn hidden_scene(base: &Scene, rgb: [f64; 3]) -> Result<Scene> {
    let mut text: serde_json::Value =
        serde_json::to_value(base).map_err(|e| Error::Run(e.to_string()))?;
    let mut overrides: Vec<crate::scene::Override> = HIDDEN
        .iter()
        .map(|(k, v)| format!("{k}={v}").parse().map_err(Error::Usage))
        .collect::<Result<_>>()?;
    overrides.push(
        format!("objects.sphere.material.color={}", serde_json::json!(rgb))
            .parse()
            .map_err(Error::Usage)?,
    );
    text["free"] = serde_json::json!([]);
    parse(&text.to_string(), "demo truth", &overrides)
}

/// For each free parameter: |fitted - truth| (largest component), and a
/// note in the parameter's own terms.
fn parameter_errors(
    space: &ParamSpace,
    truth: &Scene,
    fitted: &Scene,
) -> Vec<(String, f64, String)> {
    space
        .specs
        .iter()
        .map(|s| {
            let (t, f) = (s.field.get(truth), s.field.get(fitted));
            let (err, note) = match (t, f) {
                (Some(Value::Vector(t)), Some(Value::Vector(f))) => {
                    let d = ((t[0] - f[0]).powi(2) + (t[1] - f[1]).powi(2) + (t[2] - f[2]).powi(2))
                        .sqrt();
                    let max = (0..3).map(|c| (t[c] - f[c]).abs()).fold(0.0, f64::max);
                    if s.name.ends_with("position") {
                        // Relative to the light's distance from the sphere.
                        let c = truth.objects[truth.object_index("sphere").unwrap_or(0)]
                            .shape
                            .field("center")
                            .unwrap_or(&[0.0; 3]);
                        let dist =
                            ((t[0] - c[0]).powi(2) + (t[1] - c[1]).powi(2) + (t[2] - c[2]).powi(2))
                                .sqrt();
                        (
                            d,
                            format!(
                                "{:.3} mm = {:.3} % of its distance to the sphere",
                                d * 1000.0,
                                100.0 * d / dist
                            ),
                        )
                    } else {
                        (max, format!("largest component off by {max:.5}"))
                    }
                }
                (Some(Value::Scalar(t)), Some(Value::Scalar(f))) => (
                    (t - f).abs(),
                    format!("{f:.5} for {t:.5} ({:+.3} %)", 100.0 * (f - t) / t),
                ),
                _ => (f64::NAN, "?".into()),
            };
            (s.name.clone(), err, note)
        })
        .collect()
}

fn print_tables(rows: &[Row], search: &SearchArgs) {
    println!();
    println!("TABLE II (this run): deviation from the rendered original, best generated image");
    println!(
        "DE {}, population {} x {} generations; built-in Phong-Blinn tracer",
        search.strategy, search.population, search.generations
    );
    println!(
        "{:<8} {:>7} {:>7} {:>7} {:>8} {:>9} {:>8}",
        "Sphere", "%R", "%G", "%B", "Average", "renders", "seconds"
    );
    for r in rows {
        let d = r.deviation;
        println!(
            "{:<8} {:>7.3} {:>7.3} {:>7.3} {:>8.3} {:>9} {:>8.1}",
            r.name, d.r, d.g, d.b, d.average, r.evaluations, r.seconds
        );
    }
    println!();
    println!("Recovered parameters against the hidden truth:");
    for r in rows {
        println!("{}:", r.name);
        for (name, _, note) in &r.errors {
            println!("  {name:<36} {note}");
        }
    }
}
