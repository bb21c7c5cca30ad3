//! trace.tsv, the one writer of it: one line per generation — generation,
//! renders, seconds spent in generations so far, and the best deviation
//! (average, r, g, b) — under one header. progress.txt has no time column
//! and only every 10th generation; this gives the report's convergence plot
//! its seconds axis without assuming that every generation took as long as
//! the others. A DE stage writes it through `Recorder`, an observer that
//! passes each report on to the caller's; a space-mapped stage 2 writes a
//! line per iteration (generation = iteration, renders = fine renders), so
//! the report reads both alike.

use crate::error::{Error, Result};
use crate::fit::{GenerationReport, Observer};
use crate::metric::Deviation;
use crate::rundir::{RunDir, TRACE};
use std::io::Write;
use std::path::PathBuf;

/// The first line of every trace.tsv (the report skips `#` lines).
const HEADER: &str =
    "# generation evaluations seconds deviation_average deviation_r deviation_g deviation_b";

/// A stage's trace.tsv, open for lines.
pub struct Trace {
    path: PathBuf,
    file: std::fs::File,
}

impl Trace {
    /// A fresh trace: the file replaced by its header.
    pub fn create(dir: &RunDir) -> Result<Trace> {
        Trace::open(dir, false)
    }

    /// The trace of a resumed stage, appended to (begun with the header
    /// when it is missing or empty).
    pub fn append(dir: &RunDir) -> Result<Trace> {
        Trace::open(dir, true)
    }

    fn open(dir: &RunDir, append: bool) -> Result<Trace> {
        let path = dir.file(TRACE);
        let mut opts = std::fs::OpenOptions::new();
        opts.create(true);
        if append {
            opts.append(true);
        } else {
            opts.write(true).truncate(true);
        }
        let mut file = opts.open(&path).map_err(|e| Error::io(&path, e))?;
        let empty = file.metadata().map_err(|e| Error::io(&path, e))?.len() == 0;
        if empty {
            writeln!(file, "{HEADER}").map_err(|e| Error::io(&path, e))?;
        }
        Ok(Trace { path, file })
    }

    /// One line: the generation (or iteration), its renders so far, its
    /// seconds so far and the best deviation.
    pub fn line(
        &mut self,
        generation: usize,
        renders: usize,
        seconds: f64,
        d: &Deviation,
    ) -> Result<()> {
        writeln!(
            self.file,
            "{generation} {renders} {seconds:.4} {:.4} {:.4} {:.4} {:.4}",
            d.average, d.r, d.g, d.b
        )
        .map_err(|e| Error::io(&self.path, e))
    }
}

/// Records a stage's trace, then passes each report on.
pub struct Recorder<'a> {
    trace: Trace,
    inner: &'a mut dyn Observer,
}

impl<'a> Recorder<'a> {
    /// A fresh trace, or the resumed stage's appended to.
    pub fn new(dir: &RunDir, append: bool, inner: &'a mut dyn Observer) -> Result<Recorder<'a>> {
        let trace = if append {
            Trace::append(dir)?
        } else {
            Trace::create(dir)?
        };
        Ok(Recorder { trace, inner })
    }
}

impl Observer for Recorder<'_> {
    fn generation(&mut self, r: &GenerationReport) -> Result<()> {
        self.trace
            .line(r.generation, r.evaluations, r.elapsed, &r.best)?;
        self.inner.generation(r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rundir::Mode;

    fn dev(a: f64) -> Deviation {
        Deviation {
            average: a,
            r: a,
            g: a,
            b: a,
        }
    }

    #[test]
    fn a_trace_has_one_header_whether_fresh_or_resumed() {
        let d = tempfile::tempdir().unwrap();
        let dir = RunDir::open(d.path(), Mode::Fresh).unwrap();
        Trace::create(&dir)
            .unwrap()
            .line(0, 10, 0.5, &dev(3.0))
            .unwrap();
        Trace::append(&dir)
            .unwrap()
            .line(1, 20, 1.25, &dev(2.0))
            .unwrap();
        let text = std::fs::read_to_string(dir.file(TRACE)).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], HEADER);
        assert_eq!(lines.iter().filter(|l| l.starts_with('#')).count(), 1);
        assert_eq!(lines[1], "0 10 0.5000 3.0000 3.0000 3.0000 3.0000");
        assert_eq!(lines[2], "1 20 1.2500 2.0000 2.0000 2.0000 2.0000");
        // A fresh trace replaces the old one.
        Trace::create(&dir).unwrap();
        let text = std::fs::read_to_string(dir.file(TRACE)).unwrap();
        assert_eq!(text.trim_end(), HEADER);
    }

    #[test]
    fn a_resumed_trace_without_a_file_begins_with_the_header() {
        let d = tempfile::tempdir().unwrap();
        let dir = RunDir::open(d.path(), Mode::Fresh).unwrap();
        Trace::append(&dir)
            .unwrap()
            .line(3, 4, 5.0, &dev(1.0))
            .unwrap();
        let text = std::fs::read_to_string(dir.file(TRACE)).unwrap();
        assert!(text.starts_with(HEADER), "{text}");
    }
}
