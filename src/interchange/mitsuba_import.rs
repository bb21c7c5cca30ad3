//! `scenefit import FILE.xml`: a Mitsuba 3 XML scene read through
//! Mitsuba's own parser.

use super::scene_files::{ImportJob, Imported, Importer};
use crate::error::{Error, Result};

/// The importers' entry (`scene_files::IMPORTERS`).
pub const IMPORTER: Importer = Importer {
    name: "mitsuba",
    extensions: &["xml"],
    run,
};

fn run(_job: &ImportJob) -> Result<Imported> {
    Err(Error::Usage("import of Mitsuba XML: not built yet".into()))
}
