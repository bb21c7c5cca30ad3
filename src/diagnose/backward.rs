//! The backward step of the diagnosis's model selection, run by the
//! rounds (`rounds.rs`) of one photograph and of a set alike: after each
//! acceptance every earlier accepted effect is tested for removal (the
//! model rebuilt without it and refitted), and the one that pays least is
//! dropped when the criterion no longer accepts it over the model without
//! it. Why: forward selection alone keeps an effect accepted early forever;
//! an imitation (a blurred light standing in for a camera's response)
//! then stays once the real cause arrives, and the order in which evidence
//! arrives decides the model.

pub use super::diagnosis::Removal;
use super::effects::{self, Effect};
use super::selection::delta_bic;
use super::DiagnoseConfig;
use crate::error::Result;
use crate::scene::load::with_overrides;
use crate::scene::{Override, ParamSpace, Scene};

/// An accepted effect and which of its forms the model holds.
#[derive(Clone, Copy)]
pub struct Step {
    pub effect: &'static dyn Effect,
    pub form: usize,
}

/// `base` with `steps` added again in order, each in the form the model
/// holds (a closed-form map taken from `current`), and every free value of
/// the rebuilt scene that `current` has taken from it.
pub fn rebuild(base: &Scene, steps: &[Step], current: &Scene) -> Result<Scene> {
    let mut scene = base.clone();
    for step in steps {
        if let Some(kind) = step.effect.map_kind() {
            // The maps solved in closed form (`albedo.rs`), taken from the
            // objects of `current` that `base` leaves unmapped.
            for (o, c) in scene.objects.iter_mut().zip(&current.objects) {
                if o.material.map(kind).is_none() {
                    *o.material.map_slot(kind) = c.material.map(kind).cloned();
                }
            }
        } else if let Some(ext) = effects::forms(step.effect, &scene)
            .into_iter()
            .nth(step.form)
        {
            scene = ext.scene;
        }
    }
    let values = ParamSpace::from_scene(current).json_values(current);
    let overrides: Vec<Override> = values
        .into_iter()
        .filter(|(k, _)| scene.free.iter().any(|f| &f.param == k))
        .map(|(path, value)| Override { path, value })
        .collect();
    with_overrides(&scene, &overrides, "(diagnosis)", "backward step")
}

/// The model's SAD and free values, and those of each model without one
/// earlier accepted effect (in order); the index of the effect to remove
/// (the one whose removal costs least) and its criterion change, when the
/// criterion would not accept it over the model without it.
pub fn weakest(
    full: (f64, usize),
    reduced: &[(f64, usize)],
    n: f64,
    c: f64,
    config: &DiagnoseConfig,
) -> Option<(usize, f64, f64)> {
    reduced
        .iter()
        .enumerate()
        .map(|(j, &(sad, k))| {
            let added = full.1.saturating_sub(k);
            let d = delta_bic(sad, full.0, n, added, c);
            (j, d, 1.0 - full.0 / sad.max(1e-9))
        })
        .filter(|&(_, d, gain)| d >= -config.bic_margin || gain < config.min_gain)
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// How the backward step sees one diagnosis's models: the scene, the SAD
/// and free values of a model, and the refits of rebuilt scenes.
pub trait Models {
    type Model;
    fn scene<'m>(&self, m: &'m Self::Model) -> &'m Scene;
    fn score(&self, m: &Self::Model) -> (f64, usize);
    /// Every scene refitted (side by side), warm from its values.
    fn refit_all(&mut self, scenes: Vec<Scene>, from: &Self::Model) -> Result<Vec<Self::Model>>;
}

/// The backward step after round `round`'s acceptance: while two or more
/// effects are in, every one but the last accepted (just compared with the
/// model without it) is taken out of `model` in turn and the rest
/// refitted; the weakest is removed while the criterion, with the
/// overdispersion `c` over `n` values, says it does not pay for itself.
#[allow(clippy::too_many_arguments)]
pub fn prune<R: Models>(
    fits: &mut R,
    base: &Scene,
    steps: &mut Vec<Step>,
    model: &mut R::Model,
    n: f64,
    c: f64,
    config: &DiagnoseConfig,
    round: usize,
) -> Result<Vec<Removal>> {
    let mut removed = Vec::new();
    while steps.len() >= 2 {
        let scenes = (0..steps.len() - 1)
            .map(|j| {
                let mut rest = steps.clone();
                rest.remove(j);
                rebuild(base, &rest, fits.scene(model))
            })
            .collect::<Result<Vec<_>>>()?;
        let reduced = fits.refit_all(scenes, model)?;
        let scores: Vec<(f64, usize)> = reduced.iter().map(|m| fits.score(m)).collect();
        let Some((j, d, gain)) = weakest(fits.score(model), &scores, n, c, config) else {
            break;
        };
        removed.push(Removal {
            effect: steps[j].effect.name().to_string(),
            round,
            delta_bic: d,
            gain,
            reason: format!(
                "{} removed after round {round}: over the model without it, its criterion change is {d:.1} and the SAD down {:.1} %; it no longer pays for itself",
                steps[j].effect.name(),
                100.0 * gain
            ),
        });
        steps.remove(j);
        *model = reduced.into_iter().nth(j).expect("one refit per step");
    }
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_effect_that_no_longer_pays_is_the_one_removed() {
        let config = DiagnoseConfig::default();
        let n = 10_000.0;
        // Without the first: SAD 100 -> 99 for one value (pays nothing);
        // without the second: 100 -> 60 (pays).
        let got = weakest((99.0, 5), &[(100.0, 4), (165.0, 4)], n, 1.0, &config);
        assert_eq!(got.map(|g| g.0), Some(0));
        // Both pay: nothing removed.
        assert!(weakest((50.0, 5), &[(100.0, 4), (165.0, 4)], n, 1.0, &config).is_none());
    }
}
