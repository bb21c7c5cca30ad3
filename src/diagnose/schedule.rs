//! How a diagnosis refits its models: as one photograph's
//! (`Schedule::One`, fits in memory, `one_refit.rs`) or as a set's
//! (`Schedule::Set`, set fits, `set_refit.rs`), and the kinds of refit an
//! effect's trial gets (`Refit`). The rounds (`rounds.rs`) are the same
//! for both; the refits are told apart in one place, `trials.rs`.

use crate::scene::{ParamSpace, Scene};

/// How models are refitted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Schedule {
    /// One photograph (`fit --target`).
    One,
    /// A set of photographs (`fit --shots`).
    Set,
}

impl Schedule {
    /// The refits of the fit `inputs` come from.
    pub fn of(inputs: &super::inputs::SetInputs) -> Schedule {
        if inputs.single {
            Schedule::One
        } else {
            Schedule::Set
        }
    }
}

/// One refit of a trial.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refit {
    /// The effect's own parameters searched, then every one refined.
    Warm,
    /// Every parameter over its bounds.
    Scratch,
    /// A set fit around the start, the effect's own values spread.
    WarmSet,
    /// Solved in closed form, the others refitted warm.
    ClosedForm,
}

impl Schedule {
    /// What a candidate's `refit` says of `refit`.
    pub fn label(self, refit: Refit) -> &'static str {
        match (self, refit) {
            (_, Refit::Warm) => "warm",
            (_, Refit::Scratch) => "from scratch",
            (Schedule::One, Refit::ClosedForm) => "closed form, then warm",
            (_, Refit::WarmSet | Refit::ClosedForm) => "warm (set)",
        }
    }

    /// The values diagnosis.json's `params_after` holds: every free value
    /// of one photograph's model; a set's shared ones (each photograph's
    /// own go in `shots_after`).
    pub fn values(self, scene: &Scene) -> serde_json::Map<String, serde_json::Value> {
        let space = ParamSpace::from_scene(scene);
        match self {
            Schedule::One => space.json_values(scene),
            Schedule::Set => space.shared().json_values(scene),
        }
    }
}
