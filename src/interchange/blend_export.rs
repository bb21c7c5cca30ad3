//! `scenefit export SCENE.json --to blender -o OUT.blend`: the scene as a
//! .blend saved by Blender, built by the Blender backend's own worker code
//! (blender_scripts/export_blend.py), so that Blender renders it as
//! scenefit's Blender backend does (docs/interchange.md, "Blender").
//! What the backend refuses is refused here too; the texture maps are
//! the worker's own nodes, their decoded images packed into the file.

use super::blend_run;
use crate::error::{Error, Result};
use crate::scene::Scene;
use std::path::Path;

/// Writes `out` (a new .blend) from the scene file `scene_path`.
pub fn export(scene_path: &Path, out: &Path) -> Result<()> {
    check_output(out)?;
    let scene = crate::scene::load(scene_path)?;
    let file = scene_path.display().to_string();
    refuse_undrawn(&scene, &file)?;
    let mut value = serde_json::to_value(&scene)
        .map_err(|e| Error::Run(format!("cannot serialise the scene: {e}")))?;
    // the .blend carries each material as the user wrote it
    crate::scene::written::drop_default_material_fields(&mut value);
    let dir = tempfile::Builder::new()
        .prefix("scenefit-export-")
        .tempdir()
        .map_err(|e| Error::Run(format!("cannot make a temporary directory: {e}")))?;
    let json = dir.path().join("scene.json");
    crate::fsio::write_atomic(&json, value.to_string().as_bytes())?;
    let target = std::path::absolute(out).map_err(|e| Error::io(out, e))?;
    blend_run::run(
        dir.path(),
        None,
        "export_blend.py",
        &[json.into_os_string(), target.clone().into_os_string()],
    )?;
    if !target.is_file() {
        return Err(Error::Run(format!(
            "Blender did not write {}",
            target.display()
        )));
    }
    Ok(())
}

/// OUT ends in .blend, does not exist yet (an export never replaces a
/// file: it may be the user's own scene) and its directory does.
fn check_output(out: &Path) -> Result<()> {
    let shown = out.display();
    if out.extension().and_then(|e| e.to_str()) != Some("blend") {
        return Err(Error::Usage(format!(
            "-o {shown}: expected a file name ending in .blend"
        )));
    }
    if out.symlink_metadata().is_ok() {
        return Err(Error::Usage(format!(
            "-o {shown}: exists; expected a new file name (export never replaces a file)"
        )));
    }
    let parent = out.parent().filter(|p| !p.as_os_str().is_empty());
    if parent.is_some_and(|p| !p.is_dir()) {
        return Err(Error::Usage(format!(
            "-o {shown}: its directory does not exist"
        )));
    }
    Ok(())
}

/// The Blender backend's refusals: the export draws what the backend
/// draws (its worker builds the .blend), every texture map included.
fn refuse_undrawn(scene: &Scene, file: &str) -> Result<()> {
    let (backend, _) = crate::render::registry::find("blender")?;
    match (backend.supports)(scene).first() {
        Some(r) => Err(Error::invalid(
            file,
            r.field.clone(),
            format!("cannot be exported to Blender: {}", r.why),
        )),
        None => Ok(()),
    }
}
