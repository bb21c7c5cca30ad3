//! What an importer and an exporter of another tool's scene are (the
//! tables of them: `formats`), and the rules every format follows for its
//! output: an export writes into a
//! new or empty directory, an import writes its meshes and textures into
//! a new directory beside the scene it writes, and neither overwrites an
//! input (docs/interchange.md).

use crate::error::{Error, Result};
use crate::scene::Scene;
use std::path::{Path, PathBuf};

/// What an importer is given.
pub struct ImportJob<'a> {
    /// The other tool's file.
    pub input: &'a Path,
    /// The scene file to be written; meshes and textures go in `assets`.
    pub output: &'a Path,
    /// A new directory beside `output` for meshes and textures, which the
    /// scene names relative to `output`'s directory.
    pub assets: &'a Path,
    /// The Python (with the renderer's package) that reads the file.
    pub python: &'a Path,
}

/// What an importer returns: the scene as JSON (paths relative to the
/// output's directory) and one warning per kind of thing not mapped.
pub struct Imported {
    pub scene: serde_json::Value,
    pub warnings: Vec<String>,
}

/// A format `scenefit import` reads.
pub struct Importer {
    /// The format's name in messages.
    pub name: &'static str,
    /// The file extensions it is chosen by (lower case, without the dot).
    pub extensions: &'static [&'static str],
    pub run: fn(&ImportJob) -> Result<Imported>,
}

/// What an exporter is given: the scene as loaded (validated, paths
/// absolute) and a new or empty directory to write into.
pub struct ExportJob<'a> {
    pub scene: &'a Scene,
    /// The scene's file, for messages.
    pub scene_file: &'a Path,
    pub out: &'a Path,
    pub python: &'a Path,
}

/// What an exporter returns: the main file written and one warning per
/// kind of field the file cannot hold.
pub struct Exported {
    pub main: PathBuf,
    pub warnings: Vec<String>,
}

/// A format `scenefit export --to NAME` writes.
pub struct Exporter {
    pub name: &'static str,
    pub run: fn(&ExportJob) -> Result<Exported>,
}

/// Makes `out` a new, empty directory for an export, refusing one that
/// holds anything (an export never mixes its files with others) and one
/// that is or holds an input. Returns whether it made the directory.
pub fn export_dir(out: &Path, inputs: &[&Path]) -> Result<bool> {
    let existed = out.exists();
    if existed {
        if !out.is_dir() {
            return Err(Error::Usage(format!(
                "-o {}: exists and is not a directory; expected a new or empty directory",
                out.display()
            )));
        }
        let mut entries = std::fs::read_dir(out).map_err(|e| Error::io(out, e))?;
        if entries.next().is_some() {
            return Err(Error::Usage(format!(
                "-o {}: is not empty; expected a new or empty directory",
                out.display()
            )));
        }
    }
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    let dir = std::fs::canonicalize(out).map_err(|e| Error::io(out, e))?;
    for input in inputs {
        if let Ok(p) = std::fs::canonicalize(input) {
            if p.starts_with(&dir) {
                return Err(Error::Usage(format!(
                    "-o {}: holds the input {}; expected a directory of its own",
                    out.display(),
                    input.display()
                )));
            }
        }
    }
    Ok(!existed)
}

/// Removes what a failed export wrote into `out` (which held nothing
/// before it), and `out` itself when the export `made` it.
pub fn empty_out(out: &Path, made: bool) {
    if made {
        let _ = std::fs::remove_dir_all(out);
        return;
    }
    if let Ok(entries) = std::fs::read_dir(out) {
        for e in entries.flatten() {
            let p = e.path();
            let _ = if p.is_dir() {
                std::fs::remove_dir_all(&p)
            } else {
                std::fs::remove_file(&p)
            };
        }
    }
}

/// The directory for an import's meshes and textures: `<stem>_assets`
/// beside `output`. Refuses an output that exists (an import never
/// overwrites a file) and an assets directory that is not new or empty.
pub fn import_paths(input: &Path, output: &Path) -> Result<PathBuf> {
    if output.exists() {
        return Err(Error::Usage(format!(
            "-o {}: exists; expected a new file name (an import overwrites nothing)",
            output.display()
        )));
    }
    let stem = output
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    let parent = output.parent().unwrap_or(Path::new(""));
    let assets = parent.join(format!("{stem}_assets"));
    export_dir(&assets, &[input])?;
    Ok(assets)
}
