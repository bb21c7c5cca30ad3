//! Interchangeable coordinates: permutations of the unit coordinates that
//! the problem declares may render the same image (two lights of one kind,
//! free over the same bounds: swapping their values swaps which light is
//! which). Restarts find the other basin of such a swap only by chance —
//! each population lands in one of them — so where a local run ends alike
//! the best, the hybrid also evaluates its swapped points, one render each,
//! and offers them to [`Basins`](super::basins::Basins): a swap that fits
//! alike is reported as an alternative in every run, not in about half.
//! Whether it fits alike is the render's to say (the lights' fixed colours
//! may differ); the declaration only names which swaps to try.

use serde::{Deserialize, Serialize};

use super::basins::SEPARATION;
use super::exact;

/// The declared swaps and the swapped points awaiting a render.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Swaps {
    /// Each a permutation of the coordinates: coordinate `i` of the
    /// swapped point is coordinate `perm[i]` of the point.
    perms: Vec<Vec<usize>>,
    #[serde(with = "exact::matrix")]
    queue: Vec<Vec<f64>>,
}

impl Swaps {
    /// Keeps the permutations of `dim` coordinates that are permutations
    /// and move something; the rest are ignored.
    pub fn declare(&mut self, dim: usize, perms: Vec<Vec<usize>>) {
        self.perms = perms
            .into_iter()
            .filter(|p| is_permutation(p, dim) && p.iter().enumerate().any(|(i, &j)| i != j))
            .collect();
    }

    /// Queues the swapped points of `x` that lie in another place (farther
    /// than [`SEPARATION`] in some coordinate).
    pub fn queue_from(&mut self, x: &[f64]) {
        for p in &self.perms {
            if p.len() != x.len() {
                continue;
            }
            let swapped: Vec<f64> = p.iter().map(|&j| x[j]).collect();
            let far = swapped
                .iter()
                .zip(x)
                .any(|(a, b)| (a - b).abs() > SEPARATION);
            if far && !self.queue.contains(&swapped) {
                self.queue.push(swapped);
            }
        }
    }

    /// The points awaiting a render, if any.
    pub fn pending(&self) -> Option<&[Vec<f64>]> {
        (!self.queue.is_empty()).then_some(self.queue.as_slice())
    }

    /// The points rendered, removed from the queue.
    pub fn take(&mut self) -> Vec<Vec<f64>> {
        std::mem::take(&mut self.queue)
    }

    /// Whether every permutation and queued point has `dim` coordinates.
    pub fn fits(&self, dim: usize) -> bool {
        self.perms.iter().all(|p| is_permutation(p, dim))
            && self.queue.iter().all(|q| q.len() == dim)
    }
}

fn is_permutation(p: &[usize], dim: usize) -> bool {
    let mut seen = vec![false; dim];
    p.len() == dim
        && p.iter()
            .all(|&j| j < dim && !std::mem::replace(&mut seen[j], true))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_swap_queues_the_other_place_once_and_ignores_a_point_it_leaves_in_place() {
        let mut s = Swaps::default();
        // Swap coordinates 0 and 1; the second "permutation" repeats a
        // coordinate and the third moves nothing: both ignored.
        s.declare(3, vec![vec![1, 0, 2], vec![0, 0, 2], vec![0, 1, 2]]);
        s.queue_from(&[0.2, 0.8, 0.5]);
        s.queue_from(&[0.2, 0.8, 0.5]);
        assert_eq!(s.pending(), Some(&[vec![0.8, 0.2, 0.5]][..]));
        assert_eq!(s.take(), vec![vec![0.8, 0.2, 0.5]]);
        assert!(s.pending().is_none());
        // On the symmetry's own line the swap is the same place.
        s.queue_from(&[0.5, 0.52, 0.1]);
        assert!(s.pending().is_none());
        assert!(s.fits(3) && !s.fits(4));
    }
}
