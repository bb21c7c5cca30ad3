//! The handover from stage 1 to stage 2: the stage-1 fitted scene with the
//! bounds of its free parameters narrowed around the fitted values.
//!
//! Every backend reads the same scene format in the same units (the
//! conversions to each renderer's own units happen inside the backends, see
//! docs/renderers.md), so the handover changes where the search looks, not
//! what the numbers mean:
//!
//! ```json
//! {"param": "lights.key.intensity", "min": 1, "max": 50}      stage 1
//! {"param": "lights.key.intensity", "min": 5.4, "max": 20.1}  stage 2, fitted 12.75, window 0.15
//! ```
//!
//! Each component's new interval is the fitted value ± `window` times the
//! original span, clamped to the original bounds. Bounds live in the search
//! space: HSV colours are narrowed in H, S and V. Hue is a circle; a hue
//! window that would cross red (0 ≡ 1) cannot be written as one interval
//! in [0, 1] (the scene format's HSV bounds), so such a hue keeps its full
//! bounds and only its start is seeded.

use crate::error::{Error, Result};
use crate::rundir::{INPUT_SCENE, STAGE2};
use crate::scene::color::rgb_to_hsv;
use crate::scene::{Bound, ColorSpace, Field, Scene, Value};
use serde::{Deserialize, Serialize};

/// How one free parameter's bounds changed, for comparison.json.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Narrowed {
    pub param: String,
    /// In the search space (HSV for `hsv` colours).
    pub before: (Vec<f64>, Vec<f64>),
    pub after: (Vec<f64>, Vec<f64>),
    /// Components that kept their full bounds (a hue window across red).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub kept_full: Vec<usize>,
}

/// The stage-2 input: `fitted` (the stage-1 fitted scene, which still holds
/// the original free list) with every free parameter's bounds narrowed to
/// the fitted value ± `window` × span, except those named in `keep`, which
/// keep their original bounds (parameters whose meaning differs between the
/// two renderers' models, so that the stage-1 value is only a start).
pub fn narrow(fitted: &Scene, window: f64, keep: &[String]) -> Result<(Scene, Vec<Narrowed>)> {
    if !(window > 0.0 && window.is_finite()) {
        return Err(Error::Usage(format!(
            "--stage2-window: expected a fraction of the span > 0, got {window}"
        )));
    }
    let mut scene = fitted.clone();
    let mut report = Vec::new();
    for free in scene.free.iter_mut() {
        let field = Field::resolve(fitted, &free.param)
            .map_err(|m| Error::invalid("stage-1 fitted scene", &free.param, m))?;
        let value = field.get(fitted).ok_or_else(|| {
            Error::invalid(
                "stage-1 fitted scene",
                &free.param,
                "the parameter has no value",
            )
        })?;
        let hsv = free.space == ColorSpace::Hsv;
        let x = search_coordinates(value, hsv);
        let n = x.len();
        let (min, max) = (free.min.components(n), free.max.components(n));
        let (mut lo, mut hi) = (min.clone(), max.clone());
        let mut kept_full = Vec::new();
        let keep_all = keep.contains(&free.param);
        for c in 0..n {
            if keep_all {
                kept_full.push(c);
                continue;
            }
            let circular_hue = hsv && c == 0 && min[0] <= 0.0 && max[0] >= 1.0;
            let span = if circular_hue { 1.0 } else { max[c] - min[c] };
            let centre = x[c].clamp(min[c], max[c]);
            let (a, b) = (centre - window * span, centre + window * span);
            if circular_hue && (a < 0.0 || b > 1.0) {
                kept_full.push(c);
                continue;
            }
            lo[c] = a.max(min[c]);
            hi[c] = b.min(max[c]);
        }
        free.min = bound(&lo);
        free.max = bound(&hi);
        report.push(Narrowed {
            param: free.param.clone(),
            before: (min, max),
            after: (lo, hi),
            kept_full,
        });
    }
    // The narrowed scene must still be a valid scene (it is written as
    // stage2/input_scene.json and read back by `fit`).
    let json = serde_json::to_value(&scene).map_err(|e| Error::Run(e.to_string()))?;
    let name = format!("{STAGE2}/{INPUT_SCENE}");
    let scene = crate::scene::load::from_value(json, &name)?;
    Ok((scene, report))
}

/// A value's coordinates in the space its bounds are written in.
fn search_coordinates(value: Value, hsv: bool) -> Vec<f64> {
    match value {
        Value::Scalar(x) => vec![x],
        Value::Vector(v) if hsv => rgb_to_hsv(v).to_vec(),
        Value::Vector(v) => v.to_vec(),
    }
}

fn bound(v: &[f64]) -> Bound {
    match v {
        [x] => Bound::Scalar(*x),
        [a, b, c] => Bound::Vector([*a, *b, *c]),
        // Fields are numbers or 3-vectors; anything else was rejected when
        // the scene was loaded.
        _ => Bound::Scalar(v.first().copied().unwrap_or(0.0)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::ParamSpace;

    fn scene(color: [f64; 3], intensity: f64) -> Scene {
        let text = format!(
            r#"{{
          "format": "scenefit-scene/1",
          "image": {{"width": 8, "height": 6}},
          "camera": {{"type": "perspective", "position": [0, 1.5, 5], "look_at": [0, 0.5, 0], "fov_y_deg": 40}},
          "lights": [{{"name": "key", "type": "point", "position": [1, 3, 2], "intensity": {intensity}}}],
          "objects": [{{"name": "ball", "shape": {{"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5}},
                       "material": {{"color": {color:?}}}}}],
          "free": [
            {{"param": "lights.key.position", "min": [-3, 0.5, -3], "max": [3, 5, 5]}},
            {{"param": "lights.key.intensity", "min": 1, "max": 50}},
            {{"param": "objects.ball.material.color", "space": "hsv", "min": 0, "max": 1}}
          ]}}"#
        );
        crate::scene::parse(&text, "t.json", &[]).unwrap()
    }

    #[test]
    fn narrows_around_the_fitted_values_within_the_original_bounds() {
        let s = scene([0.2, 0.6, 0.3], 48.0);
        let (n, report) = narrow(&s, 0.15, &[]).unwrap();
        // Intensity 48 in [1, 50]: 48 ± 0.15 · 49 = ± 7.35, clamped above at 50.
        match (n.free[1].min, n.free[1].max) {
            (Bound::Scalar(lo), Bound::Scalar(hi)) => {
                assert!((lo - 40.65).abs() < 1e-9 && hi == 50.0, "{lo} {hi}")
            }
            other => panic!("{other:?}"),
        }
        // Position x: 1 ± 0.9 of span 6.
        let Bound::Vector(lo) = n.free[0].min else {
            panic!()
        };
        assert!((lo[0] - 0.1).abs() < 1e-9);
        // The fitted values sit inside the new bounds, at the same place.
        let space = ParamSpace::from_scene(&n);
        let back = space.scene_at(&n, &space.unit_of(&n));
        assert_eq!(space.json_values(&back).len(), 3);
        let v = &space.json_values(&back)["lights.key.intensity"];
        assert!((v.as_f64().unwrap() - 48.0).abs() < 1e-9);
        assert!(report[2].kept_full.is_empty());
    }

    #[test]
    fn hue_window_across_red_keeps_the_whole_circle() {
        let s = scene([0.7, 0.06, 0.05], 10.0);
        let (n, report) = narrow(&s, 0.15, &[]).unwrap();
        assert_eq!(report[2].kept_full, vec![0]);
        let (Bound::Vector(lo), Bound::Vector(hi)) = (n.free[2].min, n.free[2].max) else {
            panic!()
        };
        assert_eq!((lo[0], hi[0]), (0.0, 1.0));
        assert!(hi[1] - lo[1] < 0.31, "saturation narrowed");
    }

    #[test]
    fn kept_parameters_keep_their_bounds() {
        let s = scene([0.2, 0.6, 0.3], 48.0);
        let (n, report) = narrow(&s, 0.15, &["lights.key.intensity".to_string()]).unwrap();
        assert_eq!(
            (n.free[1].min, n.free[1].max),
            (Bound::Scalar(1.0), Bound::Scalar(50.0))
        );
        assert_eq!(report[1].kept_full, vec![0]);
        assert_ne!(n.free[0].min, s.free[0].min);
    }

    #[test]
    fn bad_window_is_a_usage_error() {
        let s = scene([0.2, 0.6, 0.3], 10.0);
        assert!(matches!(narrow(&s, 0.0, &[]), Err(Error::Usage(_))));
        assert!(matches!(narrow(&s, f64::NAN, &[]), Err(Error::Usage(_))));
    }
}
