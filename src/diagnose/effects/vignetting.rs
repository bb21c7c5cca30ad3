//! `vignetting`: the image darkening towards its corners.

use super::edit::scalar;
use super::Effect;
use crate::diagnose::features::Features;
use crate::scene::field::CameraField;
use crate::scene::{Field, FreeParam, Scene};

pub struct Vignetting;

impl Effect for Vignetting {
    fn name(&self) -> &'static str {
        "vignetting"
    }

    /// R·r² (r: distance from the centre over the half-diagonal).
    fn features(&self, f: &Features) -> Vec<Vec<f64>> {
        let (r, xs, ys) = (f.render, &f.xs, &f.ys);
        vec![f.map(|i| r[i] * (xs[i] * xs[i] + ys[i] * ys[i]))]
    }

    fn extend(&self, scene: &Scene) -> Option<(Scene, Vec<FreeParam>)> {
        if scene.camera.vignetting.is_some() {
            return None;
        }
        let mut s = scene.clone();
        s.camera.vignetting = Some(crate::scene::Vignetting { strength: 0.0 });
        let added = scalar(&s, Field::Camera(CameraField::Vignetting), 0.0, 1.0);
        Some((s, vec![added]))
    }
}
