//! `camera_response`: a tone curve between the scene's linear light and
//! the image (gain, gamma, black level), written through the sRGB transfer
//! function or as linear values.

use super::edit::{closer, field_of, scalar, Trades, DISTANCES};
use super::Effect;
use crate::diagnose::features::Features;
use crate::raster::encoding::srgb_from_linear;
use crate::scene::field::{CameraField, MaterialField};
use crate::scene::{ColorSpace, Field, FreeParam, Response, ResponseEncoding, Scene, Value};

pub struct CameraResponse;

/// Gammas tried as starts (its bounds: 0.4-2.5); gamma 1 with the
/// specular lobe off and with the light moved ([`matte`], `closer`) is a
/// start of its own.
const GAMMAS: [f64; 12] = [0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.15, 1.35, 1.6, 1.9, 2.2, 2.5];

impl Effect for CameraResponse {
    fn name(&self) -> &'static str {
        "camera_response"
    }

    /// R, R², R·ln R (gain, curvature, gamma).
    fn features(&self, f: &Features) -> Vec<Vec<f64>> {
        let r = f.render;
        vec![
            r.to_vec(),
            f.map(|i| r[i] * r[i]),
            f.map(|i| r[i] * (r[i].max(1e-4)).ln()),
        ]
    }

    fn extend(&self, scene: &Scene) -> Option<(Scene, Vec<FreeParam>)> {
        if scene.camera.response.is_some() {
            return None;
        }
        let mut s = scene.clone();
        s.camera.response = Some(Response::default());
        let added = vec![
            scalar(&s, Field::Camera(CameraField::ResponseGain), 0.5, 2.0),
            scalar(&s, Field::Camera(CameraField::ResponseGamma), 0.4, 2.5),
            // Below 0: a black level subtracted (a raw converter's).
            scalar(&s, Field::Camera(CameraField::ResponseBlack), -0.05, 0.1),
        ];
        Some((s, added))
    }

    /// A fit without the response had absorbed the curve into its free
    /// colours: a target (c L)^γ is matched best by colours c^γ. So each
    /// start sets a gamma and bends them back, c -> c^(1/γ), which keeps
    /// the colours the fit found and changes only the shading (the start
    /// renders c L^γ, its level then matched). A gamma below 1 flattens the
    /// shading, which the fit had also faked by moving a free point light
    /// away (keeping the irradiance at the look-at point with more
    /// intensity), so each gamma is also tried with the light brought
    /// closer, and every start also without its specular lobe
    /// ([`matte`]). Without these starts, a search over the curve, colours
    /// fixed, cannot reach a strong gamma.
    ///
    /// Each start keeps the extended scene's encoding: the other encoding
    /// is a variant of its own ([`Effect::variants`]).
    fn starts(&self, extended: &Scene, _added: &[FreeParam]) -> Vec<Scene> {
        let encoding = extended
            .camera
            .response
            .map_or(ResponseEncoding::Srgb, |r| r.encoding);
        let mut starts = Vec::new();
        for base in [extended.clone(), matte(extended)] {
            for &d in &DISTANCES {
                let near = closer(&base, d);
                for &g in &GAMMAS {
                    starts.push(bend(&near, g, encoding));
                }
            }
        }
        starts
    }

    /// The response written as linear values. Not a gamma of the sRGB
    /// form: the sRGB curve's linear toe makes `v^2.2` through sRGB darken
    /// the shadows a camera storing linear values keeps (the DiLiGenT set:
    /// deviation 0.50 % with gamma 2.2 through sRGB, 0.23 % written
    /// linearly), and an encoding is not a number a search could move.
    fn variants(&self, extended: &Scene) -> Vec<Scene> {
        let mut linear = extended.clone();
        if let Some(r) = linear.camera.response.as_mut() {
            r.encoding = ResponseEncoding::Linear;
        }
        vec![linear]
    }

    /// The curve trades with the light's distance along a narrow valley:
    /// a start spread over the whole bounds rarely lands in it, so the
    /// search starts around the best of the starts.
    fn trades(&self) -> Trades {
        Trades {
            light_positions: true,
            radius: 0.35,
            ..Trades::default()
        }
    }
}

/// `scene` with its free specular levels at their lower bounds: a fit
/// without the response may have faked the curve's flattened or steepened
/// shading with a broad specular lobe, which under the right curve would
/// be far too bright; the refit grows the real lobe back.
fn matte(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    for f in &scene.free {
        if let Some(field @ Field::Material(_, MaterialField::Specular)) = field_of(scene, f) {
            field.set(&mut s, Value::Scalar(f.min.at(0)));
        }
    }
    s
}

/// `scene` with the response's gamma at `g`, written with `encoding`, and
/// its free RGB object colours bent back so that their ratios render as
/// the fit without the response had them: c^(1/g) through sRGB, and
/// sRGB(c)^(1/g) written linearly (the fit's colours were seen through the
/// sRGB curve). Clamped to their bounds; the diagnosis then matches the
/// level.
fn bend(scene: &Scene, g: f64, encoding: ResponseEncoding) -> Scene {
    let mut s = scene.clone();
    if let Some(r) = s.camera.response.as_mut() {
        r.gamma = g;
        r.encoding = encoding;
    }
    let seen = |v: f64| match encoding {
        ResponseEncoding::Srgb => v,
        ResponseEncoding::Linear => srgb_from_linear(v as f32) as f64,
    };
    for f in &scene.free {
        let Some(field @ Field::Material(_, MaterialField::Color)) = field_of(scene, f) else {
            continue;
        };
        if f.space != ColorSpace::Rgb {
            continue;
        }
        let back = |v: f64, i: usize| {
            seen(v.max(0.0))
                .powf(1.0 / g)
                .clamp(f.min.at(i), f.max.at(i))
        };
        let value = match field.get(scene) {
            Some(Value::Scalar(v)) => Value::Scalar(back(v, 0)),
            Some(Value::Vector(v)) => Value::Vector([back(v[0], 0), back(v[1], 1), back(v[2], 2)]),
            None => continue,
        };
        field.set(&mut s, value);
    }
    s
}
