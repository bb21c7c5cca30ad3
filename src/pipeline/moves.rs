//! How far stage 2 moved each free parameter from where it started (the
//! handover point), for comparison.json and the report: the values before
//! and after in scene units, and each component's move as a fraction of
//! the original span in the space it is searched in (H, S, V for `hsv`
//! colours), so that "stage 2 moved nothing" reads as zeros.

use crate::scene::{ParamSpace, Scene};
use serde::{Deserialize, Serialize};

/// One free parameter's move.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Move {
    pub param: String,
    /// The value stage 2 started from, and the one it ended at.
    pub from: serde_json::Value,
    pub to: serde_json::Value,
    /// Per component: (to − from) / original span, in the search space.
    pub span_fraction: Vec<f64>,
}

/// The moves from `from` to `to`, measured in `original`'s bounds.
pub fn of(original: &Scene, from: &Scene, to: &Scene) -> Vec<Move> {
    let space = ParamSpace::from_scene(original);
    let (a, b) = (space.json_values(from), space.json_values(to));
    let mut out = Vec::new();
    for spec in &space.specs {
        let one = ParamSpace {
            specs: vec![spec.clone()],
        };
        let (ua, ub) = (one.unit_of(from), one.unit_of(to));
        out.push(Move {
            param: spec.name.clone(),
            from: a.get(&spec.name).cloned().unwrap_or_default(),
            to: b.get(&spec.name).cloned().unwrap_or_default(),
            span_fraction: ua.iter().zip(&ub).map(|(x, y)| y - x).collect(),
        });
    }
    out
}
