//! The distinct places a search has seen that fit as well as its best,
//! within the noise of an 8-bit photograph ([`Basins`]): what result.json
//! lists as `alternatives`, so that a user learns when two answers fit
//! alike instead of being handed one of them silently.
//!
//! The search offers the places its descents end at (the hybrid: each
//! local run's end, from every population it draws; a population search:
//! its final population). A point is kept when its
//! fitness is alike the best's ([`alike`]) and it is farther than
//! [`SEPARATION`] (max-norm, unit cube) from every point kept; a point near
//! a kept one replaces it when it is better, so each kept point is the best
//! seen in its neighbourhood. Points that stop being alike as the best
//! improves are dropped, and at most [`KEEP`] are kept (the worst go
//! first), so the state stays small in a checkpoint.
//!
//! Two places that fit alike are two answers the photograph does not tell
//! apart, whether they lie in two basins (two lights swapped) or along one
//! valley (a light's intensity against a colour's brightness, when nothing
//! else in the image fixes either): both are reported.

use serde::{Deserialize, Serialize};

use super::exact;

/// Two points closer than this in every unit coordinate are one answer.
pub const SEPARATION: f64 = 0.1;
/// Fitness within this fraction of the best's is alike: the deviations of
/// two fits of one photograph differ by a few percent from its noise alone
/// (8-bit rounding, sensor noise), so a smaller difference says nothing.
pub const ALIKE_RELATIVE: f64 = 0.02;
/// And within this much in absolute terms: one 8-bit level on one value in
/// a thousand, in each channel (fitness is the sum of the three channels'
/// deviations in percent), so that on an exact target (best fitness 0) a
/// point is alike only when it too renders (nearly) the same image.
pub const ALIKE_ABSOLUTE: f64 = 3.0 * 100.0 / 255.0 * 1e-3;
/// At most this many points are kept.
pub const KEEP: usize = 8;

/// Whether `other` fits alike `best` (see the module docs).
pub fn alike(best: f64, other: f64) -> bool {
    other.is_finite() && other <= best + best.abs() * ALIKE_RELATIVE + ALIKE_ABSOLUTE
}

/// The largest per-coordinate distance between two points.
fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Points of distinct places that fit alike the best (see the module docs).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Basins {
    #[serde(with = "exact::matrix")]
    points: Vec<Vec<f64>>,
    #[serde(with = "exact::vector")]
    fitness: Vec<f64>,
}

impl Basins {
    /// Offers an evaluated point; `best` is the search's best fitness so
    /// far (including this point's).
    pub fn offer(&mut self, point: &[f64], fitness: f64, best: f64) {
        if !alike(best, fitness) {
            self.prune(best);
            return;
        }
        let near = (0..self.points.len()).find(|&i| distance(&self.points[i], point) <= SEPARATION);
        match near {
            Some(i) if fitness < self.fitness[i] => {
                self.points[i] = point.to_vec();
                self.fitness[i] = fitness;
            }
            Some(_) => {}
            None => {
                self.points.push(point.to_vec());
                self.fitness.push(fitness);
            }
        }
        self.prune(best);
    }

    /// Drops the points no longer alike `best`, then the worst beyond
    /// [`KEEP`].
    fn prune(&mut self, best: f64) {
        let mut kept: Vec<(Vec<f64>, f64)> = std::mem::take(&mut self.points)
            .into_iter()
            .zip(std::mem::take(&mut self.fitness))
            .filter(|(_, f)| alike(best, *f))
            .collect();
        // Stable: equal fitness keeps the order seen, so a run is repeatable.
        kept.sort_by(|a, b| a.1.total_cmp(&b.1));
        kept.truncate(KEEP);
        (self.points, self.fitness) = kept.into_iter().unzip();
    }

    /// The kept points other than the best's own place, best first, each
    /// with its fitness, that are still alike `best`.
    pub fn alternatives(&self, best_point: &[f64], best: f64) -> Vec<(Vec<f64>, f64)> {
        let mut found: Vec<(Vec<f64>, f64)> = self
            .points
            .iter()
            .zip(&self.fitness)
            .filter(|(p, f)| alike(best, **f) && distance(p, best_point) > SEPARATION)
            .map(|(p, f)| (p.clone(), *f))
            .collect();
        found.sort_by(|a, b| a.1.total_cmp(&b.1));
        found
    }

    /// Whether every kept point has `dim` coordinates.
    pub fn fits(&self, dim: usize) -> bool {
        self.points.len() == self.fitness.len() && self.points.iter().all(|p| p.len() == dim)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_distinct_places_that_fit_alike() {
        let mut basins = Basins::default();
        basins.offer(&[0.2, 0.2], 1.0, 1.0);
        basins.offer(&[0.8, 0.2], 1.01, 1.0);
        // Near the first: replaces nothing (worse), adds nothing.
        basins.offer(&[0.25, 0.2], 1.005, 1.0);
        // Clearly worse: not alike.
        basins.offer(&[0.5, 0.9], 1.5, 1.0);
        let alt = basins.alternatives(&[0.2, 0.2], 1.0);
        assert_eq!(alt, vec![(vec![0.8, 0.2], 1.01)]);
    }

    #[test]
    fn a_better_best_drops_what_no_longer_fits_alike() {
        let mut basins = Basins::default();
        basins.offer(&[0.2, 0.2], 1.0, 1.0);
        basins.offer(&[0.8, 0.2], 1.01, 1.0);
        basins.offer(&[0.21, 0.2], 0.5, 0.5);
        assert!(basins.alternatives(&[0.21, 0.2], 0.5).is_empty());
        assert_eq!(basins.points, vec![vec![0.21, 0.2]]);
    }

    #[test]
    fn an_exact_fit_has_alternatives_only_when_they_are_exact_too() {
        assert!(alike(0.0, 0.0005));
        assert!(!alike(0.0, 0.01));
        assert!(alike(10.0, 10.19) && !alike(10.0, 10.3));
    }
}
