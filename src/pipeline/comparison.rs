//! comparison.json, the pipeline's summary (docs/usage.md, output files):
//!
//! ```json
//! {"stage1": {"renderer": "phong", "deviation": {"r", "g", "b", "average"},
//!             "evaluations": 40080, "wall_seconds": 6.1, ...},
//!  "stage2": {"renderer": "blender", ...},
//!  "handover": {"seeded": true, "window": 0.15, ...},
//!  "moves": [{"param": "lights.key.intensity", "from": 12.7, "to": 13.1,
//!             "span_fraction": [0.008]}, ...]}
//! ```
//!
//! The binding keys (read by outside scripts) come first in each stage; the
//! rest are additions.
//! `wall_seconds` is the stage's whole wall-clock time, renderer start-up
//! included; `fit_seconds` is result.json's `wall_seconds`, the time spent
//! in generations only.

use super::handover::Narrowed;
pub use super::moves::Move;
use crate::error::Result;
use crate::metric::Deviation;
use crate::rundir::{RunDir, COMPARISON};
use serde::{Deserialize, Serialize};

/// One stage's outcome.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StageSummary {
    pub renderer: String,
    pub deviation: Deviation,
    pub evaluations: usize,
    pub wall_seconds: f64,
    pub fit_seconds: f64,
    pub generations: usize,
    pub population: usize,
    pub strategy: String,
    pub seed: u64,
    pub stop_reason: String,
    /// The stage's run directory, relative to the pipeline directory.
    pub dir: String,
    /// Stage 2's method: "mapped" (space mapping) or "de".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub method: Option<String>,
}

/// How stage 2 was started from stage 1.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Handover {
    /// False with --stage2-from-scratch: full bounds, uniform start.
    pub seeded: bool,
    /// Half-width of the stage-2 bounds as a fraction of the original span.
    pub window: Option<f64>,
    /// `start_radius` of the stage-2 population (unit cube of its bounds).
    pub start_radius: Option<f64>,
    /// The stage-1 fitted values rendered by the stage-2 renderer: how far
    /// the handover starts from the target before stage 2 moves anything.
    pub deviation_at_handover: Option<Deviation>,
    #[serde(default)]
    pub bounds: Vec<Narrowed>,
}

/// comparison.json.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Comparison {
    pub stage1: StageSummary,
    pub stage2: StageSummary,
    pub handover: Handover,
    /// How far stage 2 moved each free parameter from where it started.
    #[serde(default)]
    pub moves: Vec<Move>,
    /// With `--stage2-method both`: the DE stage 2 run for comparison
    /// (in stage2_de/); `stage2` is then the mapped one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stage2_de: Option<StageSummary>,
    /// The target and mask copied into the pipeline directory.
    pub target: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mask: Option<String>,
}

impl Comparison {
    /// Reads a pipeline directory's comparison.json.
    pub fn load(dir: &RunDir) -> Result<Comparison> {
        dir.read_json(COMPARISON, "a scenefit pipeline comparison")
    }
}
