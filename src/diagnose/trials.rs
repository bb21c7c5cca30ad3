//! An effect's trials (one per form, each at its best start) and every
//! refit of a diagnosis, dispatched on its `Schedule`: the one place that
//! tells one photograph's refits (`one_refit.rs`) from a set's
//! (`set_refit.rs`), and where a closed-form effect's one trial is solved
//! (`albedo.rs`) rather than searched.
//!
//! One photograph: each effect refitted warm (its own parameters searched
//! first) and from scratch, the better counting; the unchanged model
//! refitted the same two ways; an accepted model polished. A set: each
//! effect refitted warm over the set; an accepted one also from scratch;
//! the final model polished once more.

use super::effects::{self, Effect};
use super::inputs::Params;
use super::model::Model;
use super::one_refit::{Refine, Search};
use super::refits::Refits;
use super::schedule::{Refit, Schedule};
use super::Candidate;
use crate::error::Result;
use crate::scene::{FreeParam, Scene};

/// An effect added to the model in one of its forms, at its best start,
/// ready for its refits.
pub(super) struct Trial {
    pub effect: &'static dyn Effect,
    /// Which of the effect's forms.
    pub form: usize,
    pub start: Scene,
    /// Each photograph's own values at the start.
    pub own: Vec<Params>,
    /// The free entries the effect added.
    pub added: Vec<FreeParam>,
    /// Its refits, the preferred first (a tie keeps the earlier).
    pub refits: Vec<Refit>,
}

impl Refits<'_> {
    /// `effect`'s trials on `model`: one per form, each at its best start
    /// (renders counted); a closed-form effect's one trial at the model
    /// itself; none when it does not apply.
    pub(super) fn trials(
        &mut self,
        model: &Model,
        effect: &'static dyn Effect,
    ) -> Result<Vec<Trial>> {
        let trial = |form, start, own, added, refits| Trial {
            effect,
            form,
            start,
            own,
            added,
            refits,
        };
        if effect.closed_form() {
            let applies = effect.applies(&model.scene);
            return Ok(applies
                .then(|| {
                    let (scene, own) = (model.scene.clone(), model.own.clone());
                    trial(0, scene, own, Vec::new(), vec![Refit::ClosedForm])
                })
                .into_iter()
                .collect());
        }
        let refits = match self.schedule {
            Schedule::One if self.config.restart_generations > 0 => {
                vec![Refit::Warm, Refit::Scratch]
            }
            Schedule::One => vec![Refit::Warm],
            Schedule::Set => vec![Refit::WarmSet],
        };
        let mut trials = Vec::new();
        for (form, ext) in effects::forms(effect, &model.scene).into_iter().enumerate() {
            let (start, own) = self.best_start(&ext, &model.own)?;
            trials.push(trial(form, start, own, ext.added, refits.clone()));
        }
        Ok(trials)
    }

    /// `trial` refitted by `refit` (in round `round`, from `model`): the
    /// model, and the values it solved beyond its free ones (None: a
    /// closed-form effect solved nothing).
    pub(super) fn refit(
        &mut self,
        trial: &Trial,
        refit: Refit,
        model: &Model,
        round: usize,
    ) -> Result<Option<(Model, usize)>> {
        let c = self.config;
        let trades = trial.effect.trades();
        let fitted = match refit {
            Refit::Warm => {
                let search = Search {
                    params: trades.search(&trial.start, &trial.added),
                    radius: trades.radius,
                };
                let close = Refine::close(c, c.refine_generations);
                self.run_one(&trial.start, Some(search), close)?
            }
            Refit::Scratch => self.run_one(&trial.start, None, Refine::restart(c))?,
            Refit::WarmSet => {
                // The effect's own parameters spread as its refit for one
                // photograph spreads them: they hold a neutral guess, not
                // a fit.
                let spread = trial
                    .added
                    .iter()
                    .map(|a| (a.param.clone(), trades.radius))
                    .collect();
                self.run_spread(&trial.start, &trial.own, spread)?
            }
            Refit::ClosedForm => {
                let kind = trial
                    .effect
                    .map_kind()
                    .expect("a closed-form effect solves a map");
                return super::albedo::solved(self, model, round, kind);
            }
        };
        Ok(Some((fitted, 0)))
    }

    /// The unchanged model refitted as an effect's model will be, the
    /// better kept.
    pub(super) fn unchanged(&mut self, model: Model) -> Result<Model> {
        match self.schedule {
            Schedule::One => self.unchanged_one(model),
            Schedule::Set => match self.null(&model)? {
                Some(null) => Ok(model.better(null)),
                None => Ok(model),
            },
        }
    }

    /// The unchanged model refitted as a round's searched candidates are
    /// (a set's warm refit), the baseline of that round's gains: what
    /// the refit reaches without any effect is credited to none. None for
    /// one photograph, whose candidates are measured against the model
    /// refitted once before the rounds and polished when accepted.
    pub(super) fn null(&mut self, model: &Model) -> Result<Option<Model>> {
        match self.schedule {
            Schedule::One => Ok(None),
            Schedule::Set => self.run_set(&model.scene, &model.own).map(Some),
        }
    }

    /// `scene` with `own` values refitted warm: the refit of a rebuilt
    /// model (`backward.rs`) and of a solved map (`albedo.rs`).
    pub(super) fn warm(&mut self, scene: &Scene, own: &[Params]) -> Result<Model> {
        match self.schedule {
            Schedule::One => self.run_one(scene, None, Refine::warm(self.config)),
            Schedule::Set => self.run_set(scene, own),
        }
    }

    /// The refit of a solved map's model: one photograph's short refit,
    /// a set's warm one.
    pub(super) fn after_solve(&mut self, scene: &Scene, own: &[Params]) -> Result<Model> {
        match self.schedule {
            Schedule::One => {
                let close = Refine::close(self.config, self.config.refine_generations);
                self.run_one(scene, None, close)
            }
            Schedule::Set => self.run_set(scene, own),
        }
    }

    /// An accepted candidate's model refitted once more, the better kept:
    /// one photograph's polished around it; a set's refitted from scratch
    /// (`chosen` then says so), since a warm refit keeps what the model
    /// had bent to absorb the effect it lacked.
    pub(super) fn settle(&mut self, model: Model, chosen: &mut Candidate) -> Result<Model> {
        match self.schedule {
            Schedule::One if self.config.polish_generations > 0 => {
                let polished = self.run_one(&model.scene, None, Refine::polish(self.config))?;
                Ok(model.better(polished))
            }
            Schedule::One => Ok(model),
            Schedule::Set => {
                let scratch = self.scratch(&model.scene, &model.own)?;
                if scratch.sad < model.sad {
                    chosen.refit = "warm (set), then from scratch (set)".into();
                    chosen.deviation_after = Some(scratch.deviation(self.inputs));
                    return Ok(scratch);
                }
                Ok(model)
            }
        }
    }

    /// The model after the rounds: a set's, once effects were accepted,
    /// refitted warm again. Why: the last refit stopped where block
    /// descent slows, along a valley where shared and per-shot values
    /// trade; a warm refit from there goes on down it.
    pub(super) fn finish(&mut self, model: Model, accepted: bool) -> Result<Model> {
        if self.schedule == Schedule::One || !accepted {
            return Ok(model);
        }
        let polished = self.run_set(&model.scene, &model.own)?;
        Ok(model.better(polished))
    }
}
