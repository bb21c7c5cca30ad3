//! Saving and restoring a [`De`] run as JSON, so a long fit can stop and
//! resume exactly where it was.
//!
//! The file holds the full state, generator included, with every float as
//! its bit pattern (see `exact.rs`), so a resumed run is bit-identical to
//! one that never stopped. A `summary` in plain numbers (generation, best
//! fitness and vector) sits beside it for people; loading ignores it. Saving writes a temporary file in the target's
//! directory and renames it over the target: a crash mid-save leaves the
//! previous checkpoint intact, never a half-written one.

use std::fs::{self, File};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::De;

/// Format marker, so a file from some other tool or a future layout is
/// refused with a clear message.
const FORMAT: &str = "scenefit-de-checkpoint";
const VERSION: u32 = 1;

#[derive(Serialize)]
struct FileOut<'a> {
    format: &'a str,
    version: u32,
    summary: Summary<'a>,
    state: &'a De,
}

/// Plain-number progress for a person reading the file; the bit-encoded
/// `state` is what [`load`] uses, and it ignores this.
#[derive(Serialize)]
struct Summary<'a> {
    strategy: String,
    generation: usize,
    evaluations: usize,
    /// None (null) while every evaluation has failed.
    best_fitness: Option<f64>,
    best: &'a [f64],
}

impl<'a> Summary<'a> {
    fn of(de: &'a De) -> Self {
        let (best, fitness) = de.best();
        Summary {
            strategy: de.config().strategy.to_string(),
            generation: de.generation(),
            evaluations: de.evaluations(),
            best_fitness: fitness.is_finite().then_some(fitness),
            best,
        }
    }
}

#[derive(Deserialize)]
struct Header {
    format: String,
    version: u32,
}

#[derive(Deserialize)]
struct FileIn {
    state: De,
}

/// A checkpoint could not be written or read.
#[derive(Debug, Error)]
pub enum CheckpointError {
    #[error("cannot {action} checkpoint {}: {source}", path.display())]
    Io {
        action: &'static str,
        path: PathBuf,
        source: io::Error,
    },
    #[error("cannot encode checkpoint {}: {source}", path.display())]
    Encode {
        path: PathBuf,
        source: serde_json::Error,
    },
    #[error("checkpoint {} is not a valid DE state: {source}", path.display())]
    Decode {
        path: PathBuf,
        source: serde_json::Error,
    },
    #[error("{} is not a scenefit DE checkpoint (format `{found}` version {version}; expected `{FORMAT}` version {VERSION})", path.display())]
    Format {
        path: PathBuf,
        found: String,
        version: u32,
    },
}

/// Writes `de` to `path` atomically.
pub fn save(path: impl AsRef<Path>, de: &De) -> Result<(), CheckpointError> {
    let path = path.as_ref();
    let temp = temp_path(path);
    let result = write_file(&temp, de).and_then(|()| {
        fs::rename(&temp, path).map_err(|source| CheckpointError::Io {
            action: "move into place",
            path: path.to_path_buf(),
            source,
        })
    });
    if result.is_err() {
        // Best effort: the temp file is ours and useless now; the error
        // that matters is the one being returned.
        let _ = fs::remove_file(&temp);
    }
    result
}

/// Reads a state written by [`save`].
pub fn load(path: impl AsRef<Path>) -> Result<De, CheckpointError> {
    let path = path.as_ref();
    let text = fs::read_to_string(path).map_err(|source| CheckpointError::Io {
        action: "read",
        path: path.to_path_buf(),
        source,
    })?;
    let decode = |source| CheckpointError::Decode {
        path: path.to_path_buf(),
        source,
    };
    // The header is read first so a foreign file gets a format message
    // rather than a confusing complaint about some missing field.
    let header: Header = serde_json::from_str(&text).map_err(decode)?;
    if header.format != FORMAT || header.version != VERSION {
        return Err(CheckpointError::Format {
            path: path.to_path_buf(),
            found: header.format,
            version: header.version,
        });
    }
    let file: FileIn = serde_json::from_str(&text).map_err(decode)?;
    Ok(file.state)
}

/// A sibling of `path` (same directory, so the rename cannot cross file
/// systems), hidden and marked with our process id so two processes
/// saving at once do not share it.
fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "checkpoint".to_string());
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

fn write_file(temp: &Path, de: &De) -> Result<(), CheckpointError> {
    let io_error = |action| {
        move |source| CheckpointError::Io {
            action,
            path: temp.to_path_buf(),
            source,
        }
    };
    let file = File::create(temp).map_err(io_error("create"))?;
    let mut writer = BufWriter::new(file);
    let contents = FileOut {
        format: FORMAT,
        version: VERSION,
        summary: Summary::of(de),
        state: de,
    };
    serde_json::to_writer(&mut writer, &contents).map_err(|source| CheckpointError::Encode {
        path: temp.to_path_buf(),
        source,
    })?;
    writer.flush().map_err(io_error("write"))?;
    // Flushed to disk before the rename, or a power cut could leave the
    // new name pointing at empty data.
    writer.get_ref().sync_all().map_err(io_error("sync"))?;
    Ok(())
}
