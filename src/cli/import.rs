//! `scenefit import FILE -o SCENE.json [--free GLOB]...`: another tool's
//! scene (a Mitsuba 3 XML file; a .blend file) as a scenefit scene, its
//! meshes and textures written into `SCENE_assets/` beside it, the fields
//! a spec matches made free (docs/interchange.md).

use crate::error::{Error, Result};
use crate::interchange::{formats, free_spec, scene_files};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ImportArgs {
    /// The file to read: .xml (Mitsuba 3) or .blend (Blender).
    file: PathBuf,
    /// The scene to write (JSON; a new file).
    #[arg(short, long)]
    output: PathBuf,
    /// Make the fields this glob matches free at their default bounds
    /// (`lights.*.position`; as `scenefit free`); repeatable.
    #[arg(long = "free", value_name = "GLOB")]
    free: Vec<String>,
    /// The Python with the renderer's package (default python3; env
    /// SCENEFIT_PYTHON).
    #[arg(long, value_name = "PROGRAM")]
    python: Option<PathBuf>,
}

pub fn run(a: ImportArgs) -> Result<()> {
    let importer = formats::importer_for(&a.file)?;
    if importer.name == formats::BLENDER {
        // Blender's import keeps its own output rules for now (meshes
        // beside the scene; docs/interchange.md "Blender").
        let warnings = crate::interchange::blend_import::import(&a.file, &a.output, &a.free)?;
        for w in &warnings {
            eprintln!("warning: {w}");
        }
        println!("{} written", a.output.display());
        return Ok(());
    }
    let python = super::export::python(a.python.clone())?;
    let assets = scene_files::import_paths(&a.file, &a.output)?;
    let job = scene_files::ImportJob {
        input: &a.file,
        output: &a.output,
        assets: &assets,
        python: &python,
    };
    let written = (importer.run)(&job).and_then(|imported| write(&a, imported));
    // an empty assets directory (no mesh, no texture) is not left behind;
    // a failed import leaves nothing
    let empty = std::fs::read_dir(&assets).map(|mut d| d.next().is_none());
    if written.is_err() {
        let _ = std::fs::remove_dir_all(&assets);
    } else if empty.unwrap_or(false) {
        let _ = std::fs::remove_dir(&assets);
    }
    written
}

/// Checks the imported scene as a scene, adds the `--free` entries and
/// writes it (paths relative to its directory, as the importer wrote them).
fn write(a: &ImportArgs, imported: scene_files::Imported) -> Result<()> {
    let out = a.output.display().to_string();
    let mut value = imported.scene;
    let mut scene = crate::scene::load::from_value(value.clone(), &out)?;
    let added = free_spec::apply(&mut scene, &a.free, &a.file.display().to_string())?;
    if !added.is_empty() {
        value["free"] = serde_json::to_value(&scene.free)
            .map_err(|e| Error::Run(format!("cannot serialise the free list: {e}")))?;
        crate::scene::load::from_value(value.clone(), &out)?;
    }
    let text = serde_json::to_string_pretty(&value)
        .map_err(|e| Error::Run(format!("cannot serialise the scene: {e}")))?;
    crate::fsio::write_atomic(&a.output, format!("{text}\n").as_bytes())?;
    for w in &imported.warnings {
        eprintln!("warning: {w}");
    }
    for p in &added {
        println!("free: {p}");
    }
    println!(
        "{} objects, {} lights; {} written",
        scene.objects.len(),
        scene.lights.len(),
        a.output.display()
    );
    Ok(())
}
