//! `grazing_diffuse`: a diffuse term that is not Lambertian towards grazing
//! angles, on every object whose diffuse term shows: a smooth dielectric
//! (plastic, paint, glaze) darkens towards its terminator and its
//! silhouette, since the light crosses its surface on the way in and out;
//! a rough one brightens there. Burley's F_D90 (`material.diffuse_f90`,
//! docs/scene-format.md) held constant.

use super::edit::{is_free, scalar};
use super::Effect;
use crate::diagnose::features::Features;
use crate::scene::field::MaterialField;
use crate::scene::{Field, FreeParam, Scene};

pub struct GrazingDiffuse;

/// The factor's bounds: 0 (no diffuse light at grazing incidence, the
/// Schlick transmission of a smooth surface) to 2.5 (Burley's roughest).
const F90: (f64, f64) = (0.0, 2.5);

impl Effect for GrazingDiffuse {
    fn name(&self) -> &'static str {
        "grazing_diffuse"
    }

    /// R·(1 − R/peak)⁵ and R·(1 − R/peak)²: where a diffuse surface turns
    /// away from the light, R falls with the cosine the factor acts on.
    fn features(&self, f: &Features) -> Vec<Vec<f64>> {
        let r = f.render;
        let peak = f.peak.max(1e-9);
        let away = |i: usize| (1.0 - r[i] / peak).clamp(0.0, 1.0);
        vec![
            f.map(|i| r[i] * away(i).powi(5)),
            f.map(|i| r[i] * away(i).powi(2)),
        ]
    }

    /// Every object with a diffuse term that shows (set or searched) gets
    /// its own factor, at 1.
    fn extend(&self, scene: &Scene) -> Option<(Scene, Vec<FreeParam>)> {
        let mut s = scene.clone();
        let mut added = Vec::new();
        for (i, o) in scene.objects.iter().enumerate() {
            let m = &o.material;
            let shows = m.color.iter().any(|&c| c > 0.0)
                || is_free(scene, Field::Material(i, MaterialField::Color));
            if m.diffuse_f90.is_some() || m.diffuse <= 0.0 || !shows {
                continue;
            }
            s.objects[i].material.diffuse_f90 = Some(1.0);
            let field = Field::Material(i, MaterialField::DiffuseF90);
            added.push(scalar(&s, field, F90.0, F90.1));
        }
        Some((s, added))
    }
}
