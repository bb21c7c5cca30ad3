//! A report through the API: report.html of a fit or pipeline directory
//! (re)written while the directory's lock is held, so that no run writes
//! it meanwhile. A set fit's directory is refused: its page is the set
//! diagnosis's.

use crate::error::{Error, Result};
use crate::report::ReportOptions;
use crate::rundir::{Kind, RunDir, COMPARISON, REPORT, RESULT, SHOTS};
use std::path::{Path, PathBuf};

/// What a report reads besides the run directory.
#[derive(Clone, Debug, Default)]
pub struct ReportRequest {
    /// The target and mask, when the run directory does not hold them.
    pub options: ReportOptions,
    /// The figures' TrueType font and the option or variable that named
    /// it (None: a system font).
    pub font: Option<(&'static str, PathBuf)>,
}

/// Writes `dir`/report.html; returns its path.
pub fn report(dir: &Path, r: ReportRequest) -> Result<PathBuf> {
    // Only a run's directory is locked (report refuses any other below,
    // and leaves no lock file in it).
    let is_run = [RESULT, COMPARISON].iter().any(|n| dir.join(n).is_file());
    let _held = is_run.then(|| RunDir::update(dir, Kind::Fit)).transpose()?;
    if dir.join(SHOTS).is_file() {
        return Err(Error::Usage(format!(
            "{}: a fit of a set of photographs ({SHOTS}); report draws a fit of one photograph or a pipeline; `scenefit diagnose {} -o DIR` writes a set's {REPORT}",
            dir.display(),
            dir.display()
        )));
    }
    if let Some((source, path)) = r.font {
        crate::report::font::use_file(source, path)?;
    }
    crate::report::write(dir, &r.options)
}
