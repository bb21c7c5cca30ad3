//! `scenefit import-cameras (--colmap DIR | --opencv FILE...) --images DIR
//! -o SHOTS.json [--scene SCENE.json]`: cameras from calibration tools as
//! a shots file, each photograph's pinhole camera under `set`
//! (docs/interchange.md).

use crate::error::{Error, Result};
use crate::interchange::shots_out::{self, Named};
use crate::interchange::{colmap, opencv_yaml};
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct ImportCamerasArgs {
    /// A COLMAP text model: the directory holding cameras.txt and images.txt.
    #[arg(
        long,
        value_name = "DIR",
        conflicts_with = "opencv",
        required_unless_present = "opencv"
    )]
    colmap: Option<PathBuf>,
    /// An OpenCV calibration YAML, one per photograph (the image with the same name stem).
    #[arg(long, value_name = "FILE")]
    opencv: Vec<PathBuf>,
    /// The directory of the photographs.
    #[arg(long, value_name = "DIR")]
    images: PathBuf,
    /// The shots file to write (JSON).
    #[arg(short, long)]
    output: PathBuf,
    /// Check the shots file against this scene (its pinhole camera, the
    /// photographs' size) before writing it.
    #[arg(long, value_name = "SCENE")]
    scene: Option<PathBuf>,
}

pub fn run(a: ImportCamerasArgs) -> Result<()> {
    if !a.images.is_dir() {
        return Err(Error::Usage(format!(
            "--images {}: not a directory; expected the directory of the photographs",
            a.images.display()
        )));
    }
    let (cameras, source, inputs) = match &a.colmap {
        Some(dir) => {
            let list = colmap::read(dir)?;
            let named = list.into_iter().map(|i| Named {
                name: i.name,
                camera: i.camera,
                from: dir.join("cameras.txt"),
            });
            let inputs = vec![dir.join("cameras.txt"), dir.join("images.txt")];
            (
                named.collect(),
                dir.join("images.txt").display().to_string(),
                inputs,
            )
        }
        None => (
            opencv_cameras(&a.opencv, &a.images)?,
            "--opencv".to_string(),
            a.opencv.clone(),
        ),
    };
    refuse_overwriting(&a.output, &inputs)?;
    if let Some(scene) = &a.scene {
        same_size(&cameras, &crate::scene::load(scene)?)?;
    }
    let file = shots_out::build(cameras, &a.images, &a.output, &source)?;
    let text = serde_json::to_string_pretty(&file)
        .map_err(|e| Error::Run(format!("cannot write the shots file: {e}")))?;
    if let Some(scene) = &a.scene {
        check_against(scene, &a.output, &text)?;
    }
    crate::fsio::write_atomic(&a.output, format!("{text}\n").as_bytes())?;
    println!(
        "{} shots written to {}",
        file.shots.len(),
        a.output.display()
    );
    Ok(())
}

/// One camera per OpenCV file, named by the image with the file's stem.
fn opencv_cameras(files: &[PathBuf], images: &Path) -> Result<Vec<Named>> {
    let mut out = Vec::with_capacity(files.len());
    for f in files {
        let (camera, posed) = opencv_yaml::read(f)?;
        let stem = f
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string();
        let name = shots_out::find_image(images, &stem)
            .and_then(|p| p.file_name().map(|n| n.to_string_lossy().to_string()))
            .unwrap_or(stem);
        if !posed {
            eprintln!(
                "warning: {}: no rvec/tvec; the camera is placed at the origin looking along +z (the scene in the camera's coordinates)",
                f.display()
            );
        }
        out.push(Named {
            name,
            camera,
            from: f.clone(),
        });
    }
    Ok(out)
}

/// Every camera calibrated for the scene's image size: intrinsics of
/// another size would place every pixel wrong.
fn same_size(cameras: &[Named], scene: &crate::scene::Scene) -> Result<()> {
    let want = (scene.image.width, scene.image.height);
    for c in cameras {
        if let Some(got) = c.camera.size.filter(|&s| s != want) {
            return Err(Error::Usage(format!(
                "{}: {}: calibrated for {}x{} pixels, the scene's image is {}x{}; expected photographs of the calibrated size",
                c.from.display(), crate::scene::limits::quote(&c.name), got.0, got.1, want.0, want.1
            )));
        }
    }
    Ok(())
}

/// The output must not be one of the inputs.
fn refuse_overwriting(out: &Path, inputs: &[PathBuf]) -> Result<()> {
    let canon = |p: &Path| std::fs::canonicalize(p).ok();
    if let Some(o) = canon(out) {
        if inputs.iter().any(|i| canon(i).as_ref() == Some(&o)) {
            return Err(Error::Usage(format!(
                "-o {}: is an input; expected a new file name",
                out.display()
            )));
        }
    }
    Ok(())
}

/// Loads the shots file as `fit --shots` would with `scene`, from a
/// temporary file beside the output (its paths are relative to it).
fn check_against(scene: &Path, out: &Path, text: &str) -> Result<()> {
    let dir = out
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let tmp = tempfile::Builder::new()
        .prefix(".import-cameras-")
        .suffix(".json")
        .tempfile_in(dir)
        .map_err(|e| Error::io(dir, e))?;
    std::fs::write(tmp.path(), text).map_err(|e| Error::io(tmp.path(), e))?;
    let scene = crate::scene::load(scene)?;
    crate::fit::set::shots::load(tmp.path(), &scene).map_err(|e| {
        if !e.is_user_error() {
            return e;
        }
        // name the file the user will get, not the temporary one
        let t = tmp.path().display().to_string();
        let o = out.display().to_string();
        Error::Usage(format!(
            "{} (checked against the scene)",
            e.to_string().replace(&t, &o)
        ))
    })?;
    Ok(())
}
