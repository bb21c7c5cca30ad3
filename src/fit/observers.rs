//! What a fit writes as it goes, as observers of the generation loop:
//! progress.txt and the paper's best_gNNNN.bmp snapshots every
//! `snapshot_every` generations, and failures.log every generation.

use super::executor::Observer;
use super::GenerationReport;
use crate::error::{Error, Result};
use crate::rundir::{snapshot_name, RunDir, FAILURES, PROGRESS};
use std::io::Write;
use std::path::PathBuf;

/// Appends a line to a log file of the run, opened on first use.
struct Appender {
    path: PathBuf,
    file: Option<std::fs::File>,
}

impl Appender {
    fn new(dir: &RunDir, name: &str) -> Appender {
        Appender {
            path: dir.file(name),
            file: None,
        }
    }

    fn line(&mut self, text: &str) -> Result<()> {
        if self.file.is_none() {
            let f = std::fs::OpenOptions::new()
                .create(true)
                .append(true)
                .open(&self.path)
                .map_err(|e| Error::io(&self.path, e))?;
            self.file = Some(f);
        }
        let f = self.file.as_mut().expect("opened above");
        writeln!(f, "{text}").map_err(|e| Error::io(&self.path, e))
    }
}

/// progress.txt and the snapshots, every `every` generations.
pub struct Progress {
    log: Appender,
    dir: PathBuf,
    every: usize,
}

impl Progress {
    /// A fresh run writes the header; a resumed one appends (and writes
    /// it if the run it resumes had not written the file yet).
    pub fn new(dir: &RunDir, every: usize, fresh: bool) -> Result<Progress> {
        let mut log = Appender::new(dir, PROGRESS);
        if fresh || !dir.file(PROGRESS).exists() {
            log.line("# generation evaluations deviation_average deviation_r deviation_g deviation_b params")?;
        }
        Ok(Progress {
            log,
            dir: dir.path().to_path_buf(),
            every: every.max(1),
        })
    }
}

impl Observer for Progress {
    fn cadence(&self) -> usize {
        self.every
    }

    fn generation(&mut self, r: &GenerationReport) -> Result<()> {
        if let Some(img) = r.best_image {
            crate::raster::io::write_image(img, &self.dir.join(snapshot_name(r.generation)))?;
        }
        let d = &r.best;
        let params = serde_json::to_string(&r.params).unwrap_or_default();
        self.log.line(&format!(
            "{} {} {:.4} {:.4} {:.4} {:.4} {params}",
            r.generation, r.evaluations, d.average, d.r, d.g, d.b
        ))
    }
}

/// failures.log: every failed render, as it happens.
pub struct Failures {
    log: Appender,
    pub count: usize,
}

impl Failures {
    pub fn new(dir: &RunDir) -> Failures {
        Failures {
            log: Appender::new(dir, FAILURES),
            count: 0,
        }
    }
}

impl Failures {
    /// Logs failed renders (also those of a generation that failed whole,
    /// which no observer sees).
    pub fn record(&mut self, failures: &[String]) -> Result<()> {
        for f in failures {
            self.log.line(f)?;
        }
        self.count += failures.len();
        Ok(())
    }
}

impl Observer for Failures {
    fn generation(&mut self, r: &GenerationReport) -> Result<()> {
        self.record(r.failures)
    }
}
