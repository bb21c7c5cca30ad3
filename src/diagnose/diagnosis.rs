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
    /// Free entries held at the fit's values through the diagnosis
    /// (shared geometry, `held.rs`); free again in improved_scene.json.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub held: Vec<String>,
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
}
