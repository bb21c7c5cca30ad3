//! A set fit's state between blocks, saved after every block
//! (`set_state.json`) so that `--resume` continues from the last finished
//! one; it records what defines the run (one identity per photograph) and
//! refuses a resume with other inputs.

use super::SetConfig;
use crate::error::{Error, Result};
use crate::fit::identity::RunIdentity;
use crate::fit::set::shots::Shot;
use crate::render::Renderer;
use crate::rundir::{RunDir, SET_STATE};
use crate::scene::{ParamSpace, Scene};
use serde::{Deserialize, Serialize};

const FORMAT: &str = "scenefit-set-state/1";

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SetState {
    pub format: String,
    /// One per photograph, in the shots file's order.
    pub identities: Vec<RunIdentity>,
    pub rounds: usize,
    /// The shared parameters, unit cube.
    pub shared: Vec<f64>,
    /// Each photograph's own parameters, unit cube.
    pub own: Vec<Vec<f64>>,
    pub blocks_done: usize,
    pub shared_blocks: usize,
    /// The set's average deviation after each block.
    pub history: Vec<f64>,
    /// Renders so far.
    pub evaluations: usize,
    pub generations: usize,
    pub failed_renders: usize,
    pub seconds: f64,
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
        let file = dir.file(SET_STATE).display().to_string();
        let s: SetState = dir.read_json(SET_STATE, "a scenefit set state")?;
        let bad = |key: &str, what: &str| Error::invalid(&file, key, what);
        if s.format != FORMAT {
            return Err(bad("format", &format!("expected \"{FORMAT}\"")));
        }
        let now = identities(shots, renderer, config);
        let refuse = |what: String| {
            Error::Usage(format!(
                "cannot resume the run in {}: {what}; resume with the same inputs and options, or start afresh with --overwrite",
                dir.path().display()
            ))
        };
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
        Ok(s)
    }

    pub fn save(&self, dir: &RunDir) -> Result<()> {
        dir.write_json(SET_STATE, self)
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

fn identities(shots: &[Shot], renderer: &dyn Renderer, config: &SetConfig) -> Vec<RunIdentity> {
    shots
        .iter()
        .map(|s| RunIdentity::of(&s.scene, &s.target, &renderer.name(), &config.fit))
        .collect()
}
