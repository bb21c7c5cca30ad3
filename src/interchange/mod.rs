//! Files of other tools read into the project's formats: cameras from
//! calibration tools (COLMAP text models, OpenCV calibration YAML) turned
//! into a shots file, and free parameters from a short spec for a scene
//! that no one wrote by hand (docs/interchange.md). Each reader parses its format
//! into [`camera::Calibrated`], the one pinhole in OpenCV's conventions the
//! scene format holds; `shots_out` matches them to photographs.

pub mod camera;
pub mod colmap;
pub mod free_spec;
pub mod opencv_yaml;
pub mod shots_out;

/// The most a calibration file (COLMAP's cameras.txt or images.txt, an
/// OpenCV YAML) may hold: images.txt lists every 2-D point of every
/// photograph, some hundreds of MiB for the largest reconstructions.
pub const MAX_CALIBRATION_BYTES: u64 = 512 << 20;

use crate::error::{Error, Result};
use std::path::Path;

/// The text of calibration file `path`, read through `input/` with its cap.
pub(crate) fn read_text(path: &Path, expected: &str) -> Result<String> {
    let bytes = crate::input::read_capped(path, MAX_CALIBRATION_BYTES)
        .map_err(|e| crate::input::capped_error(path, e, expected))?;
    String::from_utf8(bytes).map_err(|e| {
        Error::Usage(format!(
            "{}: byte {}: not UTF-8 text; expected {expected}",
            path.display(),
            e.utf8_error().valid_up_to()
        ))
    })
}
