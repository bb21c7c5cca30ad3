//! A fit's state, one type for one photograph and for a set, saved to
//! checkpoint.json when the run starts and after every step it finishes
//! (every generation of a search, every photograph of a set's per-shot
//! block), so that `--resume` continues where the run stopped and ends
//! where an uninterrupted run ends. Every `f64` a later step reads from
//! the set's vectors is stored bit-exactly (`optimize::exact`). It
//! records what defines the run (one identity per photograph); the
//! checks of a resume against this run's inputs are in `resume`. A
//! finished fit of one photograph keeps its last phase's search: its
//! final population (the report's trade-offs), and a larger generation
//! budget resumes it. It is read back by `saved::load`, which reads
//! earlier builds' checkpoints too.

use crate::error::Result;
use crate::fit::identity::RunIdentity;
use crate::metric::Deviation;
use crate::optimize::{exact, Search, Searcher};
use crate::rundir::{RunDir, CHECKPOINT, SET_STATE};
use crate::scene::{ParamSpace, Scene};
use serde::{Deserialize, Serialize};

/// Format 3: one format for one photograph's fit and a set's.
pub const FORMAT: &str = "scenefit-checkpoint/3";

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FitState {
    pub format: String,
    /// One per photograph, in the shots file's order.
    pub identities: Vec<RunIdentity>,
    /// A set's rounds at most (`--rounds`); 0 for one photograph.
    #[serde(default)]
    pub rounds: usize,
    /// One photograph given on its own: the scene with earlier phases'
    /// best values in place. None for a set.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base: Option<Scene>,
    /// A set's shared parameters, unit cube.
    #[serde(default, with = "exact::vector")]
    pub shared: Vec<f64>,
    /// A set's photographs' own parameters, unit cube.
    #[serde(default, with = "exact::matrix")]
    pub own: Vec<Vec<f64>>,
    /// Steps of the plan finished (phases, or a set's blocks).
    pub blocks_done: usize,
    #[serde(default)]
    pub shared_blocks: usize,
    /// A set's average deviation after each block.
    #[serde(default, with = "exact::vector")]
    pub history: Vec<f64>,
    /// Renders and generations of the steps finished.
    pub evaluations: usize,
    pub generations: usize,
    #[serde(default)]
    pub failed_renders: usize,
    pub seconds: f64,
    /// What of the step in progress is done.
    #[serde(default)]
    pub within: Within,
    /// A set's last finished shared block's search: its standard errors
    /// (result.json's `identifiability`).
    #[serde(default)]
    pub last_shared: Option<Searcher>,
    /// The names of a set's photographs held out of the fit: part of
    /// what defines the run (a resume holding out others is refused).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub held_out: Vec<String>,
}

/// The progress within the step in progress (empty between steps but
/// for a finished phase, whose search stays).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Within {
    /// A per-shot block: the deviation (r, g, b, average) of each
    /// photograph fitted so far, in order.
    #[serde(default, with = "exact::matrix")]
    pub own_parts: Vec<Vec<f64>>,
    /// A search (a phase, a shared block) after its last generation.
    pub search: Option<Searcher>,
}

impl Within {
    pub fn push_part(&mut self, d: Deviation) {
        self.own_parts.push(vec![d.r, d.g, d.b, d.average]);
    }

    /// The deviations of the photographs fitted so far.
    pub fn parts(&self) -> Vec<Deviation> {
        self.own_parts
            .iter()
            .map(|p| Deviation {
                r: p[0],
                g: p[1],
                b: p[2],
                average: p[3],
            })
            .collect()
    }
}

impl FitState {
    /// A fresh run's state with nothing done.
    pub fn new(identities: Vec<RunIdentity>, rounds: usize) -> FitState {
        FitState {
            format: FORMAT.into(),
            identities,
            rounds,
            base: None,
            shared: Vec::new(),
            own: Vec::new(),
            blocks_done: 0,
            shared_blocks: 0,
            history: Vec::new(),
            evaluations: 0,
            generations: 0,
            failed_renders: 0,
            seconds: 0.0,
            within: Within::default(),
            last_shared: None,
            held_out: Vec::new(),
        }
    }

    /// One photograph's scene with earlier phases' values in place.
    pub fn base(&self) -> Option<&Scene> {
        self.base.as_ref()
    }

    pub fn save(&self, dir: &RunDir) -> Result<()> {
        dir.write_json(CHECKPOINT, self)
    }

    /// Photograph `i`'s scene with a set's current shared and own values.
    pub fn shot_scene(
        &self,
        i: usize,
        scene: &Scene,
        shared: &ParamSpace,
        own: &ParamSpace,
    ) -> Scene {
        let s = shared.scene_at(scene, &self.shared);
        own.scene_at(&s, &self.own[i])
    }

    /// The final (or current) population of one photograph's search in
    /// scene units, for the report.
    pub fn population(&self) -> Option<crate::fit::Population> {
        let base = self.base.as_ref()?;
        let (members, fitness) = self.within.search.as_ref()?.population()?;
        let space = ParamSpace::from_scene(base);
        let phase = *space.phases().get(self.blocks_done)?;
        Some(crate::fit::Population {
            base: base.clone(),
            phase,
            members: members.to_vec(),
            fitness: fitness.to_vec(),
        })
    }
}

/// True when `search` is a search over `dim` coordinates whose
/// population, if it has one, is finite: what a saved search must be for
/// a resume to continue it.
pub fn search_fits(search: &Searcher, dim: usize) -> bool {
    search.best().0.len() == dim
        && search.population().is_none_or(|(p, f)| {
            p.len() == f.len()
                && p.iter()
                    .all(|u| u.len() == dim && u.iter().all(|x| x.is_finite()))
        })
}

/// Where the run in `dir` saved its state: checkpoint.json, or an earlier
/// build's set_state.json.
pub fn saved_in(dir: &RunDir) -> &'static str {
    if !dir.file(CHECKPOINT).is_file() && dir.file(SET_STATE).is_file() {
        SET_STATE
    } else {
        CHECKPOINT
    }
}
