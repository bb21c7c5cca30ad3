//! `scenefit export SCENE.json --to mitsuba|blender -o OUT`: a scene as
//! another tool's file, drawn there as scenefit's backend for that tool
//! draws it (docs/interchange.md).

use crate::error::Result;
use crate::interchange::{formats, scene_files};
use crate::render::RenderOptions;
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct ExportArgs {
    /// The scene file (JSON).
    scene: PathBuf,
    /// The format: mitsuba (XML, meshes, textures) or blender (.blend).
    #[arg(long, value_name = "FORMAT")]
    to: String,
    /// The directory to write (new or empty).
    #[arg(short, long)]
    output: PathBuf,
    /// The Python with the renderer's package (default python3; env
    /// SCENEFIT_PYTHON).
    #[arg(long, value_name = "PROGRAM")]
    python: Option<PathBuf>,
}

pub fn run(a: ExportArgs) -> Result<()> {
    let exporter = formats::exporter_for(&a.to)?;
    if exporter.name == formats::BLENDER {
        // Blender's export writes one new .blend file named by -o, not a
        // directory (docs/interchange.md "Blender").
        crate::interchange::blend_export::export(&a.scene, &a.output)?;
        println!("{} written", a.output.display());
        return Ok(());
    }
    let scene = crate::scene::load(&a.scene)?;
    let python = python(a.python.clone())?;
    let mut inputs: Vec<PathBuf> = vec![a.scene.clone()];
    inputs.extend(files_of(&scene));
    let refs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    let made = scene_files::export_dir(&a.output, &refs)?;
    let job = scene_files::ExportJob {
        scene: &scene,
        scene_file: &a.scene,
        out: &a.output,
        python: &python,
    };
    let done = match (exporter.run)(&job) {
        Ok(done) => done,
        Err(e) => {
            // a failed export leaves no trace: the directory was new or
            // empty, so all it holds is ours
            scene_files::empty_out(&a.output, made);
            return Err(e);
        }
    };
    for w in &done.warnings {
        eprintln!("warning: {w}");
    }
    println!("{} written", done.main.display());
    Ok(())
}

/// The mesh and texture files a scene names (inputs an export may not
/// write over).
fn files_of(scene: &crate::scene::Scene) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for o in &scene.objects {
        if let crate::scene::shape::Shape::Mesh { file } = &o.shape {
            out.push(PathBuf::from(file));
        }
        for kind in crate::scene::texture::MapKind::ALL {
            if let Some(t) = o.material.map(kind) {
                out.push(PathBuf::from(t.file()));
            }
        }
    }
    out
}

/// The Python that runs the renderer's package: `--python`, else
/// SCENEFIT_PYTHON, else python3, found on the PATH.
pub(super) fn python(flag: Option<PathBuf>) -> Result<PathBuf> {
    let opts = super::env::render_options(RenderOptions {
        python: flag,
        ..RenderOptions::default()
    })?;
    let name = opts
        .python
        .map(|p| p.to_string_lossy().into_owned())
        .unwrap_or_else(|| "python3".into());
    crate::exec::discover::find(
        &name,
        "name a Python 3 with the renderer's package (--python or SCENEFIT_PYTHON)",
    )
}
