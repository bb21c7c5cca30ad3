//! How a set fit is set up: its options (`SetConfig`), every field its
//! renders vary, and each block's seed and search options; what the
//! blocks, the joint block, the outcome, the predictions of held-out
//! photographs and the state between blocks share.

use super::shots::Shot;
use crate::fit::FitConfig;
use crate::scene::{Field, ParamSpace, ParamSpec};

/// Generations without improvement that end a block when `--stagnation`
/// is not given: a block is one step of an alternation, not the last word.
const BLOCK_STAGNATION: usize = 30;

/// How a set fit runs: each block as `fit` (search options, budget per
/// block), and how many rounds at most.
#[derive(Clone, Debug)]
pub struct SetConfig {
    pub fit: FitConfig,
    /// Shared blocks at most (each followed by a per-shot block).
    pub rounds: usize,
    /// Every value is already near its fit (a refit from a chosen start):
    /// skip the first per-shot block and start every block around the
    /// current values.
    pub warm: bool,
    /// End with the joint block (`--joint`). Off by default: on a
    /// generated set missing a second light it fitted the wrong model
    /// better, and the diagnosis then chose area_light (docs/sets.md).
    pub joint: bool,
    /// Shared parameters (by name) a warm refit has just added: the first
    /// shared block spreads each over this unit-cube radius instead of
    /// starting it around its value, which is a neutral guess, not a fit
    /// (a second light at zero intensity would otherwise never leave
    /// where it was put).
    pub spread: Vec<(String, f64)>,
}

impl SetConfig {
    /// One photograph's fit run as `fit` says (no blocks, no rounds).
    pub fn one(fit: FitConfig) -> SetConfig {
        SetConfig {
            fit,
            rounds: 0,
            warm: false,
            joint: false,
            spread: Vec::new(),
        }
    }
}

/// Every field a set's renders vary: the free parameters and the fields
/// the shots' `set` fixes, with bounds that hold every shot's value (a
/// renderer prepares for the range it will be asked to draw).
pub fn varying(space: &ParamSpace, shots: &[Shot]) -> ParamSpace {
    let mut specs = space.specs.clone();
    for s in shots {
        for key in s.entry.set.keys() {
            if specs.iter().any(|p| &p.name == key) {
                continue;
            }
            let Ok(field) = Field::resolve(&s.scene, key) else {
                continue;
            };
            let values: Vec<Vec<f64>> = shots
                .iter()
                .filter_map(|o| field.get(&o.scene).map(|v| v.components()))
                .collect();
            let n = values.first().map_or(0, Vec::len);
            let fold = |f: fn(f64, f64) -> f64, init: f64| -> Vec<f64> {
                (0..n)
                    .map(|c| values.iter().map(|v| v[c]).fold(init, f))
                    .collect()
            };
            specs.push(ParamSpec {
                name: key.clone(),
                field,
                min: fold(f64::min, f64::INFINITY),
                max: fold(f64::max, f64::NEG_INFINITY),
                hsv: false,
                phase: 1,
                per_shot: true,
            });
        }
    }
    ParamSpace { specs }
}

/// The seed of block `block` (and photograph `shot` within it): each has
/// its own stream of the run's seed.
pub fn block_seed(seed: u64, block: usize, shot: usize) -> u64 {
    seed.wrapping_add((block as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15))
        .wrapping_add((shot as u64).wrapping_mul(0xBF58_476D_1CE4_E5B9))
}

/// A block's search options: the run's, with a population of ten per
/// coordinate (DE's usual rule; at least 16, at most the run's) and a
/// stagnation stop.
pub fn block_config(config: &FitConfig, dim: usize, seed: u64) -> FitConfig {
    let mut c = config.clone();
    c.de.seed = seed;
    c.de.population = (10 * dim).clamp(16, config.de.population.max(16));
    c.stagnation = Some(config.stagnation.unwrap_or(BLOCK_STAGNATION));
    c.phase_generations = None;
    c
}
