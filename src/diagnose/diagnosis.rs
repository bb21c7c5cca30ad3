//! What a diagnosis finds, as diagnosis.json holds it: each effect tried
//! (a `Candidate`), the diagnosis of one photograph and of a set.

use super::inputs::Params;
use crate::metric::Deviation;
use serde::Serialize;

/// One effect tried in one round.
#[derive(Clone, Debug, Serialize)]
pub struct Candidate {
    pub effect: String,
    /// R² of the residual on the effect's feature maps.
    pub evidence: f64,
    /// The deviation after its refit (None: not applicable).
    pub deviation_after: Option<Deviation>,
    pub round: usize,
    /// BIC after its refit minus BIC of the model it extends, with the
    /// round's overdispersion (`selection.rs`).
    pub delta_bic: Option<f64>,
    /// ĉ of the round: how much less than independent samples its pixels
    /// count for (1: independent).
    pub overdispersion: Option<f64>,
    /// Relative drop of the sum of absolute differences.
    pub gain: Option<f64>,
    pub added_params: usize,
    pub accepted: bool,
    /// Which refit counted: "warm" or "from scratch".
    pub refit: String,
    /// A set's candidate weighed on the residual without the albedo's
    /// part, or against the finest colour map, as well (`footing.rs`);
    /// `delta_bic`, `gain` and `overdispersion` are the footing's that
    /// `counted` names.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub footing: Option<Footing>,
}

/// A candidate weighed on more than one footing (diagnosis.json's
/// `footing`, `footing.rs`): on the residual as it is; with a colour map
/// solved for the model before and after it while no object has one
/// (texture-free); against the finest colour map the photographs support
/// once the diagnosis has added one (finest-map).
#[derive(Clone, Debug, Serialize)]
pub struct Footing {
    /// "plain", "texture-free" (the lower criterion of the two) or
    /// "finest-map" (higher than the one counted before it).
    pub counted: &'static str,
    pub plain_delta_bic: f64,
    pub plain_gain: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub texture_free_delta_bic: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub texture_free_gain: Option<f64>,
    /// ĉ of the texture-free footing's residuals.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub texture_free_overdispersion: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub finest_map_delta_bic: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub finest_map_gain: Option<f64>,
    /// ĉ of the finest-map footing's residuals.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub finest_map_overdispersion: Option<f64>,
}

impl Footing {
    /// A candidate's plain footing, counted until another is.
    pub fn plain(delta_bic: f64, gain: f64) -> Footing {
        Footing {
            counted: "plain",
            plain_delta_bic: delta_bic,
            plain_gain: gain,
            texture_free_delta_bic: None,
            texture_free_gain: None,
            texture_free_overdispersion: None,
            finest_map_delta_bic: None,
            finest_map_gain: None,
            finest_map_overdispersion: None,
        }
    }
}

/// diagnosis.json.
#[derive(Clone, Debug, Serialize)]
pub struct Diagnosis {
    pub deviation_before: Deviation,
    pub deviation_after: Deviation,
    pub candidates: Vec<Candidate>,
    pub accepted: Vec<String>,
    pub params_after: serde_json::Map<String, serde_json::Value>,
    /// The deviation of the unchanged model refitted with the same budget.
    pub deviation_refined: Deviation,
    /// Smooth structure remains that no effect explained.
    pub unexplained: bool,
    pub renders: usize,
    pub wall_seconds: f64,
    /// The least SAD gain an effect needed to be accepted (`--min-gain`):
    /// the one threshold a user may move, so a diagnosis says which it ran.
    pub min_gain: f64,
    /// Free entries held at the fit's values through the diagnosis
    /// (shared geometry, `held.rs`); free again in improved_scene.json.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub held: Vec<String>,
    /// Accepted effects the backward step took out again (`backward.rs`).
    pub removed: Vec<Removal>,
    /// Effects a round tried that explained the same residual as the one
    /// it accepted, and why that one (`imitations.rs`).
    pub imitations: Vec<Imitation>,
}

/// The name `accepted` gets when smooth structure remains.
pub const UNEXPLAINED: &str = "unexplained";

/// One photograph after the diagnosis (diagnosis.json's `shots_after`).
#[derive(Clone, Debug, Serialize)]
pub struct ShotAfter {
    pub name: String,
    pub params: Params,
    pub deviation_before: Deviation,
    pub deviation_after: Deviation,
}

/// diagnosis.json of a set.
#[derive(Clone, Debug, Serialize)]
pub struct SetDiagnosis {
    #[serde(flatten)]
    pub diagnosis: Diagnosis,
    pub shots_after: Vec<ShotAfter>,
    /// Each held-out photograph predicted by the fit's model and the
    /// improved one (`fit::set::held_out`), and the predictions after.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub held_out: Vec<crate::fit::set::held_out::Compared>,
    #[serde(skip)]
    pub held_out_images: Vec<crate::raster::Image>,
}

/// An accepted effect the backward step removed (diagnosis.json's
/// `removed`).
#[derive(Clone, Debug, Serialize)]
pub struct Removal {
    pub effect: String,
    /// The round after whose acceptance it was removed.
    pub round: usize,
    /// The criterion's change from the model without it to the model with
    /// it (above −margin: it no longer pays for itself).
    pub delta_bic: f64,
    /// The relative drop of SAD it still gave.
    pub gain: f64,
    pub reason: String,
}

/// Two effects of one round that explain the same residual.
#[derive(Clone, Debug, Serialize)]
pub struct Imitation {
    pub round: usize,
    pub chosen: String,
    pub other: String,
    /// Correlation of the two refits' changes to the render (8-bit levels
    /// over the mask, every photograph).
    pub correlation: f64,
    pub reason: String,
}
