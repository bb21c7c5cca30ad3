//! The formats `scenefit import` and `scenefit export` know, as two small
//! tables: an importer by the input's file extension, an exporter by
//! `--to` name. A new format is one line in each.

use super::scene_files::{Exporter, Importer};
use crate::error::{Error, Result};
use std::path::Path;

/// The importers, chosen by the input's extension.
pub const IMPORTERS: &[Importer] = &[
    super::mitsuba_import::IMPORTER,
    Importer {
        name: BLENDER,
        extensions: &["blend"],
        run: |_| Err(own_rules()),
    },
];

/// The exporters, chosen by `--to`.
pub const EXPORTERS: &[Exporter] = &[
    super::mitsuba_export::EXPORTER,
    Exporter {
        name: BLENDER,
        run: |_| Err(own_rules()),
    },
];

/// Blender's row: its import and export keep their own output rules
/// (one .blend file; meshes beside the scene), so the commands call
/// `blend_import` / `blend_export` directly and never this `run`.
pub const BLENDER: &str = "blender";

fn own_rules() -> Error {
    Error::Run("Blender's import and export are called by the commands directly".into())
}

/// The importer for `input`'s extension.
pub fn importer_for(input: &Path) -> Result<&'static Importer> {
    let ext = input
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    IMPORTERS
        .iter()
        .find(|i| i.extensions.contains(&ext.as_str()))
        .ok_or_else(|| {
            let known: Vec<String> = IMPORTERS
                .iter()
                .flat_map(|i| i.extensions.iter().map(|e| format!(".{e} ({})", i.name)))
                .collect();
            Error::Usage(format!(
                "{}: unknown kind of file; expected {}",
                input.display(),
                known.join(" or ")
            ))
        })
}

/// The exporter `--to name` names.
pub fn exporter_for(name: &str) -> Result<&'static Exporter> {
    EXPORTERS.iter().find(|e| e.name == name).ok_or_else(|| {
        let known: Vec<&str> = EXPORTERS.iter().map(|e| e.name).collect();
        Error::Usage(format!(
            "--to {name}: unknown format; expected {}",
            known.join(" or ")
        ))
    })
}
