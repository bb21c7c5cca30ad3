//! `scenefit export --to mitsuba`: a scene as a Mitsuba 3 XML file.

use super::scene_files::{ExportJob, Exported, Exporter};
use crate::error::{Error, Result};

/// The exporters' entry (`scene_files::EXPORTERS`).
pub const EXPORTER: Exporter = Exporter {
    name: "mitsuba",
    run,
};

fn run(_job: &ExportJob) -> Result<Exported> {
    Err(Error::Usage("export to Mitsuba XML: not built yet".into()))
}
