//! `scenefit report RUN_DIR [--target IMG] [--mask M] [--font PATH]`: (re)writes
//! RUN_DIR/report.html for a fit directory or a pipeline directory.

use crate::error::Result;
use crate::report::{self, ReportOptions};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ReportArgs {
    /// A fit directory (result.json) or a pipeline directory (comparison.json).
    dir: PathBuf,
    /// The target, when the run directory does not hold it (a fit records
    /// the path it was given, relative to where it ran).
    #[arg(long)]
    target: Option<PathBuf>,
    /// The mask the fit used (a fit directory does not record it).
    #[arg(long)]
    mask: Option<PathBuf>,
    /// The TrueType font of the figures' text (default: $SCENEFIT_FONT,
    /// else a system font such as DejaVu Sans).
    #[arg(long, value_name = "PATH")]
    font: Option<PathBuf>,
    /// Print nothing on success.
    #[arg(long, short)]
    quiet: bool,
}

pub fn run(a: ReportArgs) -> Result<()> {
    super::env::use_font(a.font)?;
    let path = report::write(
        &a.dir,
        &ReportOptions {
            target: a.target,
            mask: a.mask,
        },
    )?;
    if !a.quiet {
        println!("{}", path.display());
    }
    Ok(())
}
