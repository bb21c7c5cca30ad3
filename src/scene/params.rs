//! The parameter space: the scene's `free` list as one search vector in the
//! unit cube, and back. Each free entry takes one coordinate (a number) or
//! three (a vector, or a colour searched in RGB or HSV). Values written back
//! into a scene are always in the scene's own units (colours as linear RGB).

use super::color::{hsv_to_rgb, rgb_to_hsv};
use super::field::{Field, Value};
use super::types::{ColorSpace, Scene};

/// One free parameter, resolved.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamSpec {
    pub name: String,
    pub field: Field,
    /// Bounds per component, in the search space (HSV for `hsv` colours).
    pub min: Vec<f64>,
    pub max: Vec<f64>,
    pub hsv: bool,
    pub phase: u32,
    /// Each photograph of a set has its own value (see `FreeParam`).
    pub per_shot: bool,
}

impl ParamSpec {
    pub fn dim(&self) -> usize {
        self.min.len()
    }

    /// The scene value at unit-cube coordinates `u` (one per component).
    pub fn value_at(&self, u: &[f64]) -> Value {
        let x: Vec<f64> = (0..self.dim())
            .map(|c| self.min[c] + u[c].clamp(0.0, 1.0) * (self.max[c] - self.min[c]))
            .collect();
        if x.len() == 1 {
            Value::Scalar(x[0])
        } else {
            let v = [x[0], x[1], x[2]];
            Value::Vector(if self.hsv { hsv_to_rgb(v) } else { v })
        }
    }

    /// Unit-cube coordinates of a scene value (clamped into the bounds).
    pub fn unit_of(&self, value: Value) -> Vec<f64> {
        let x = match value {
            Value::Scalar(x) => vec![x],
            Value::Vector(v) => (if self.hsv { rgb_to_hsv(v) } else { v }).to_vec(),
        };
        let mut x = x;
        if self.hsv && self.min[0] < 0.0 && x[0] < self.min[0] + 1.0 {
            x[0] = x[0].rem_euclid(1.0); // the circle's point inside the search interval
        }
        (0..self.dim())
            .map(|c| {
                let span = self.max[c] - self.min[c];
                if span > 0.0 {
                    ((x[c] - self.min[c]) / span).clamp(0.0, 1.0)
                } else {
                    0.5
                }
            })
            .collect()
    }
}

/// The free parameters of a scene, in file order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParamSpace {
    pub specs: Vec<ParamSpec>,
}

impl ParamSpace {
    /// Builds the space of a validated scene.
    pub fn from_scene(scene: &Scene) -> ParamSpace {
        let specs = scene
            .free
            .iter()
            .filter_map(|f| {
                let field = Field::resolve(scene, &f.param).ok()?;
                let n = field.get(scene)?.components().len();
                let hsv = f.space == ColorSpace::Hsv;
                let (mut min, mut max) = (f.min.components(n), f.max.components(n));
                if hsv && min[0] <= 0.0 && max[0] >= 1.0 {
                    // Hue is a circle: search it over an interval that
                    // overlaps itself, so that no hue sits on a bound (a red
                    // at hue 0.002 was otherwise pinned to the bound at 0).
                    min[0] = -0.25;
                    max[0] = 1.25;
                }
                Some(ParamSpec {
                    name: f.param.clone(),
                    field,
                    min,
                    max,
                    hsv,
                    phase: f.phase.unwrap_or(1),
                    per_shot: f.per_shot,
                })
            })
            .collect();
        ParamSpace { specs }
    }

    pub fn dim(&self) -> usize {
        self.specs.iter().map(ParamSpec::dim).sum()
    }

    pub fn is_empty(&self) -> bool {
        self.specs.is_empty()
    }

    /// The phases present, ascending.
    pub fn phases(&self) -> Vec<u32> {
        let mut p: Vec<u32> = self.specs.iter().map(|s| s.phase).collect();
        p.sort_unstable();
        p.dedup();
        p
    }

    /// The sub-space of one phase.
    pub fn phase(&self, phase: u32) -> ParamSpace {
        self.filtered(|s| s.phase == phase)
    }

    /// The parameters shared by every photograph of a set (`per_shot` false).
    pub fn shared(&self) -> ParamSpace {
        self.filtered(|s| !s.per_shot)
    }

    /// The parameters each photograph of a set has its own value of.
    pub fn per_shot(&self) -> ParamSpace {
        self.filtered(|s| s.per_shot)
    }

    /// The sub-space of the parameters `keep` accepts, in order.
    pub fn filtered(&self, keep: impl Fn(&ParamSpec) -> bool) -> ParamSpace {
        ParamSpace {
            specs: self.specs.iter().filter(|s| keep(s)).cloned().collect(),
        }
    }

    /// Fields this space changes.
    pub fn fields(&self) -> Vec<Field> {
        self.specs.iter().map(|s| s.field).collect()
    }

    /// The values at unit-cube point `u`, in scene units.
    pub fn values(&self, u: &[f64]) -> Vec<(String, Value)> {
        let mut at = 0;
        self.specs
            .iter()
            .map(|s| {
                let v = s.value_at(&u[at..at + s.dim()]);
                at += s.dim();
                (s.name.clone(), v)
            })
            .collect()
    }

    /// Writes the values at `u` into `scene`.
    pub fn apply(&self, scene: &mut Scene, u: &[f64]) {
        let mut at = 0;
        for s in &self.specs {
            s.field.set(scene, s.value_at(&u[at..at + s.dim()]));
            at += s.dim();
        }
    }

    /// A copy of `base` with the values at `u`.
    pub fn scene_at(&self, base: &Scene, u: &[f64]) -> Scene {
        let mut s = base.clone();
        self.apply(&mut s, u);
        s
    }

    /// The unit-cube point of the values `scene` holds now.
    pub fn unit_of(&self, scene: &Scene) -> Vec<f64> {
        self.specs
            .iter()
            .flat_map(|s| s.unit_of(s.field.get(scene).unwrap_or(Value::Scalar(0.0))))
            .collect()
    }

    /// The current values of these parameters in `scene`, as JSON.
    pub fn json_values(&self, scene: &Scene) -> serde_json::Map<String, serde_json::Value> {
        self.specs
            .iter()
            .filter_map(|s| Some((s.name.clone(), s.field.get(scene)?.to_json())))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FREE: &str = r#"
        {"param": "lights.key.position", "min": [-3, 0.5, -3], "max": [3, 5, 5]},
        {"param": "lights.key.intensity", "min": 1, "max": 50, "phase": 1},
        {"param": "objects.ball.material.color", "space": "hsv", "min": 0, "max": 1, "phase": 2}"#;

    #[test]
    fn round_trip_through_unit_cube() {
        let scene = crate::scene::test_scene::ball(r#""color": [0.8, 0.7, 0.1]"#, FREE);
        let space = ParamSpace::from_scene(&scene);
        assert_eq!(space.dim(), 7);
        let u = space.unit_of(&scene);
        let back = space.scene_at(&scene, &u);
        let a = space.json_values(&scene);
        let b = space.json_values(&back);
        for (k, v) in &a {
            let x: Vec<f64> = serde_json::from_value(if v.is_array() {
                v.clone()
            } else {
                serde_json::json!([v])
            })
            .unwrap();
            let y: Vec<f64> = serde_json::from_value(if b[k].is_array() {
                b[k].clone()
            } else {
                serde_json::json!([b[k]])
            })
            .unwrap();
            for (p, q) in x.iter().zip(&y) {
                assert!((p - q).abs() < 1e-12, "{k}: {x:?} vs {y:?}");
            }
        }
        assert_eq!(space.phases(), vec![1, 2]);
        assert_eq!(space.phase(2).dim(), 3);
    }
}
