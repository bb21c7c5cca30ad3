//! `scenefit report RUN_DIR [--target IMG] [--mask M] [--font PATH]`: (re)writes
//! RUN_DIR/report.html for a fit directory or a pipeline directory, holding
//! the directory's lock meanwhile (no run may be writing it). A set fit's
//! directory is refused with what to run instead: its page is the set
//! diagnosis's (every photograph before and after), the report's figures
//! are those of one photograph.

use crate::api::{self, ReportRequest};
use crate::error::Result;
use crate::report::ReportOptions;
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
    let request = ReportRequest {
        options: ReportOptions {
            target: a.target,
            mask: a.mask,
        },
        font: super::env::font(a.font),
    };
    let path = api::report(&a.dir, request)?;
    if !a.quiet {
        println!("{}", path.display());
    }
    Ok(())
}
