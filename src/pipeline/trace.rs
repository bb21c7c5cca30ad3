//! What a stage records beside the fit's own files, for the report:
//!
//! - `trace.tsv`: one line per generation — generation, renders, seconds
//!   spent in generations so far, and the best deviation (average, r, g, b).
//!   progress.txt has no time column and only every 10th generation; this
//!   gives the convergence plot its seconds axis without assuming that every
//!   generation took as long as the others.
//! - `final_checkpoint.json`: the fit's checkpoint as it was after the last
//!   generation. A finished fit leaves `"de": null` in checkpoint.json (the
//!   phase's optimizer is dropped once the phase ends); this copy keeps the
//!   final population, whose spread tells which parameters the image pins
//!   down and which trade off against each other.
//!
//! Both are written by an observer that wraps the caller's: the fit saves
//! its checkpoint before it reports a generation, so the file read then holds
//! that generation's population.

use crate::error::{Error, Result};
use crate::fit::{GenerationReport, Observer};
use std::io::Write;
use std::path::{Path, PathBuf};

pub const TRACE: &str = "trace.tsv";
pub const FINAL_CHECKPOINT: &str = "final_checkpoint.json";

/// Records a stage's trace and its last checkpoint, then passes each report on.
pub struct Recorder<'a> {
    dir: PathBuf,
    trace: std::fs::File,
    last_checkpoint: Option<Vec<u8>>,
    inner: &'a mut dyn Observer,
    /// The first write error; reported when the stage ends.
    error: Option<Error>,
}

impl<'a> Recorder<'a> {
    pub fn new(dir: &Path, inner: &'a mut dyn Observer) -> Result<Recorder<'a>> {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        let path = dir.join(TRACE);
        let mut trace = std::fs::File::create(&path).map_err(|e| Error::io(&path, e))?;
        writeln!(
            trace,
            "# generation evaluations seconds deviation_average deviation_r deviation_g deviation_b"
        )
        .map_err(|e| Error::io(&path, e))?;
        let _ = std::fs::remove_file(dir.join(FINAL_CHECKPOINT));
        Ok(Recorder {
            dir: dir.to_path_buf(),
            trace,
            last_checkpoint: None,
            inner,
            error: None,
        })
    }

    /// Writes final_checkpoint.json; returns the first error met on the way.
    pub fn finish(self) -> Result<()> {
        if let Some(e) = self.error {
            return Err(e);
        }
        if let Some(bytes) = self.last_checkpoint {
            let path = self.dir.join(FINAL_CHECKPOINT);
            std::fs::write(&path, bytes).map_err(|e| Error::io(&path, e))?;
        }
        Ok(())
    }
}

impl Observer for Recorder<'_> {
    fn generation(&mut self, r: &GenerationReport) {
        let d = r.best;
        let line = writeln!(
            self.trace,
            "{} {} {:.4} {:.4} {:.4} {:.4} {:.4}",
            r.generation, r.evaluations, r.elapsed, d.average, d.r, d.g, d.b
        );
        if let (Err(e), None) = (line, &self.error) {
            self.error = Some(Error::io(&self.dir.join(TRACE), e));
        }
        // Kept in memory, written once at the end: a copy per generation
        // would double the disk traffic of a fast Phong stage.
        if let Ok(bytes) = std::fs::read(self.dir.join("checkpoint.json")) {
            self.last_checkpoint = Some(bytes);
        }
        self.inner.generation(r);
    }
}
