//! The run directory: the one owner of every file name a run writes or
//! reads back (fit, pipeline stages, report), of how they are written
//! (atomically, through `fsio`), of who may use the directory (one run at a
//! time, never a stranger's files destroyed), and of how a run's target is
//! found again later.
//!
//! A run directory is opened in one of three modes: a fresh run refuses a
//! directory that already holds files (an earlier run's results, a
//! checkpoint that `--resume` would continue) unless told to overwrite; a
//! resumed run needs the checkpoint; an overwriting run removes the earlier
//! run's files only once it is ready to write its own. While a run holds
//! the directory it keeps an advisory lock on `.scenefit.lock`, so that two
//! runs into one directory cannot both succeed.

mod lock;

use crate::error::{Error, Result};
use crate::fsio;
use crate::raster::{io as image_io, Image};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// result.json: the fitted parameters and the deviation (binding keys).
pub const RESULT: &str = "result.json";
/// fitted_scene.json: the scene with the fitted values in place.
pub const FITTED_SCENE: &str = "fitted_scene.json";
/// slurm-jobs.txt: the task-name prefixes of the run's Slurm sessions, so
/// that a later run in the directory cancels what a killed one left.
pub const SLURM_JOBS: &str = "slurm-jobs.txt";
/// best.png: the best render.
pub const BEST: &str = "best.png";
/// progress.txt: a line every few generations.
pub const PROGRESS: &str = "progress.txt";
/// checkpoint.json: what `--resume` continues from.
pub const CHECKPOINT: &str = "checkpoint.json";
/// failures.log: every failed render, with the renderer's stderr.
pub const FAILURES: &str = "failures.log";
/// trace.tsv: one line per generation with its time (the report's axis).
pub const TRACE: &str = "trace.tsv";
/// A set fit's state as earlier builds saved it (now in `CHECKPOINT`):
/// still resumed, and removed by `--overwrite`.
pub const SET_STATE: &str = "set_state.json";
/// A set fit's photographs, with absolute paths.
pub const SHOTS: &str = "shots.json";
/// A pipeline's copy of the target, and of the mask when one was given.
pub const TARGET: &str = "target.png";
pub const MASK: &str = "mask.png";
/// A pipeline's stage 2: the scene handed over, and its first render.
pub const INPUT_SCENE: &str = "input_scene.json";
pub const HANDOVER: &str = "handover.png";
/// A pipeline's stage 2 by space mapping: its state after every iteration
/// (what `--resume` continues from) and the fine render at its current point.
pub const SPACEMAP_STATE: &str = "spacemap.json";
pub const SPACEMAP_CURRENT: &str = "spacemap_current.png";
/// A pipeline's comparison of its stages.
pub const COMPARISON: &str = "comparison.json";
/// The HTML report and its figures' folder.
pub const REPORT: &str = "report.html";
pub const FIGURES: &str = "figures";
/// A diagnosis: diagnosis.json (the `Diagnosis` fields), the extended
/// scene with its refitted values, heatmaps of the residual before and
/// after (on one scale), and the render of the improved scene; its page
/// is `REPORT`.
pub const DIAGNOSIS_JSON: &str = "diagnosis.json";
pub const IMPROVED_SCENE: &str = "improved_scene.json";
pub const RESIDUAL_BEFORE: &str = "residual_before.png";
pub const RESIDUAL_AFTER: &str = "residual_after.png";
pub const RENDER_AFTER: &str = "render_after.png";
/// A pipeline's stage directories.
pub const STAGE1: &str = "stage1";
pub const STAGE2: &str = "stage2";
/// A pipeline's DE stage 2 run beside the mapped one for comparison
/// (`--stage2-method both`).
pub const STAGE2_DE: &str = "stage2_de";
/// The lock a run holds on its directory.
const LOCK: &str = ".scenefit.lock";

/// The best render of one photograph of a set.
pub fn shot_best_name(shot: &str) -> String {
    format!("best_{shot}.png")
}

/// A set diagnosis's per-photograph files: the render after, and the
/// residual heatmaps before and after (one scale for the whole set).
pub fn shot_render_after(shot: &str) -> String {
    format!("render_after_{shot}.png")
}
pub fn shot_residual_before(shot: &str) -> String {
    format!("residual_before_{shot}.png")
}
pub fn shot_residual_after(shot: &str) -> String {
    format!("residual_after_{shot}.png")
}

/// True for a name a diagnosis writes: what `diagnose --overwrite`
/// replaces, and what no input inside its output directory may be.
pub fn diagnosis_owns(name: &str) -> bool {
    let per_shot = |prefix: &str| {
        name.strip_prefix(prefix)
            .and_then(|n| n.strip_suffix(".png"))
            .is_some_and(|shot| !shot.is_empty())
    };
    [
        DIAGNOSIS_JSON,
        IMPROVED_SCENE,
        RESIDUAL_BEFORE,
        RESIDUAL_AFTER,
        RENDER_AFTER,
        REPORT,
    ]
    .contains(&name)
        || per_shot("render_after_")
        || per_shot("residual_before_")
        || per_shot("residual_after_")
}

/// The snapshots' names as a reader is told them.
pub const SNAPSHOTS: &str = "best_gNNNN.bmp";

/// True for a name `shot_best_name` gives (a set's render of a photograph).
fn is_shot_best(name: &str) -> bool {
    name.strip_prefix("best_")
        .and_then(|n| n.strip_suffix(".png"))
        .is_some_and(|shot| !shot.is_empty())
}

/// best_gNNNN.bmp: the best image at a generation, as the paper saved them.
pub fn snapshot_name(generation: usize) -> String {
    format!("best_g{generation:04}.bmp")
}

/// The generation of a snapshot file name, if it is one.
pub fn snapshot_generation(name: &str) -> Option<usize> {
    name.strip_prefix("best_g")?
        .strip_suffix(".bmp")?
        .parse()
        .ok()
}

/// The kind of run a directory holds: it decides which names are the
/// run's own (what `--overwrite` removes and what no input may be).
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    /// A fit: its results, logs, snapshots and a report of it.
    Fit,
    /// A pipeline: its copies of the target and mask, its comparison and
    /// report, and its stage directories (each a fit).
    Pipeline,
    /// A set fit (`fit --shots`): a fit's files, its state between
    /// blocks, its shots file and every photograph's best render.
    Set,
    /// Another command's directory (a diagnosis): the names it writes,
    /// as its own module lists them (rundir imports none of them).
    Named(fn(&str) -> bool),
}

impl Kind {
    fn owns(self, name: &str) -> bool {
        let fit = snapshot_generation(name).is_some()
            || [
                RESULT,
                FITTED_SCENE,
                BEST,
                PROGRESS,
                CHECKPOINT,
                FAILURES,
                TRACE,
                REPORT,
            ]
            .contains(&name);
        match self {
            Kind::Fit => fit,
            Kind::Pipeline => {
                fit || [TARGET, MASK, INPUT_SCENE, HANDOVER, COMPARISON].contains(&name)
            }
            Kind::Set => fit || name == SET_STATE || name == SHOTS || is_shot_best(name),
            Kind::Named(owns) => owns(name),
        }
    }

    fn owns_dir(self, name: &str) -> bool {
        name == FIGURES
            || (matches!(self, Kind::Pipeline)
                && (name == STAGE1 || name == STAGE2 || name == STAGE2_DE))
    }
}

/// How a run treats what is already in its directory.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Mode {
    /// The directory must be new or empty.
    #[default]
    Fresh,
    /// Continue from the checkpoint in the directory.
    Resume,
    /// Replace an earlier run's files (once this run is ready to write).
    Overwrite,
}

/// A run's directory, held (locked) for as long as the value lives.
#[derive(Debug)]
pub struct RunDir {
    path: PathBuf,
    kind: Kind,
    _lock: Option<lock::Lock>,
}

impl RunDir {
    /// Opens `path` for a run in `mode`: creates it, takes its lock, and
    /// refuses a directory whose files this run would silently replace.
    pub fn open(path: &Path, mode: Mode) -> Result<RunDir> {
        RunDir::open_as(path, mode, Kind::Fit)
    }

    /// As `open`, for a run of `kind`.
    pub fn open_as(path: &Path, mode: Mode, kind: Kind) -> Result<RunDir> {
        if path.exists() && !path.is_dir() {
            return Err(Error::Usage(format!(
                "{}: the output must be a directory, and this is a file",
                path.display()
            )));
        }
        std::fs::create_dir_all(path).map_err(|e| Error::io(path, e))?;
        let lock = lock::Lock::take(&path.join(LOCK))?;
        let dir = RunDir {
            path: path.to_path_buf(),
            kind,
            _lock: Some(lock),
        };
        dir.remove_stale_temps();
        match mode {
            Mode::Fresh => dir.require_empty()?,
            Mode::Resume => dir.require_state()?,
            Mode::Overwrite => {}
        }
        Ok(dir)
    }

    /// A finished run's directory that a command adds to (a report):
    /// it must exist, and it is locked so that no run is writing it.
    pub fn update(path: &Path, kind: Kind) -> Result<RunDir> {
        if !path.is_dir() {
            return Err(Error::Usage(format!(
                "{}: not a directory of a scenefit run",
                path.display()
            )));
        }
        RunDir::open_as(path, Mode::Overwrite, kind)
    }

    /// A directory to read a finished run from, without a lock.
    pub fn existing(path: &Path) -> Result<RunDir> {
        if !path.is_dir() {
            return Err(Error::Usage(format!(
                "{}: not a directory of a scenefit run",
                path.display()
            )));
        }
        Ok(RunDir {
            path: path.to_path_buf(),
            kind: Kind::Fit,
            _lock: None,
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The path of one of the run's files.
    pub fn file(&self, name: &str) -> PathBuf {
        self.path.join(name)
    }

    /// A sub-directory of this run (a pipeline's stage), held by the same lock.
    pub fn sub(&self, name: &str) -> Result<RunDir> {
        let path = self.file(name);
        std::fs::create_dir_all(&path).map_err(|e| Error::io(&path, e))?;
        Ok(RunDir {
            path,
            kind: Kind::Fit,
            _lock: None,
        })
    }

    /// Removes temporary files a killed run left (it held the lock this
    /// run holds now, so none is being written).
    fn remove_stale_temps(&self) {
        let Ok(entries) = std::fs::read_dir(&self.path) else {
            return;
        };
        for e in entries.flatten() {
            if fsio::is_temp_name(&e.file_name().to_string_lossy()) {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }

    /// What `--resume` continues from: the state file of this kind of run.
    fn require_state(&self) -> Result<()> {
        let (states, stage1): (&[&str], bool) = match self.kind {
            Kind::Fit => (&[CHECKPOINT], false),
            Kind::Pipeline => (&[CHECKPOINT], true),
            Kind::Set => (&[CHECKPOINT, SET_STATE], false),
            Kind::Named(_) => (&[], false),
        };
        let stage1 = stage1 && self.path.join(STAGE1).join(CHECKPOINT).is_file();
        if stage1 || states.iter().any(|s| self.file(s).is_file()) {
            return Ok(());
        }
        Err(Error::Usage(format!(
            "{}: nothing to resume (no {}); run without --resume to start afresh",
            self.path.display(),
            states.first().copied().unwrap_or("saved state")
        )))
    }

    fn require_empty(&self) -> Result<()> {
        let entries = std::fs::read_dir(&self.path).map_err(|e| Error::io(&self.path, e))?;
        let mut names: Vec<String> = entries
            .flatten()
            .map(|e| e.file_name().to_string_lossy().to_string())
            .filter(|n| n != LOCK)
            .collect();
        if names.is_empty() {
            return Ok(());
        }
        names.sort();
        let what = if names.iter().any(|n| n == CHECKPOINT || n == SET_STATE) {
            "an earlier run's checkpoint"
        } else {
            "files"
        };
        let resume = match self.kind {
            Kind::Named(_) => "",
            _ => "--resume to continue that run, ",
        };
        Err(Error::Usage(format!(
            "{}: the output directory already holds {what} ({}{}); pass {resume}--overwrite to replace it, or choose another directory",
            self.path.display(),
            names.iter().take(3).cloned().collect::<Vec<_>>().join(", "),
            if names.len() > 3 { ", …" } else { "" }
        )))
    }

    /// Removes an earlier run's files (those a run writes, nothing else),
    /// for `--overwrite`, once the new run is ready to write its own.
    pub fn clear(&self) -> Result<()> {
        let entries = std::fs::read_dir(&self.path).map_err(|e| Error::io(&self.path, e))?;
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().to_string();
            let p = e.path();
            if self.kind.owns(&name) {
                std::fs::remove_file(&p).map_err(|err| Error::io(&p, err))?;
            } else if self.kind.owns_dir(&name) && p.is_dir() {
                std::fs::remove_dir_all(&p).map_err(|err| Error::io(&p, err))?;
            }
        }
        Ok(())
    }

    /// Refuses an input file (`what`: the option that named it) that this
    /// run would overwrite: one of the run's own file names in its directory.
    pub fn refuse_overwritten_input(&self, input: &Path, what: &str) -> Result<()> {
        let (Ok(input), Ok(dir)) = (input.canonicalize(), self.path.canonicalize()) else {
            return Ok(());
        };
        let inside = input.parent().is_some_and(|p| p.starts_with(&dir));
        let name = input.file_name().map(|n| n.to_string_lossy().to_string());
        if inside && name.as_deref().is_some_and(|n| self.kind.owns(n)) {
            return Err(Error::Usage(format!(
                "{what} {}: this file is inside the output directory and the run would overwrite it; copy it elsewhere first",
                input.display()
            )));
        }
        Ok(())
    }

    /// Writes a JSON file of the run, atomically.
    pub fn write_json<T: Serialize + ?Sized>(&self, name: &str, value: &T) -> Result<()> {
        let text = serde_json::to_string_pretty(value)
            .map_err(|e| Error::Run(format!("cannot encode {name}: {e}")))?;
        fsio::write_atomic(&self.file(name), text.as_bytes())
    }

    /// Writes a text file of the run, atomically.
    pub fn write_text(&self, name: &str, text: &str) -> Result<()> {
        fsio::write_atomic(&self.file(name), text.as_bytes())
    }

    /// Writes an image of the run, atomically.
    pub fn write_image(&self, name: &str, image: &Image) -> Result<()> {
        image_io::write_image(image, &self.file(name))
    }

    /// Reads a JSON file of the run; the error names the file and says it
    /// is not what a run writes.
    pub fn read_json<T: DeserializeOwned>(&self, name: &str, what: &str) -> Result<T> {
        let path = self.file(name);
        let text = fsio::read_text_capped(&path, fsio::MAX_JSON_BYTES)?;
        serde_json::from_str(&text).map_err(|e| {
            Error::invalid(
                path.display().to_string(),
                "(top level)",
                format!("not {what} ({e})"),
            )
        })
    }

    /// Reads an image of the run.
    pub fn read_image(&self, name: &str) -> Result<Image> {
        image_io::read_image(&self.file(name), name)
    }

    /// Finds the target a run was fitted to from what its result.json
    /// recorded: as recorded (absolute, or relative to where the run was
    /// started), then relative to the run directory and its parent, then by
    /// its name inside the run directory (a pipeline keeps a copy).
    pub fn find_target(&self, recorded: Option<&str>) -> Result<PathBuf> {
        let Some(t) = recorded else {
            return Err(Error::Usage(format!(
                "{}: {RESULT} names no target; give --target",
                self.path.display()
            )));
        };
        let given = PathBuf::from(t);
        let mut tries = vec![given.clone()];
        if given.is_relative() {
            tries.push(self.path.join(&given));
            if let Some(parent) = self.path.parent() {
                tries.push(parent.join(&given));
            }
            if let Some(name) = given.file_name() {
                tries.push(self.path.join(name));
            }
        }
        tries.into_iter().find(|p| p.is_file()).ok_or_else(|| {
            Error::Usage(format!(
                "{}: the target {t} named in {RESULT} is not found from here; give --target",
                self.path.display()
            ))
        })
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_diagnosis_owns_every_name_it_writes_and_nothing_else() {
        for n in [
            DIAGNOSIS_JSON.to_string(),
            REPORT.into(),
            shot_render_after("s1"),
            shot_residual_before("s1"),
            shot_residual_after("s1"),
        ] {
            assert!(diagnosis_owns(&n), "{n}");
        }
        for n in ["photo.png", "render_after_.png", "notes.txt", "result.json"] {
            assert!(!diagnosis_owns(n), "{n}");
        }
    }

    use super::*;

    #[test]
    fn a_fresh_run_refuses_an_earlier_runs_files() {
        let d = tempfile::tempdir().unwrap();
        std::fs::write(d.path().join(CHECKPOINT), "{}").unwrap();
        let e = RunDir::open(d.path(), Mode::Fresh).unwrap_err().to_string();
        assert!(e.contains("--resume") && e.contains("--overwrite"), "{e}");
        assert!(RunDir::open(d.path(), Mode::Resume).is_ok());
    }

    #[test]
    fn a_killed_runs_temporary_files_are_removed() {
        let d = tempfile::tempdir().unwrap();
        std::fs::write(d.path().join(".checkpoint.json.tmp.123.0"), "x").unwrap();
        let _dir = RunDir::open(d.path(), Mode::Fresh).unwrap();
        assert!(!d.path().join(".checkpoint.json.tmp.123.0").exists());
    }

    #[test]
    fn one_run_at_a_time() {
        let d = tempfile::tempdir().unwrap();
        let held = RunDir::open(d.path(), Mode::Fresh).unwrap();
        let e = RunDir::open(d.path(), Mode::Overwrite)
            .unwrap_err()
            .to_string();
        assert!(e.contains("in use"), "{e}");
        drop(held);
        assert!(RunDir::open(d.path(), Mode::Overwrite).is_ok());
    }

    #[test]
    fn overwrite_removes_only_run_files() {
        let d = tempfile::tempdir().unwrap();
        for n in [RESULT, "best_g0010.bmp", "notes.txt"] {
            std::fs::write(d.path().join(n), "x").unwrap();
        }
        let dir = RunDir::open(d.path(), Mode::Overwrite).unwrap();
        dir.clear().unwrap();
        assert!(d.path().join("notes.txt").exists());
        assert!(!d.path().join(RESULT).exists());
        assert!(!d.path().join("best_g0010.bmp").exists());
    }

    #[test]
    fn inputs_the_run_would_overwrite_are_refused() {
        let d = tempfile::tempdir().unwrap();
        let dir = RunDir::open(d.path(), Mode::Overwrite).unwrap();
        std::fs::write(d.path().join(BEST), "x").unwrap();
        std::fs::write(d.path().join("photo.png"), "x").unwrap();
        assert!(dir
            .refuse_overwritten_input(&d.path().join(BEST), "--target")
            .is_err());
        assert!(dir
            .refuse_overwritten_input(&d.path().join("photo.png"), "--target")
            .is_ok());
    }
}
