//! `scenefit import FILE.blend -o scene.json [--free GLOB...]`: a .blend's
//! active scene read by Blender itself (blender_scripts/import_blend.py,
//! headless, the file's own scripts not run) into a scenefit scene, its
//! meshes written as PLY files beside the scene (docs/interchange.md,
//! "Blender": what each datablock becomes, and what is not read). The
//! file is checked to be a .blend before Blender opens it; the scene
//! Blender's script returns is validated as any scene file before it is
//! written.

use super::blend_run;
use crate::error::{Error, Result};
use std::path::Path;

/// The largest .blend read (the file is Blender's to read; this only
/// bounds what a user can point scenefit at by mistake).
const MAX_BLEND_BYTES: u64 = 8 << 30;

/// Reads `file` and writes the scene `out` (JSON) with its meshes beside
/// it; `free` frees the fields its globs match (`scenefit free`). Returns
/// the warnings (one per kind of thing not mapped).
pub fn import(file: &Path, out: &Path, free: &[String]) -> Result<Vec<String>> {
    check_blend(file)?;
    let (dir_out, stem) = output_place(file, out)?;
    crate::exec::discover::find("blender", &crate::exec::discover::apt_hint("blender"))
        .map_err(|e| Error::Usage(format!("{}: Blender reads it: {e}", file.display())))?;
    let dir = tempfile::Builder::new()
        .prefix("scenefit-import-")
        .tempdir()
        .map_err(|e| Error::Run(format!("cannot make a temporary directory: {e}")))?;
    let result = dir.path().join("import.json");
    let blend = std::path::absolute(file).map_err(|e| Error::io(file, e))?;
    blend_run::run(
        dir.path(),
        Some(&blend),
        "import_blend.py",
        &[
            result.clone().into_os_string(),
            dir_out.into_os_string(),
            stem.into(),
        ],
    )?;
    let text = crate::input::read_text_capped(&result, crate::input::MAX_JSON_BYTES)?;
    let mut answer: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| Error::Run(format!("import_blend.py answered no JSON: {e}")))?;
    let warnings: Vec<String> = answer["warnings"]
        .as_array()
        .map(|w| {
            w.iter()
                .filter_map(|s| s.as_str().map(String::from))
                .collect()
        })
        .unwrap_or_default();
    let mut value = answer["scene"].take();
    crate::scene::written::drop_default_material_fields(&mut value);
    let shown = out.display().to_string();
    // validated as the scene file it becomes (mesh paths relative to it)
    let mut scene = crate::scene::load::from_value(value.clone(), &shown)?;
    if !free.is_empty() {
        super::free_spec::apply(&mut scene, free, &file.display().to_string())?;
        value["free"] = serde_json::to_value(&scene.free)
            .map_err(|e| Error::Run(format!("cannot serialise the free list: {e}")))?;
    }
    let text = serde_json::to_string_pretty(&value)
        .map_err(|e| Error::Run(format!("cannot serialise the scene: {e}")))?;
    crate::fsio::write_atomic(out, format!("{text}\n").as_bytes())?;
    Ok(warnings)
}

/// A regular file, within the size cap, starting as a .blend does:
/// `BLENDER` uncompressed, or Blender's compressed forms (gzip before
/// 3.0, Zstandard since).
fn check_blend(file: &Path) -> Result<()> {
    let expected = "a .blend file saved by Blender";
    let (head, len) = crate::input::read_head(file, 8)
        .map_err(|e| crate::input::capped_error(file, e, expected))?;
    if len > MAX_BLEND_BYTES {
        return Err(Error::Usage(format!(
            "{}: {len} bytes, over the {} GiB read; expected {expected}",
            file.display(),
            MAX_BLEND_BYTES >> 30
        )));
    }
    let blend = head.starts_with(b"BLENDER")
        || head.starts_with(&[0x1f, 0x8b])
        || head.starts_with(&[0x28, 0xb5, 0x2f, 0xfd]);
    if !blend {
        return Err(Error::Usage(format!(
            "{}: not a .blend file (it does not start with BLENDER nor Blender's compression); expected {expected}",
            file.display()
        )));
    }
    Ok(())
}

/// The directory the meshes go to (the scene's) and the scene's file stem;
/// `out` must end in .json, its directory exist, and not be the input.
fn output_place(file: &Path, out: &Path) -> Result<(std::path::PathBuf, String)> {
    let shown = out.display();
    let stem = out
        .file_stem()
        .and_then(|s| s.to_str())
        .filter(|_| out.extension().is_some_and(|e| e == "json"));
    let Some(stem) = stem else {
        return Err(Error::Usage(format!(
            "-o {shown}: expected a scene file name ending in .json"
        )));
    };
    let parent = out.parent().filter(|p| !p.as_os_str().is_empty());
    let dir =
        std::path::absolute(parent.unwrap_or(Path::new("."))).map_err(|e| Error::io(out, e))?;
    if !dir.is_dir() {
        return Err(Error::Usage(format!(
            "-o {shown}: its directory does not exist"
        )));
    }
    if std::fs::canonicalize(out).ok() == std::fs::canonicalize(file).ok() && out.exists() {
        return Err(Error::Usage(format!(
            "-o {shown}: is the file read; expected a new file name"
        )));
    }
    Ok((dir, stem.to_string()))
}
