//! Consistency checks on a [`De`] state read from outside (a checkpoint).
//!
//! The engine indexes its vectors freely, trusting the shapes its
//! constructors build. A state from a file has no such guarantee, so these
//! checks run on every deserialisation and turn a damaged or hand-edited
//! checkpoint into an error message instead of a panic mid-run.

use super::config::MIN_POPULATION;
use super::de::{Adaptation, De};

impl De {
    pub(super) fn check_invariants(&self) -> Result<(), String> {
        let np = self.config.population;
        let dim = self.dim;
        if np < MIN_POPULATION {
            return Err(format!("population {np} is below {MIN_POPULATION}"));
        }
        if self.adaptation.strategy() != self.config.strategy {
            return Err(format!(
                "adaptive state is for {} but the config says {}",
                self.adaptation.strategy(),
                self.config.strategy
            ));
        }
        if self.population.len() != np || self.fitness.len() != np {
            return Err(format!(
                "{} individuals and {} fitness values for a population of {np}",
                self.population.len(),
                self.fitness.len()
            ));
        }
        check_points("population", &self.population, dim)?;
        if self
            .fitness
            .iter()
            .any(|f| f.is_nan() || *f == f64::NEG_INFINITY)
        {
            return Err("fitness holds NaN or -inf (failures are stored as +inf)".to_string());
        }
        if let Some(batch) = &self.pending {
            if !self.evaluated {
                return Err("trials pending before the initial population was told".to_string());
            }
            if batch.trials.len() != np || batch.f.len() != np || batch.cr.len() != np {
                return Err(format!("pending batch is not of size {np}"));
            }
            check_points("pending trial", &batch.trials, dim)?;
        }
        if !self.evaluated && (self.generation != 0 || self.evaluations != 0) {
            return Err("counters advanced before the initial population was told".to_string());
        }
        if self.progress.last_improvement_generation() > self.generation {
            return Err("last improvement is after the current generation".to_string());
        }
        match &self.adaptation {
            Adaptation::Fixed => Ok(()),
            Adaptation::Jde(jde) => jde.check(np),
            Adaptation::Shade(shade) => shade.check(np, dim),
        }
    }
}

/// Every point has `dim` coordinates, all inside the unit cube.
fn check_points(what: &str, points: &[Vec<f64>], dim: usize) -> Result<(), String> {
    for (i, point) in points.iter().enumerate() {
        if point.len() != dim {
            return Err(format!(
                "{what} {i} has {} coordinates, expected {dim}",
                point.len()
            ));
        }
        if !point.iter().all(|x| (0.0..=1.0).contains(x)) {
            return Err(format!("{what} {i} leaves the unit cube"));
        }
    }
    Ok(())
}
