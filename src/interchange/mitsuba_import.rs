//! `scenefit import FILE.xml`: a Mitsuba 3 XML scene read through
//! Mitsuba's own parser (workers/mitsuba_import.py, run once): camera,
//! lights, shapes (meshes written as PLY), materials in the project's
//! convention, bitmaps as texture maps; one warning per kind of thing
//! not mapped (docs/interchange.md has the tables).

use super::python_run;
use super::scene_files::{ImportJob, Imported, Importer};
use crate::error::{Error, Result};
use crate::input;
use std::ffi::OsString;

/// The importers' entry (`formats::IMPORTERS`).
pub const IMPORTER: Importer = Importer {
    name: "mitsuba",
    extensions: &["xml"],
    run,
};

const SCRIPT: (&str, &str) = (
    "mitsuba_import.py",
    include_str!("../../workers/mitsuba_import.py"),
);

const EXPECTED: &str = "a Mitsuba 3 scene (XML with a <scene> element)";

fn run(job: &ImportJob) -> Result<Imported> {
    // read here first: a clear refusal of what is no scene (a FIFO, a
    // huge file, another XML) before Python and Mitsuba start
    let bytes = input::read_capped(job.input, input::MAX_SCENE_XML_BYTES)
        .map_err(|e| input::capped_error(job.input, e, EXPECTED))?;
    let text = String::from_utf8_lossy(&bytes);
    if !text.contains("<scene") {
        return Err(Error::Usage(format!(
            "{}: no <scene> element; expected {EXPECTED}",
            job.input.display()
        )));
    }
    // the script runs in a directory of its own: absolute paths
    let file = std::fs::canonicalize(job.input).map_err(|e| Error::io(job.input, e))?;
    let assets = std::fs::canonicalize(job.assets).map_err(|e| Error::io(job.assets, e))?;
    let prefix = job
        .assets
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let args: Vec<OsString> = vec![file.into(), assets.into(), prefix.into()];
    let answer = python_run::run(
        job.python,
        python_run::MITSUBA_MODULES,
        SCRIPT,
        &args,
        "import of Mitsuba XML",
    )?;
    Ok(Imported {
        warnings: python_run::warnings(&answer),
        scene: answer["scene"].clone(),
    })
}
