//! A set fit's state, saved (checkpoint.json, the file a single fit's
//! checkpoint has) when the run starts, after
//! every photograph of a per-shot block and every generation of a shared
//! block, so that `--resume` continues where the run stopped and ends
//! where an uninterrupted run ends: a photograph's fit cut short is redone
//! from its own seed, a shared block continues from its saved search.
//! Every `f64` a later block reads is stored bit-exactly
//! (`optimize::exact`): a value off by one ulp would send the resumed run
//! elsewhere. It records what defines the run (one identity per
//! photograph) and refuses a resume with other inputs. A set run saved
//! by an earlier build (`set_state.json`, format 2) still resumes.

use super::SetConfig;
use crate::error::{Error, Result};
use crate::fit::identity::RunIdentity;
use crate::fit::set::shots::Shot;
use crate::metric::Deviation;
use crate::optimize::{exact, Searcher};
use crate::render::Renderer;
use crate::rundir::{RunDir, CHECKPOINT, SET_STATE};
use crate::scene::{ParamSpace, Scene};
use serde::{Deserialize, Serialize};

/// Format 3: format 2 (values bit-exact, the progress within a block)
/// and the last shared block's search, saved as checkpoint.json.
pub const FORMAT: &str = "scenefit-set-state/3";
/// Format 2, saved as set_state.json by earlier builds: still resumed.
const FORMAT_2: &str = "scenefit-set-state/2";

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SetState {
    pub format: String,
    /// One per photograph, in the shots file's order.
    pub identities: Vec<RunIdentity>,
    pub rounds: usize,
    /// The shared parameters, unit cube.
    #[serde(with = "exact::vector")]
    pub shared: Vec<f64>,
    /// Each photograph's own parameters, unit cube.
    #[serde(with = "exact::matrix")]
    pub own: Vec<Vec<f64>>,
    pub blocks_done: usize,
    pub shared_blocks: usize,
    /// The set's average deviation after each block.
    #[serde(with = "exact::vector")]
    pub history: Vec<f64>,
    /// Renders so far.
    pub evaluations: usize,
    pub generations: usize,
    pub failed_renders: usize,
    pub seconds: f64,
    /// What of the block in progress is done.
    pub within: Within,
    /// The last finished shared block's search: its standard errors
    /// (result.json's `identifiability`).
    #[serde(default)]
    pub last_shared: Option<Searcher>,
}

/// The progress within the block in progress (empty between blocks).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Within {
    /// A per-shot block: the deviation (r, g, b, average) of each
    /// photograph fitted so far, in order.
    #[serde(with = "exact::matrix")]
    pub own_parts: Vec<Vec<f64>>,
    /// A shared block: its search after its last generation.
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

impl SetState {
    /// A fresh run's state: every value as the scene (and each shot's
    /// `set`) gives it.
    pub fn start(
        scene: &Scene,
        shots: &[Shot],
        renderer: &dyn Renderer,
        config: &SetConfig,
        space: &ParamSpace,
    ) -> SetState {
        SetState {
            format: FORMAT.into(),
            identities: identities(shots, renderer, config),
            rounds: config.rounds,
            shared: space.shared().unit_of(scene),
            own: shots
                .iter()
                .map(|s| s.own_space(space).unit_of(&s.scene))
                .collect(),
            blocks_done: 0,
            shared_blocks: 0,
            history: Vec::new(),
            evaluations: 0,
            generations: 0,
            failed_renders: 0,
            seconds: 0.0,
            within: Within::default(),
            last_shared: None,
        }
    }

    /// The saved state of the run in `dir`, checked against this run's
    /// inputs.
    pub fn resume(
        dir: &RunDir,
        scene: &Scene,
        shots: &[Shot],
        renderer: &dyn Renderer,
        config: &SetConfig,
        space: &ParamSpace,
    ) -> Result<SetState> {
        let name = saved_in(dir);
        let file = dir.file(name).display().to_string();
        crate::fit::Checkpoint::check_kind(dir, name, FORMAT)?;
        let s: SetState = dir.read_json(name, "a scenefit set state")?;
        let bad = |key: &str, what: &str| Error::invalid(&file, key, what);
        if s.format != FORMAT && !(name == SET_STATE && s.format == FORMAT_2) {
            return Err(bad("format", &format!("expected \"{FORMAT}\"")));
        }
        let now = identities(shots, renderer, config);
        let refuse = |what: String| crate::fit::Checkpoint::refuse(&file, &what);
        if s.identities.len() != now.len() {
            return Err(refuse(format!(
                "the shots file listed {} photographs, now {}",
                s.identities.len(),
                now.len()
            )));
        }
        for ((was, is), shot) in s.identities.iter().zip(&now).zip(shots) {
            if let Some(what) = was.mismatch(is) {
                return Err(refuse(format!("shot {}: {what}", shot.name)));
            }
        }
        if s.rounds != config.rounds {
            return Err(refuse(format!(
                "--rounds was {}, now {}",
                s.rounds, config.rounds
            )));
        }
        let fresh = SetState::start(scene, shots, renderer, config, space);
        let unit = |v: &[f64]| v.iter().all(|x| (0.0..=1.0).contains(x));
        let sizes_ok = s.shared.len() == fresh.shared.len()
            && unit(&s.shared)
            && s.own.len() == fresh.own.len()
            && s.own
                .iter()
                .zip(&fresh.own)
                .all(|(a, b)| a.len() == b.len() && unit(a));
        if !sizes_ok {
            return Err(bad(
                "shared",
                "expected unit-cube values for every free parameter of the scene",
            ));
        }
        if !(s.seconds.is_finite() && s.seconds >= 0.0) {
            return Err(bad("seconds", "expected seconds >= 0"));
        }
        check_within(&s, shots.len(), fresh.shared.len()).map_err(|(k, w)| bad(k, w))?;
        Ok(s)
    }

    pub fn save(&self, dir: &RunDir) -> Result<()> {
        dir.write_json(CHECKPOINT, self)
    }

    /// Photograph `i`'s scene with the current shared and own values.
    pub fn shot_scene(
        &self,
        i: usize,
        shot: &Shot,
        shared: &ParamSpace,
        own: &ParamSpace,
    ) -> Scene {
        let s = shared.scene_at(&shot.scene, &self.shared);
        own.scene_at(&s, &self.own[i])
    }
}

/// The progress within a block, checked against the set: no more parts
/// than photographs, each four finite numbers; a search over the shared
/// coordinates.
fn check_within(
    s: &SetState,
    shots: usize,
    shared: usize,
) -> std::result::Result<(), (&'static str, &'static str)> {
    let w = &s.within;
    let parts_ok = w.own_parts.len() <= shots
        && w.own_parts
            .iter()
            .all(|p| p.len() == 4 && p.iter().all(|x| x.is_finite() && *x >= 0.0));
    if !parts_ok {
        return Err((
            "within.own_parts",
            "expected four deviations >= 0 for each photograph fitted so far",
        ));
    }
    let fits = |q: &Searcher| crate::fit::Checkpoint::search_fits(q, shared);
    let search_ok = w.search.as_ref().is_none_or(fits) && s.last_shared.as_ref().is_none_or(fits);
    if !search_ok || (w.search.is_some() && !w.own_parts.is_empty()) {
        return Err((
            "within.search",
            "expected a search over the scene's shared coordinates",
        ));
    }
    let unit_ok = s.history.iter().all(|h| h.is_finite() && *h >= 0.0);
    if !unit_ok {
        return Err(("history", "expected deviations >= 0"));
    }
    Ok(())
}

/// Where the run in `dir` saved its state: checkpoint.json, or an earlier
/// build's set_state.json.
fn saved_in(dir: &RunDir) -> &'static str {
    if !dir.file(CHECKPOINT).is_file() && dir.file(SET_STATE).is_file() {
        SET_STATE
    } else {
        CHECKPOINT
    }
}

fn identities(shots: &[Shot], renderer: &dyn Renderer, config: &SetConfig) -> Vec<RunIdentity> {
    shots
        .iter()
        .map(|s| RunIdentity::of(&s.scene, &s.target, &renderer.name(), &config.fit))
        .collect()
}
