//! What a diagnosis starts from: the fitted scene of a fit directory, its
//! target, and the mask (without the target's saturated pixels, as in the
//! fit).

use crate::error::Result;
use crate::fit::{FitResult, FitTarget};
use crate::metric::Mask;
use crate::raster::Encoding;
use crate::raster::Image;
use crate::rundir::{RunDir, FITTED_SCENE, MASK};
use crate::scene::Scene;
use std::path::{Path, PathBuf};

/// The fit's scene (its model and free parameters), target and mask.
pub struct Inputs {
    pub scene: Scene,
    pub target: Image,
    pub mask: Option<Mask>,
}

impl Inputs {
    /// Reads a fit directory: fitted_scene.json, and the target named in
    /// result.json (or `target`); the mask from `mask`, else FIT_DIR/mask.png
    /// when present.
    pub fn from_fit_dir(dir: &Path, target: Option<&Path>, mask: Option<&Path>) -> Result<Inputs> {
        let scene = crate::scene::load(&dir.join(FITTED_SCENE))?;
        let (target_path, what, encoding) = match target {
            Some(t) => (t.to_path_buf(), "--target", None),
            None => {
                let (path, encoding) = fit_target(dir)?;
                (path, "the fit's target", encoding)
            }
        };
        let size = (scene.image.width, scene.image.height);
        let default_mask = dir.join(MASK);
        let mask_path = mask
            .map(Path::to_path_buf)
            .or_else(|| default_mask.exists().then_some(default_mask));
        let mask = mask_path.as_deref().map(|m| (m, "--mask"));
        let (target, note) = FitTarget::from_photo(&target_path, what, mask, encoding, size)?;
        if let Some(n) = note {
            // Diagnose has no --quiet and prints its own summary: said once.
            eprintln!("{n}");
        }
        Ok(Inputs {
            scene,
            target: target.image,
            mask: target.mask,
        })
    }
}

/// The target result.json names, found by the run directory's one rule,
/// and the encoding the fit read it in.
fn fit_target(dir: &Path) -> Result<(PathBuf, Option<Encoding>)> {
    let run = RunDir::existing(dir)?;
    let result = FitResult::load(&run)?;
    Ok((
        run.find_target(result.target.as_deref())?,
        result.target_encoding,
    ))
}
