//! jDE: per-individual self-adaptation of F and CR (Brest et al. 2006).
//!
//! Before making its trial, each individual may resample its F (with
//! probability tau1, uniformly in [0.1, 1.0]) and its CR (with probability
//! tau2, uniformly in [0, 1]). The trial is built by DE/rand/1/bin with
//! those values, and they are kept only if the trial wins selection: good
//! settings survive with the individuals they produced.

use rand::Rng;
use serde::{Deserialize, Serialize};

use super::{exact, sampling};

/// tau1 and tau2 of Brest et al., both 0.1 there: the chance that an
/// individual resamples its F, and (apart) its CR.
const TAU: f64 = 0.1;
/// F is resampled as `F_LOWER + rand * F_SPAN`, i.e. in [0.1, 1.0].
const F_LOWER: f64 = 0.1;
const F_SPAN: f64 = 0.9;
/// The paper's starting values.
const F_INITIAL: f64 = 0.5;
const CR_INITIAL: f64 = 0.9;

/// Each individual's current F and CR.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JdeState {
    #[serde(with = "exact::vector")]
    f: Vec<f64>,
    #[serde(with = "exact::vector")]
    cr: Vec<f64>,
}

impl JdeState {
    pub fn new(np: usize) -> Self {
        JdeState {
            f: vec![F_INITIAL; np],
            cr: vec![CR_INITIAL; np],
        }
    }

    /// The F and CR individual `i` uses for its next trial.
    pub fn propose<R: Rng>(&self, i: usize, rng: &mut R) -> (f64, f64) {
        let f = if sampling::unit(rng) < TAU {
            F_LOWER + sampling::unit(rng) * F_SPAN
        } else {
            self.f[i]
        };
        let cr = if sampling::unit(rng) < TAU {
            sampling::unit(rng)
        } else {
            self.cr[i]
        };
        (f, cr)
    }

    /// Individual `i`'s trial won, so it inherits the trial's settings.
    pub fn accept(&mut self, i: usize, f: f64, cr: f64) {
        self.f[i] = f;
        self.cr[i] = cr;
    }

    /// Per-individual F values (for inspection and tests).
    pub fn f(&self) -> &[f64] {
        &self.f
    }

    /// Checks a loaded state against the population size.
    pub fn check(&self, np: usize) -> Result<(), String> {
        if self.f.len() != np || self.cr.len() != np {
            return Err(format!(
                "jDE keeps {} F and {} CR values for {np} individuals",
                self.f.len(),
                self.cr.len()
            ));
        }
        if !self.f.iter().chain(&self.cr).all(|v| v.is_finite()) {
            return Err("jDE F or CR value is not finite".to_string());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn resamples_about_one_in_ten_within_the_ranges() {
        let state = JdeState::new(1);
        let mut rng = ChaCha8Rng::seed_from_u64(10);
        let n = 20_000;
        let (mut new_f, mut new_cr) = (0, 0);
        for _ in 0..n {
            let (f, cr) = state.propose(0, &mut rng);
            assert!((0.1..=1.0).contains(&f) && (0.0..=1.0).contains(&cr));
            new_f += usize::from(f != F_INITIAL);
            new_cr += usize::from(cr != CR_INITIAL);
        }
        let share = |k: usize| k as f64 / n as f64;
        assert!(
            (share(new_f) - TAU).abs() < 0.01,
            "F resampled {}",
            share(new_f)
        );
        assert!(
            (share(new_cr) - TAU).abs() < 0.01,
            "CR resampled {}",
            share(new_cr)
        );
    }

    #[test]
    fn only_accepted_settings_are_kept() {
        let mut state = JdeState::new(2);
        state.accept(1, 0.3, 0.2);
        assert_eq!(state.f(), &[F_INITIAL, 0.3]);
        assert_eq!(state.cr, vec![CR_INITIAL, 0.2]);
    }
}
