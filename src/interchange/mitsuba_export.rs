//! `scenefit export --to mitsuba`: a scene as a Mitsuba 3 XML file with
//! its meshes, textures and the module registering scenefit's own
//! plug-ins beside it (workers/mitsuba_export.py), drawn by Mitsuba as
//! the Mitsuba backend draws the scene: the same refusals (the backend's
//! `supports`), near lights lowered as before every backend, and the
//! backend's own translation of the scene (docs/interchange.md).

use super::python_run;
use super::scene_files::{ExportJob, Exported, Exporter};
use crate::error::{Error, Result};
use crate::render::{camera_effects, external, mitsuba, near_lights};
use std::ffi::OsString;

/// The exporters' entry (`formats::EXPORTERS`).
pub const EXPORTER: Exporter = Exporter {
    name: "mitsuba",
    run,
};

const SCRIPT: (&str, &str) = (
    "mitsuba_export.py",
    include_str!("../../workers/mitsuba_export.py"),
);

fn run(job: &ExportJob) -> Result<Exported> {
    let file = job.scene_file.display();
    if let Some(r) = (mitsuba::BACKEND.supports)(job.scene).first() {
        return Err(Error::Usage(format!(
            "{file}: {}: {} (the Mitsuba backend draws no such scene; nor does its export)",
            r.field, r.why
        )));
    }
    let mut warnings = Vec::new();
    if camera_effects::has_effects(&job.scene.camera) {
        warnings.push(format!(
            "{file}: camera: vignetting, response, exposure and white balance are applied by scenefit to the rendered image; the XML renders without them"
        ));
    }
    let scene = external::plain_scene(&near_lights::lower(job.scene));
    let text = serde_json::to_string(&scene)
        .map_err(|e| Error::Run(format!("cannot serialise the scene: {e}")))?;
    // the scene the script reads lies in the output's own directory for
    // the run, and goes when it ends
    let input = job.out.join(".scenefit-export-scene.json");
    crate::fsio::write_atomic(&input, text.as_bytes())?;
    // the script runs in a directory of its own: absolute paths
    let out = std::fs::canonicalize(job.out).map_err(|e| Error::io(job.out, e))?;
    let args: Vec<OsString> = vec![out.join(".scenefit-export-scene.json").into(), out.into()];
    let answer = python_run::run(
        job.python,
        python_run::MITSUBA_MODULES,
        SCRIPT,
        &args,
        "export to mitsuba",
    );
    let _ = std::fs::remove_file(&input);
    warnings.extend(python_run::warnings(&answer?));
    Ok(Exported {
        main: job.out.join("scene.xml"),
        warnings,
    })
}
