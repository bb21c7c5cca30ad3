//! The command line (docs/usage.md): `demo`, `render`, `fit`, `pipeline`,
//! `diagnose`, `report`, `import-cameras`, `free`, `import`, `export`. Each subcommand lives in its own file; this one parses and dispatches,
//! and turns errors into one line and an exit code.

mod demo;
mod diagnose;
mod env;
mod export;
mod fit;
mod free;
mod import;
mod import_cameras;
mod numbers;
mod pipeline;
mod progress;
mod render;
mod renderer_args;
mod report;
mod search;

use clap::{Parser, Subcommand};

#[derive(Parser, Debug)]
#[command(
    name = "scenefit",
    version,
    about = "Recover a scene's optical parameters from a photograph by rendering in the loop"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// The paper's job on built-in data: fit hidden-truth targets of paper_box.json.
    Demo(demo::DemoArgs),
    /// Render a scene to an image.
    Render(render::RenderArgs),
    /// Fit a scene's free parameters to a target image.
    Fit(fit::FitArgs),
    /// Find the effect a fit's model lacks, add it, refit, report before and after.
    Diagnose(diagnose::DiagnoseArgs),
    /// Two-stage fit: Phong over the full bounds, then a physically based renderer around its result.
    Pipeline(pipeline::PipelineArgs),
    /// (Re)write report.html of a fit or pipeline directory.
    Report(report::ReportArgs),
    /// Cameras from COLMAP or OpenCV calibration as a shots file (docs/interchange.md).
    ImportCameras(import_cameras::ImportCamerasArgs),
    /// List the fields a scene offers as free parameters, or free those a glob matches.
    Free(free::FreeArgs),
    /// Read another tool's scene (.blend) into a scene file (docs/interchange.md).
    Import(import::ImportArgs),
    /// Write a scene in another tool's format (--to blender) (docs/interchange.md).
    Export(export::ExportArgs),
}

/// Runs the command line; returns the process exit code.
pub fn main() -> i32 {
    if std::env::args_os().nth(1).as_deref() == Some(crate::exec::watchdog::WATCHDOG_ARG.as_ref()) {
        return crate::exec::watchdog::serve();
    }
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if e.use_stderr() => {
            // One line: clap's message up to its first blank line, joined.
            let text = e.render().to_string();
            let first: Vec<&str> = text
                .lines()
                .take_while(|l| !l.trim().is_empty())
                .map(str::trim)
                .collect();
            let line = crate::scene::limits::one_line(&first.join(" "));
            eprintln!("{line} (see --help)");
            return 2;
        }
        Err(e) => {
            let _ = e.print(); // --help, --version
            return 0;
        }
    };
    // renderers and run directories must not outlive even a SIGKILL
    crate::exec::watchdog::enable();
    let result = match cli.command {
        Command::Demo(a) => demo::run(a),
        Command::Render(a) => render::run(a),
        Command::Fit(a) => fit::run(a),
        Command::Diagnose(a) => diagnose::run(a),
        Command::Pipeline(a) => pipeline::run(a),
        Command::Report(a) => report::run(a),
        Command::ImportCameras(a) => import_cameras::run(a),
        Command::Free(a) => free::run(a),
        Command::Import(a) => import::run(a),
        Command::Export(a) => export::run(a),
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            // one line whatever the message holds (names, serde's text)
            eprintln!("error: {}", crate::scene::limits::one_line(&e.to_string()));
            if e.is_user_error() {
                2
            } else {
                1
            }
        }
    }
}
