//! `scenefit report RUN_DIR [--target IMG] [--mask M]`: (re)writes
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
    /// Print nothing on success.
    #[arg(long, short)]
    quiet: bool,
}

pub fn run(a: ReportArgs) -> Result<()> {
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
