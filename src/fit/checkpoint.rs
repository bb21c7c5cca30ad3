//! The run's state between generations, saved to checkpoint.json after each
//! one so that `--resume` continues exactly where the run stopped. A
//! finished run keeps its last phase's search in it: its final population
//! (the report's trade-offs), and a larger generation budget resumes it.

use super::identity::RunIdentity;
use crate::error::{Error, Result};
use crate::optimize::{Search, Searcher};
use crate::rundir::{RunDir, CHECKPOINT};
use crate::scene::{ParamSpace, Scene};
use serde::{Deserialize, Serialize};

const FORMAT: &str = "scenefit-checkpoint/2";

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Checkpoint {
    pub format: String,
    pub identity: RunIdentity,
    /// The phase in progress (index into the sorted phases).
    pub phase_index: usize,
    /// The scene with earlier phases' best values in place.
    pub base: Scene,
    /// The phase's search; None before its first generation.
    pub search: Option<Searcher>,
    pub generation_offset: usize,
    pub evaluations_before: usize,
    pub elapsed_before: f64,
}

/// A [`Checkpoint`] as written: the same fields, in the same order, the
/// search borrowed.
#[derive(Serialize)]
struct Saved<'a> {
    format: &'a str,
    identity: &'a RunIdentity,
    phase_index: usize,
    base: &'a Scene,
    search: Option<&'a Searcher>,
    generation_offset: usize,
    evaluations_before: usize,
    elapsed_before: f64,
}

impl Checkpoint {
    pub fn start(base: Scene, identity: RunIdentity) -> Checkpoint {
        Checkpoint {
            format: FORMAT.into(),
            identity,
            phase_index: 0,
            base,
            search: None,
            generation_offset: 0,
            evaluations_before: 0,
            elapsed_before: 0.0,
        }
    }

    /// Reads a run's checkpoint and checks everything in it that a resume
    /// relies on.
    pub fn load(dir: &RunDir) -> Result<Checkpoint> {
        let file = dir.file(CHECKPOINT).display().to_string();
        Checkpoint::check_kind(dir, CHECKPOINT, FORMAT)?;
        let c: Checkpoint = dir.read_json(CHECKPOINT, "a scenefit checkpoint (format 2)")?;
        if c.format != FORMAT {
            return Err(Error::invalid(
                &file,
                "format",
                format!("expected \"{FORMAT}\""),
            ));
        }
        crate::scene::validate::validate(&c.base, &format!("{file} (base)"))?;
        let space = ParamSpace::from_scene(&c.base);
        let phases = space.phases();
        let Some(&phase) = phases.get(c.phase_index) else {
            return Err(Error::invalid(
                &file,
                "phase_index",
                "past the scene's phases",
            ));
        };
        if let Some(s) = &c.search {
            let dim = space.phase(phase).dim();
            if !Checkpoint::search_fits(s, dim) {
                return Err(Error::invalid(
                    &file,
                    "search",
                    format!("does not match the scene's {dim} free coordinates of phase {phase}"),
                ));
            }
        }
        if !(c.elapsed_before.is_finite() && c.elapsed_before >= 0.0) {
            return Err(Error::invalid(
                &file,
                "elapsed_before",
                "expected seconds >= 0",
            ));
        }
        Ok(c)
    }

    /// Refuses a resume whose inputs differ from the checkpoint's run.
    pub fn check_identity(&self, dir: &RunDir, now: &RunIdentity) -> Result<()> {
        match self.identity.mismatch(now) {
            None => Ok(()),
            Some(what) => Err(Checkpoint::refuse(
                &dir.file(CHECKPOINT).display().to_string(),
                &what,
            )),
        }
    }

    /// The refusal of a resume whose inputs differ (`what`) from those of
    /// the run saved in `file`: one photograph's or a set's.
    pub fn refuse(file: &str, what: &str) -> Error {
        Error::Usage(format!(
            "cannot resume the run saved in {file}: {what}; resume with the same inputs and options, or start afresh with --overwrite"
        ))
    }

    /// Refuses the state file `name` when it was saved by the other kind
    /// of fit (one photograph's checkpoint read for a set, or a set's for
    /// one photograph), saying which it holds; `want` is the format this
    /// run reads. Any other format is left to the reader's own check.
    pub fn check_kind(dir: &RunDir, name: &str, want: &str) -> Result<()> {
        #[derive(Deserialize)]
        struct Head {
            format: Option<String>,
        }
        let Ok(head) = dir.read_json::<Head>(name, "a scenefit checkpoint") else {
            return Ok(());
        };
        let is_set = |f: &str| f.starts_with("scenefit-set-state/");
        let holds = match head.format.as_deref() {
            Some(f) if (is_set(f) || f == FORMAT) && is_set(f) != is_set(want) => {
                if is_set(f) {
                    "a set's fit (fit --shots)"
                } else {
                    "one photograph's fit (fit --target)"
                }
            }
            _ => return Ok(()),
        };
        Err(Error::Usage(format!(
            "cannot resume the run saved in {}: it holds {holds}; resume it with the inputs it was started with, or start afresh with --overwrite",
            dir.file(name).display()
        )))
    }

    /// True when `search` is a search over `dim` coordinates whose
    /// population, if it has one, is finite: what a saved search must be
    /// for a resume to continue it.
    pub fn search_fits(search: &Searcher, dim: usize) -> bool {
        search.best().0.len() == dim
            && search.population().is_none_or(|(p, f)| {
                p.len() == f.len()
                    && p.iter()
                        .all(|u| u.len() == dim && u.iter().all(|x| x.is_finite()))
            })
    }

    /// Refuses a checkpoint whose scene declares another image size than
    /// the run's scene: the size the run's memory was checked for
    /// (`scene::memory`) is the size it renders at.
    pub fn check_image(&self, dir: &RunDir, scene: &Scene) -> Result<()> {
        let (b, s) = (&self.base.image, &scene.image);
        if (b.width, b.height) == (s.width, s.height) {
            return Ok(());
        }
        Err(Error::invalid(
            dir.file(CHECKPOINT).display().to_string(),
            "base.image",
            format!(
                "declares {}x{} pixels; expected the scene's {}x{}",
                b.width, b.height, s.width, s.height
            ),
        ))
    }

    pub fn save(&self, dir: &RunDir) -> Result<()> {
        dir.write_json(CHECKPOINT, &self.saved(self.search.as_ref()))
    }

    /// Saves the checkpoint with `search` as its search, borrowed: the fit
    /// saves after every generation and need not copy the search for it.
    pub fn save_with(&self, dir: &RunDir, search: &Searcher) -> Result<()> {
        dir.write_json(CHECKPOINT, &self.saved(Some(search)))
    }

    fn saved<'a>(&'a self, search: Option<&'a Searcher>) -> Saved<'a> {
        Saved {
            format: &self.format,
            identity: &self.identity,
            phase_index: self.phase_index,
            base: &self.base,
            search,
            generation_offset: self.generation_offset,
            evaluations_before: self.evaluations_before,
            elapsed_before: self.elapsed_before,
        }
    }

    /// The final (or current) population in scene units, for the report.
    pub fn population(&self) -> Option<super::Population> {
        let search = self.search.as_ref()?;
        let (members, fitness) = search.population()?;
        let space = ParamSpace::from_scene(&self.base);
        let phase = *space.phases().get(self.phase_index)?;
        Some(super::Population {
            base: self.base.clone(),
            phase,
            members: members.to_vec(),
            fitness: fitness.to_vec(),
        })
    }
}
