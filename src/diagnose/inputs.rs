//! What a diagnosis starts from: the fitted scene of a fit directory, its
//! target, and the mask (without the target's saturated pixels, as in the
//! fit); for a set fit, the shared model, the photographs and each one's
//! own fitted values.

use crate::error::{Error, Result};
use crate::fit::set::shots::Shot;
use crate::fit::{FitResult, FitTarget, HeldOutResult};
use crate::metric::Mask;
use crate::raster::Encoding;
use crate::raster::Image;
use crate::rundir::{RunDir, FITTED_SCENE, MASK, SHOTS};
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

/// A photograph's own values: parameter name to value.
pub type Params = serde_json::Map<String, serde_json::Value>;

/// A set fit's outputs, as a diagnosis starts from them.
pub struct SetInputs {
    /// The shared model.
    pub scene: Scene,
    pub shots: Vec<Shot>,
    /// Each photograph's own fitted values.
    pub own: Vec<Params>,
    /// Photographs held out (by the fit or `diagnose --hold-out`): in no
    /// refit, predicted at the end (`fit::set::held_out`).
    pub held_out: Vec<Shot>,
    /// The fit's own predictions of the shots it held out (result.json's
    /// `held_out`): their `deviation_fit` is taken as the fit reported it,
    /// not predicted again.
    pub fit_held_out: Vec<HeldOutResult>,
    /// A fit of one photograph (`--target`), not a shots file: its models
    /// are refitted as one photograph's and its files carry no shot name.
    pub single: bool,
}

impl SetInputs {
    /// One photograph as a set of one: its scene shared, the photograph
    /// its one shot, with no own values.
    pub fn one(inputs: &Inputs) -> SetInputs {
        let target = FitTarget {
            image: inputs.target.clone(),
            levels: None,
            mask: inputs.mask.clone(),
            path: None,
            encoding: None,
        };
        SetInputs {
            scene: inputs.scene.clone(),
            shots: vec![Shot::one(&inputs.scene, target)],
            own: vec![Params::new()],
            held_out: Vec::new(),
            fit_held_out: Vec::new(),
            single: true,
        }
    }

    /// The set fit in `dir`, or None when `dir` holds a fit of one
    /// photograph; the shots `hold_out` names held out besides the fit's.
    pub fn from_fit_dir(dir: &Path, hold_out: &[String]) -> Result<Option<SetInputs>> {
        if !dir.join(crate::rundir::RESULT).is_file() {
            return Ok(None); // the one-photograph path says what is missing
        }
        let run = RunDir::existing(dir)?;
        let result = FitResult::load(&run)?;
        let Some(results) = result.shots else {
            return Ok(None);
        };
        let scene = crate::scene::load(&dir.join(FITTED_SCENE))?;
        let (mut shots, _) = crate::fit::set::shots::load(&dir.join(SHOTS), &scene)?;
        crate::fit::set::held_out::mark(&mut shots, hold_out, "--hold-out")?;
        let (shots, held_out) = crate::fit::set::held_out::split(&shots)?;
        let own = shots
            .iter()
            .map(|s| {
                results
                    .iter()
                    .find(|r| r.name == s.name)
                    .map(|r| r.params.clone())
                    .ok_or_else(|| {
                        Error::invalid(
                            run.file(crate::rundir::RESULT).display().to_string(),
                            "shots",
                            format!("expected a result for shot {}", s.name),
                        )
                    })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Some(SetInputs {
            scene,
            shots,
            own,
            held_out,
            fit_held_out: result.held_out,
            single: false,
        }))
    }
}
