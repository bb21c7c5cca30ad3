//! `fresnel`: highlights that brighten towards grazing angles, on every
//! glossy object.

use super::edit::{glossy, scalar, Trades};
use super::Effect;
use crate::diagnose::features::Features;
use crate::scene::field::MaterialField;
use crate::scene::{Field, FreeParam, Scene};

pub struct Fresnel;

impl Effect for Fresnel {
    fn name(&self) -> &'static str {
        "fresnel"
    }

    /// The highlight excess and its halo, weighted by the distance from
    /// the image centre (grazing rims).
    fn features(&self, f: &Features) -> Vec<Vec<f64>> {
        let (s, s1, _) = f.highlight();
        let (xs, ys) = (&f.xs, &f.ys);
        let rr = |i: usize| (xs[i] * xs[i] + ys[i] * ys[i]).sqrt();
        vec![f.map(|i| s[i] * rr(i)), f.map(|i| s1[i] * rr(i))]
    }

    fn extend(&self, scene: &Scene) -> Option<(Scene, Vec<FreeParam>)> {
        let mut s = scene.clone();
        let mut added = Vec::new();
        for i in glossy(scene) {
            if s.objects[i].material.fresnel.is_some() {
                continue;
            }
            s.objects[i].material.fresnel = Some(1.0);
            let field = Field::Material(i, MaterialField::Fresnel);
            added.push(scalar(&s, field, 0.02, 1.0));
        }
        Some((s, added))
    }

    /// Fresnel whitens highlights the fit had matched with its colours.
    fn trades(&self) -> Trades {
        Trades {
            colours: true,
            ..Trades::default()
        }
    }
}
