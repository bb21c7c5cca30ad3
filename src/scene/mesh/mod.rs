//! `{"type": "mesh", "file": "model.ply"}`: a triangle mesh read from a
//! PLY (ASCII or binary, either byte order) or OBJ file. A scene holds
//! only the path (made absolute when the scene is read, relative to the
//! scene file, as `albedo_map` is); the triangles are read once per
//! process and shared, since a fit clones the scene for every candidate.
//!
//! What is kept: positions, per-vertex normals when the file has them (for
//! smooth shading; face normals otherwise), per-vertex texture coordinates
//! when it has them (for textures), and triangles (polygons fanned).
//! Every file is read through `input::read_capped`; declared counts are
//! checked against the file's size before anything is allocated.

mod data;
mod obj;
mod ply;

pub use data::Mesh;

use crate::error::{Error, Result};
use crate::input::{read_capped, CappedRead, MAX_MESH_BYTES};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

type Cache = Mutex<HashMap<PathBuf, Arc<Mesh>>>;

fn cache() -> &'static Cache {
    static CACHE: OnceLock<Cache> = OnceLock::new();
    CACHE.get_or_init(Default::default)
}

/// The mesh at `path` (absolute, as the scene holds it), read once per
/// process. Errors are one line naming the file.
pub fn get(path: &Path) -> Result<Arc<Mesh>> {
    if let Some(m) = cache().lock().expect("mesh cache").get(path) {
        return Ok(m.clone());
    }
    let mesh = Arc::new(read(path)?);
    cache()
        .lock()
        .expect("mesh cache")
        .insert(path.to_path_buf(), mesh.clone());
    Ok(mesh)
}

/// Reads and checks the mesh file at `path`, by its extension (`.ply`,
/// `.obj`, any case) or, failing that, by a PLY file's first line.
pub fn read(path: &Path) -> Result<Mesh> {
    let bad = |m: String| Error::Usage(format!("{}: {m}", path.display()));
    let bytes = read_capped(path, MAX_MESH_BYTES).map_err(|e| match e {
        CappedRead::Io(e) if e.kind() == std::io::ErrorKind::InvalidInput => bad(e.to_string()),
        CappedRead::Io(e) => Error::io(path, e),
        CappedRead::Directory => bad("a directory; expected a PLY or OBJ mesh file".into()),
        CappedRead::TooLarge => bad(format!(
            "too large; expected a mesh file of at most {} MiB",
            MAX_MESH_BYTES >> 20
        )),
    })?;
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let mesh = match ext.as_deref() {
        Some("obj") => obj::parse(&bytes),
        Some("ply") => ply::parse(&bytes),
        _ if bytes.starts_with(b"ply") => ply::parse(&bytes),
        _ => Err("expected a .ply or .obj mesh file".into()),
    }
    .map_err(|m| bad(format!("not a readable mesh: {m}")))?;
    mesh.check()
        .map_err(|m| bad(format!("not a usable mesh: {m}")))?;
    Ok(mesh)
}

/// Checks the mesh of a scene's object at load time, so that a bad file
/// is refused with the scene's file and key before anything renders.
pub fn check(path: &Path, file: &str, key: &str) -> Result<()> {
    get(path).map(|_| ()).map_err(|e| match e {
        Error::Io { path, source } => {
            Error::invalid(file, key, format!("{}: {source}", path.display()))
        }
        other => Error::invalid(file, key, other.to_string()),
    })
}

#[cfg(test)]
mod tests;
