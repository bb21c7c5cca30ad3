//! A fit's saved state read back into the one state type
//! (`state::FitState`): today's format, and those of earlier builds — one
//! photograph's `scenefit-checkpoint/2`, a set's `scenefit-set-state/3`
//! (checkpoint.json) and `/2` (the same fields, in set_state.json). A run
//! saved by an earlier build resumes, and its final population is still
//! reported; any other format is refused naming the key.

use super::state::{saved_in, FitState, Within, FORMAT};
use crate::error::{Error, Result};
use crate::fit::identity::RunIdentity;
use crate::optimize::Searcher;
use crate::rundir::{RunDir, SET_STATE};
use crate::scene::Scene;
use serde::Deserialize;

const ONE_2: &str = "scenefit-checkpoint/2";
const SET_3: &str = "scenefit-set-state/3";
const SET_2: &str = "scenefit-set-state/2";

/// One photograph's checkpoint, format 2.
#[derive(Deserialize)]
struct OneV2 {
    identity: RunIdentity,
    phase_index: usize,
    base: Scene,
    search: Option<Searcher>,
    generation_offset: usize,
    evaluations_before: usize,
    elapsed_before: f64,
}

impl From<OneV2> for FitState {
    fn from(c: OneV2) -> FitState {
        let mut s = FitState::new(vec![c.identity], 0);
        s.base = Some(c.base);
        s.blocks_done = c.phase_index;
        s.within = Within {
            own_parts: Vec::new(),
            search: c.search,
        };
        s.generations = c.generation_offset;
        s.evaluations = c.evaluations_before;
        s.seconds = c.elapsed_before;
        s
    }
}

/// Reads the state saved in `dir` (checkpoint.json, or an earlier build's
/// set_state.json) and checks what holds whatever the run: its format,
/// its seconds.
pub fn load(dir: &RunDir) -> Result<FitState> {
    let name = saved_in(dir);
    let file = dir.file(name).display().to_string();
    let s = read(dir, name, FORMAT)?;
    if !(s.seconds.is_finite() && s.seconds >= 0.0) {
        return Err(Error::invalid(&file, "seconds", "expected seconds >= 0"));
    }
    Ok(s)
}

/// Reads the state file `name` of `dir` in today's format `now` or an
/// earlier one; any other format is refused naming the key.
fn read(dir: &RunDir, name: &str, now: &str) -> Result<FitState> {
    #[derive(Deserialize)]
    struct Head {
        format: Option<String>,
    }
    let what = "a scenefit checkpoint";
    let head: Head = dir.read_json(name, what)?;
    let format = head.format.unwrap_or_default();
    let mut s: FitState =
        if format == now || format == SET_3 || (format == SET_2 && name == SET_STATE) {
            dir.read_json(name, what)?
        } else if format == ONE_2 {
            dir.read_json::<OneV2>(name, what)?.into()
        } else {
            return Err(Error::invalid(
                dir.file(name).display().to_string(),
                "format",
                format!("expected \"{now}\""),
            ));
        };
    s.format = now.into();
    Ok(s)
}
