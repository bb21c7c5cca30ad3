//! result.json and what a finished fit leaves in memory and on disk:
//! result.json, fitted_scene.json and best.png, result.json last so that
//! its presence means the run finished.

use crate::error::{Error, Result};
use crate::metric::Deviation;
use crate::raster::Image;
use crate::rundir::{RunDir, BEST, FITTED_SCENE, RESULT};
use crate::scene::Scene;
use serde::{Deserialize, Serialize};

/// result.json. The binding keys come first; the rest are additions.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FitResult {
    pub renderer: String,
    pub strategy: String,
    pub seed: u64,
    pub params: serde_json::Map<String, serde_json::Value>,
    pub deviation: Deviation,
    /// The deviation from the photograph's unrounded levels, when it is
    /// finer than 8-bit sRGB (16-bit, float, linear); `deviation` is on
    /// the photograph rounded to 8-bit sRGB.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub deviation_precise: Option<Deviation>,
    pub evaluations: usize,
    pub generations: usize,
    pub wall_seconds: f64,
    pub stop_reason: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<String>,
    /// How the target's values were read (`srgb` or `linear`), so that
    /// `diagnose` and `report` read it the same way.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_encoding: Option<crate::raster::Encoding>,
    #[serde(default)]
    pub failed_renders: usize,
    /// Standard errors and correlations from a local search's final
    /// Jacobian (the `hybrid` strategy); absent for a population search.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub identifiability: Option<super::uncertainty::Uncertainty>,
    /// A set of photographs (`fit --shots`): each one's own parameters and
    /// deviation; `params` then holds the shared ones.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shots: Option<Vec<ShotResult>>,
}

/// One photograph's part of result.json.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ShotResult {
    pub name: String,
    /// This photograph's own parameters.
    pub params: serde_json::Map<String, serde_json::Value>,
    pub deviation: Deviation,
}

impl FitResult {
    /// Reads DIR/result.json.
    pub fn load(dir: &RunDir) -> Result<FitResult> {
        dir.read_json(RESULT, "a scenefit result")
    }

    /// Refuses a result with a non-finite number: it would not be read back.
    pub fn check_finite(&self) -> Result<()> {
        let mut bad = None;
        for (k, v) in &self.params {
            let finite = match v {
                serde_json::Value::Number(n) => n.as_f64().is_some_and(f64::is_finite),
                serde_json::Value::Array(a) => {
                    a.iter().all(|x| x.as_f64().is_some_and(f64::is_finite))
                }
                _ => true,
            };
            if !finite {
                bad = Some(k.clone());
            }
        }
        for (name, d) in [
            ("deviation", Some(&self.deviation)),
            ("deviation_precise", self.deviation_precise.as_ref()),
        ] {
            let Some(d) = d else { continue };
            if bad.is_none() && ![d.r, d.g, d.b, d.average].iter().all(|x| x.is_finite()) {
                bad = Some(name.into());
            }
        }
        match bad {
            None => Ok(()),
            Some(k) => Err(Error::Run(format!(
                "the fit produced a non-finite value for {k}; no result written (check the bounds of the scene's free parameters)"
            ))),
        }
    }
}

/// The final population of the last phase searched, for the trade-offs.
#[derive(Clone, Debug)]
pub struct Population {
    /// The scene searched (its free list gives the bounds).
    pub base: Scene,
    pub phase: u32,
    /// Unit-cube points and their fitness.
    pub members: Vec<Vec<f64>>,
    pub fitness: Vec<f64>,
}

/// Everything a finished fit produced, in memory.
#[derive(Clone, Debug)]
pub struct FitOutcome {
    pub result: FitResult,
    /// The scene with the fitted values in place.
    pub scene: Scene,
    /// The best render.
    pub image: Image,
    /// The last phase's final population (a global search's; None for a
    /// search without one).
    pub population: Option<Population>,
}

/// Writes the final files; result.json last.
pub fn finish(dir: &RunDir, outcome: &FitOutcome) -> Result<()> {
    dir.write_image(BEST, &outcome.image)?;
    dir.write_json(FITTED_SCENE, &outcome.scene)?;
    dir.write_json(RESULT, &outcome.result)
}
