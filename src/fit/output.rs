//! result.json and what a finished fit leaves in memory and on disk, one
//! writer for one photograph and a set: each best image (best.png, or
//! best_NAME.png for each photograph of a set), a set's shots.json,
//! fitted_scene.json and result.json, result.json last so that its
//! presence means the run finished.

use crate::error::{Error, Result};
use crate::metric::Deviation;
use crate::raster::Image;
use crate::rundir::{RunDir, BEST, FITTED_SCENE, RESULT, SHOTS};
use crate::scene::field::{Field, LightField, Value};
use crate::scene::{ParamSpace, Scene};
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
    /// Other answers the search saw that fit alike the best, within the
    /// noise of an 8-bit photograph (`optimize::basins`), best first;
    /// absent when the answer is unambiguous.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub alternatives: Vec<Alternative>,
    /// A set's photographs held out of the fit (`"hold_out": true`,
    /// `--hold-out`), each predicted from the fitted model
    /// (`set::held_out`); absent when none was held out.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub held_out: Vec<HeldOutResult>,
}

/// One entry of result.json's `alternatives`: another answer, in the
/// scene's values as `params` gives them, and its average deviation in
/// percent (as `deviation.average`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Alternative {
    pub params: serde_json::Map<String, serde_json::Value>,
    pub deviation: f64,
}

/// The search's alternatives (unit points and fitness, best first) as
/// result.json's entries, keeping only those whose scene values differ
/// from the best's, and from every better alternative kept, by more than
/// `optimize::basins::SEPARATION` of a parameter's range: a light's
/// direction compared as a direction (its length changes nothing; two
/// lengths of one swapped direction are one answer), a colour searched in
/// HSV as RGB (a black ball's hue changes nothing).
pub fn alternatives(
    space: &ParamSpace,
    base: &Scene,
    best: &[f64],
    found: &[(Vec<f64>, f64)],
) -> Vec<Alternative> {
    let far =
        |a: &[f64], b: &[f64]| answer_distance(space, a, b) > crate::optimize::basins::SEPARATION;
    let mut kept: Vec<&(Vec<f64>, f64)> = Vec::new();
    for f in found {
        if far(best, &f.0) && kept.iter().all(|k| far(&k.0, &f.0)) {
            kept.push(f);
        }
    }
    kept.into_iter()
        .map(|(u, fitness)| Alternative {
            params: space.json_values(&space.scene_at(base, u)),
            // The fitness is the sum of the three channels' deviations.
            deviation: fitness / 3.0,
        })
        .collect()
}

/// The largest difference between two unit points' scene values, each
/// as a fraction of its parameter's range (see [`alternatives`]).
fn answer_distance(space: &ParamSpace, a: &[f64], b: &[f64]) -> f64 {
    let mut at = 0;
    let mut largest: f64 = 0.0;
    for spec in &space.specs {
        let (ua, ub) = (&a[at..at + spec.dim()], &b[at..at + spec.dim()]);
        at += spec.dim();
        let d = match (spec.field, spec.value_at(ua), spec.value_at(ub)) {
            (Field::Light(_, LightField::Direction), Value::Vector(x), Value::Vector(y)) => {
                let (x, y) = (unit(x), unit(y));
                (0..3).map(|c| (x[c] - y[c]).abs()).fold(0.0, f64::max) / 2.0
            }
            (_, Value::Vector(x), Value::Vector(y)) if spec.hsv => {
                (0..3).map(|c| (x[c] - y[c]).abs()).fold(0.0, f64::max)
            }
            _ => ua
                .iter()
                .zip(ub)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max),
        };
        largest = largest.max(d);
    }
    largest
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if n > 0.0 {
        v.map(|c| c / n)
    } else {
        v
    }
}

/// One photograph's part of result.json.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ShotResult {
    pub name: String,
    /// This photograph's own parameters.
    pub params: serde_json::Map<String, serde_json::Value>,
    pub deviation: Deviation,
}

/// One held-out photograph in result.json: its own values as predicted
/// (the shared ones frozen at the fit's) and the prediction's deviation.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct HeldOutResult {
    pub name: String,
    pub params: serde_json::Map<String, serde_json::Value>,
    pub deviation_fit: Deviation,
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

/// What a finished fit writes, whatever its photographs.
pub struct Written<'a, S: Serialize> {
    /// Each best image and its file name.
    pub images: Vec<(String, &'a Image)>,
    /// A set's photographs, with absolute paths (shots.json), for
    /// `diagnose`.
    pub shots: Option<&'a S>,
    pub scene: &'a Scene,
    pub result: &'a FitResult,
}

/// Writes a finished fit's files; result.json last.
pub fn write<S: Serialize>(dir: &RunDir, w: &Written<S>) -> Result<()> {
    for (name, image) in &w.images {
        dir.write_image(name, image)?;
    }
    if let Some(shots) = w.shots {
        dir.write_json(SHOTS, shots)?;
    }
    dir.write_json(FITTED_SCENE, w.scene)?;
    dir.write_json(RESULT, w.result)
}

/// One photograph's files: best.png, fitted_scene.json, result.json.
pub fn write_one(dir: &RunDir, outcome: &FitOutcome) -> Result<()> {
    write(
        dir,
        &Written::<()> {
            images: vec![(BEST.to_string(), &outcome.image)],
            shots: None,
            scene: &outcome.scene,
            result: &outcome.result,
        },
    )
}
