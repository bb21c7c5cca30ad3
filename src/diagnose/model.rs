//! A diagnosis's model, for one photograph and a set alike (one photograph
//! is a set of one, with no own values): the shared scene, each
//! photograph's own values, its renders, and the sum of absolute
//! differences over all of them; and the pooled measures over the set.

use super::inputs::{Params, SetInputs};
use super::residual::Residual;
use crate::error::Result;
use crate::fit::set::shots::Shot;
use crate::metric::{deviation, Deviation};
use crate::raster::Image;
use crate::scene::load::with_overrides;
use crate::scene::{Override, ParamSpace, Scene};

/// A model of the photographs: the shared scene, each photograph's own
/// values, its renders, and the sum of absolute differences over all.
#[derive(Clone)]
pub struct Model {
    pub scene: Scene,
    pub own: Vec<Params>,
    pub images: Vec<Image>,
    pub sad: f64,
}

impl Model {
    /// Whichever of the two is closer to the targets (self on a tie).
    pub(super) fn better(self, other: Model) -> Model {
        if other.sad < self.sad {
            other
        } else {
            self
        }
    }

    /// Free coordinates: the shared ones and every photograph's own.
    pub(super) fn dim(&self, inputs: &SetInputs) -> usize {
        let space = ParamSpace::from_scene(&self.scene);
        space.shared().dim()
            + inputs
                .shots
                .iter()
                .map(|s| s.own_space(&space).dim())
                .sum::<usize>()
    }

    pub(super) fn deviations(&self, inputs: &SetInputs) -> Vec<Deviation> {
        self.images
            .iter()
            .zip(&inputs.shots)
            .map(|(img, s)| deviation(&s.target.image, img, s.target.mask.as_ref()))
            .collect()
    }

    /// The deviation over every photograph.
    pub(super) fn deviation(&self, inputs: &SetInputs) -> Deviation {
        pooled(&self.deviations(inputs), inputs)
    }

    pub(super) fn residuals(&self, inputs: &SetInputs) -> Vec<Residual> {
        self.images
            .iter()
            .zip(&inputs.shots)
            .map(|(img, s)| Residual::new(&s.target.image, img, s.target.mask.as_ref()))
            .collect()
    }
}

/// Each photograph as a shot of `scene`: its `set` values and then its
/// own values `own` in place (a photograph with neither: `scene` as it is,
/// checked but not rebuilt through JSON, whose numbers would come back a
/// digit off).
pub(super) fn shots_of(scene: &Scene, inputs: &SetInputs, own: &[Params]) -> Result<Vec<Shot>> {
    inputs
        .shots
        .iter()
        .zip(own)
        .map(|(s, own)| {
            if s.entry.set.is_empty() && own.is_empty() {
                crate::scene::validate::validate(scene, "(diagnosis)")?;
                let scene = scene.clone();
                return Ok(Shot { scene, ..s.clone() });
            }
            let overrides: Vec<Override> = s
                .entry
                .set
                .iter()
                .chain(own.iter())
                .map(|(k, v)| Override {
                    path: k.clone(),
                    value: v.clone(),
                })
                .collect();
            let scene = with_overrides(scene, &overrides, "(diagnosis)", &s.name)?;
            Ok(Shot { scene, ..s.clone() })
        })
        .collect()
}

/// The deviation over every photograph (each weighted by its pixels).
pub(super) fn pooled(devs: &[Deviation], inputs: &SetInputs) -> Deviation {
    let parts: Vec<(Deviation, usize)> = devs
        .iter()
        .zip(&inputs.shots)
        .map(|(d, s)| (*d, crate::fit::set::counted(&s.target)))
        .collect();
    Deviation::pooled(&parts)
}

/// The mean of `(weight, value)` pairs; one pair is its value, exactly
/// (a photograph alone is not reweighed, so that one photograph's
/// evidence and levels are its own to the last digit).
pub(super) fn weighted_mean(pairs: &[(f64, f64)]) -> f64 {
    if let [(_, v)] = pairs {
        return *v;
    }
    let n: f64 = pairs.iter().map(|x| x.0).sum();
    pairs.iter().map(|x| x.0 * x.1).sum::<f64>() / n.max(1.0)
}

#[cfg(test)]
mod tests {
    use super::weighted_mean;

    #[test]
    fn one_value_is_its_own_mean_and_weights_count() {
        let v = 0.1 + 0.2;
        assert_eq!(weighted_mean(&[(3.0, v)]).to_bits(), v.to_bits());
        assert_eq!(weighted_mean(&[(1.0, 1.0), (3.0, 5.0)]), 4.0);
    }
}
