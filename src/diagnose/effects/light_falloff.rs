//! `light_falloff`: a point light whose irradiance falls off with another
//! power of the distance than the scene says.

use super::edit::{closer, field_of, first_light, scalar, Trades, DISTANCES};
use super::Effect;
use crate::diagnose::features::Features;
use crate::scene::field::LightField;
use crate::scene::{Falloff, Field, FreeParam, LightKind, Scene, Value};

pub struct LightFalloff;

/// Falloff exponents tried as starts (bounds 0-4).
const POWERS: [f64; 7] = [0.0, 0.5, 1.0, 1.5, 2.5, 3.0, 4.0];

impl Effect for LightFalloff {
    fn name(&self) -> &'static str {
        "light_falloff"
    }

    /// R·x, R·y, R·x², R·y² (a smooth multiplicative ramp).
    fn features(&self, f: &Features) -> Vec<Vec<f64>> {
        f.ramp()
    }

    /// The first point light without an exponent gets one, at the value
    /// its falloff implies.
    fn extend(&self, scene: &Scene) -> Option<(Scene, Vec<FreeParam>)> {
        let i = first_light(scene, LightKind::Point, |l| l.falloff_power.is_none())?;
        let mut s = scene.clone();
        let l = &mut s.lights[i];
        l.falloff_power = Some(if l.falloff == Falloff::InverseSquare {
            2.0
        } else {
            0.0
        });
        let added = scalar(&s, Field::Light(i, LightField::FalloffPower), 0.0, 4.0);
        Some((s, vec![added]))
    }

    /// A fit without the exponent had faked a slower falloff by moving the
    /// light away (a faster one, closer), so each exponent is tried at
    /// several distances, the level matched after.
    fn starts(&self, extended: &Scene, added: &[FreeParam]) -> Vec<Scene> {
        let Some(field) = added.first().and_then(|f| field_of(extended, f)) else {
            return Vec::new();
        };
        let mut starts = Vec::new();
        for &p in &POWERS {
            let mut s = extended.clone();
            field.set(&mut s, Value::Scalar(p));
            for &d in &DISTANCES {
                starts.push(closer(&s, d));
            }
        }
        starts
    }

    /// The exponent trades with the light's distance.
    fn trades(&self) -> Trades {
        Trades {
            light_positions: true,
            ..Trades::default()
        }
    }
}
