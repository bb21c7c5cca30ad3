//! Files of other tools read into the project's formats: cameras from
//! calibration tools (COLMAP text models, OpenCV calibration YAML) turned
//! into a shots file, and free parameters from a short spec for a scene
//! that no one wrote by hand (docs/interchange.md). Each reader parses its format
//! into [`camera::Calibrated`], the one pinhole in OpenCV's conventions the
//! scene format holds; `shots_out` matches them to photographs.

pub mod blend_export;
pub mod blend_import;
mod blend_run;
pub mod camera;
pub mod colmap;
pub mod formats;
pub mod free_spec;
pub mod mitsuba_export;
pub mod mitsuba_import;
pub mod opencv_yaml;
pub mod python_run;
pub mod scene_files;
pub mod script_run;
pub mod shots_out;

use crate::error::{Error, Result};
use std::path::Path;

/// The text of calibration file `path`, read through `input/` with its cap.
pub(crate) fn read_text(path: &Path, expected: &str) -> Result<String> {
    let bytes = crate::input::read_capped(path, crate::input::MAX_CALIBRATION_BYTES)
        .map_err(|e| crate::input::capped_error(path, e, expected))?;
    String::from_utf8(bytes).map_err(|e| {
        Error::Usage(format!(
            "{}: byte {}: not UTF-8 text; expected {expected}",
            path.display(),
            e.utf8_error().valid_up_to()
        ))
    })
}
