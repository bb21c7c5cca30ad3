//! Image-space camera effects applied after any backend: vignetting, the
//! camera's response curve (the diagnosis's effects `vignetting`,
//! `camera_response`) and a photograph's exposure and white balance (the
//! nuisance parameters `fit --nuisance` frees). A wrapper around every
//! renderer, so no backend needs to know these fields.
//!
//! ```json
//! "camera": {..., "vignetting": {"strength": 0.3},
//!            "response": {"gain": 1.1, "gamma": 0.9, "black": 0.01},
//!            "exposure": 1.2, "white_balance": [1.0, 0.95, 1.1]}
//! ```
//! Each 8-bit sRGB pixel is decoded to linear v, then
//! `v * (1 - strength * r^2)` (r: distance from the image centre over the
//! half-diagonal), times exposure and the channel's white balance, then
//! `black + gain * v^gamma`, then sRGB-encoded again, or, for a response
//! whose `encoding` is `linear`, written as a fraction of level 255 as it
//! is (a camera that stores linear values).
//! A scene without these fields passes through untouched.

use super::layer::{Layer, Prepared};
#[cfg(test)]
use super::srgb::encode;
use super::srgb::{decode, encode_exact};
use super::Image;
use crate::scene::{Camera, ParamSpace, Response, ResponseEncoding, Scene};
use std::borrow::Cow;

/// The layer that applies the camera's image-space effects after any backend.
#[derive(Clone, Copy, Debug)]
pub struct CameraEffects;

impl Layer for CameraEffects {
    fn prepare<'a>(&self, base: &'a Scene, varying: &'a ParamSpace) -> Prepared<'a> {
        // The backend never sees the image-space fields vary: they do not
        // change what it renders.
        let inner_space = ParamSpace {
            specs: varying
                .specs
                .iter()
                .filter(|s| !s.field.is_image_space())
                .cloned()
                .collect(),
        };
        Ok((Cow::Borrowed(base), Cow::Owned(inner_space)))
    }

    fn after(&self, scene: &Scene, image: &mut Image) {
        apply(&scene.camera, image);
    }
}

/// True when the camera has an image-space effect that changes pixels.
pub fn has_effects(cam: &Camera) -> bool {
    cam.vignetting.is_some_and(|v| v.strength != 0.0)
        || cam.exposure.is_some_and(|e| e != 1.0)
        || cam.white_balance.is_some_and(|wb| wb != [1.0; 3])
        || cam.response.is_some_and(|r| {
            r.gain != 1.0
                || r.gamma != 1.0
                || r.black != 0.0
                || r.encoding == ResponseEncoding::Linear
        })
}

/// The 8-bit level the response writes for the curve's output `x`.
fn writer(encoding: ResponseEncoding) -> fn(f64) -> u8 {
    match encoding {
        ResponseEncoding::Srgb => encode_exact,
        ResponseEncoding::Linear => |x| (x.clamp(0.0, 1.0) * 255.0).round() as u8,
    }
}

/// The 8-bit level `r` writes for the linear value `x`: the curve
/// `black + gain x^gamma`, then its encoding.
pub fn level(r: &Response, x: f64) -> u8 {
    writer(r.encoding)(r.black + r.gain * x.max(0.0).powf(r.gamma))
}

/// The linear value behind the 8-bit level `v` under `r`: the encoding and
/// the curve undone (a level below `black` gives 0).
pub fn linear(r: &Response, v: u8) -> f64 {
    let y = match r.encoding {
        ResponseEncoding::Srgb => decode(v),
        ResponseEncoding::Linear => v as f64 / 255.0,
    };
    ((y - r.black).max(0.0) / r.gain.max(1e-9)).powf(1.0 / r.gamma.max(1e-3))
}

/// Applies the camera's vignetting and response to `img` in place.
pub fn apply(cam: &Camera, img: &mut Image) {
    if !has_effects(cam) {
        return;
    }
    let (w, h) = img.dimensions();
    let (cx, cy) = (w as f64 / 2.0, h as f64 / 2.0);
    let half_diag2 = cx * cx + cy * cy;
    let k = cam.vignetting.map_or(0.0, |v| v.strength);
    let resp = cam.response.unwrap_or_default();
    let exposure = cam.exposure.unwrap_or(1.0);
    let balance = cam.white_balance.unwrap_or([1.0; 3]).map(|b| b * exposure);
    if k == 0.0 {
        // Without vignetting each channel's output depends on its 8-bit
        // input alone: a table per channel instead of two powers per value
        // (the difference between ~600 and ~6,000 renders/s at 128x96).
        let lut = decoded();
        let tables =
            balance.map(|b| -> [u8; 256] { std::array::from_fn(|i| level(&resp, lut[i] * b)) });
        for px in img.pixels_mut() {
            for (c, t) in px.0.iter_mut().zip(&tables) {
                *c = t[*c as usize];
            }
        }
        return;
    }
    // With it, (v b f)^gamma = (v b)^gamma f^gamma: a table per channel and
    // 8-bit input, and one power per pixel (none at gamma 1).
    let powered = balance.map(|b| powered(b, resp.gamma));
    let write = writer(resp.encoding);
    for (x, y, px) in img.enumerate_pixels_mut() {
        let (dx, dy) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
        let fall = (1.0 - k * (dx * dx + dy * dy) / half_diag2).max(0.0);
        let bent = if resp.gamma == 1.0 {
            fall
        } else {
            fall.powf(resp.gamma)
        };
        for (c, table) in px.0.iter_mut().zip(&powered) {
            *c = write(resp.black + resp.gain * table[*c as usize] * bent);
        }
    }
}

/// The linear value of every 8-bit sRGB code, computed once.
fn decoded() -> &'static [f64; 256] {
    static TABLE: std::sync::OnceLock<[f64; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|i| decode(i as u8)))
}

/// (v b)^gamma for the linear value v of every 8-bit code, from the
/// codes' logarithms (an exponential each, not a power).
fn powered(b: f64, gamma: f64) -> [f64; 256] {
    static LN: std::sync::OnceLock<[f64; 256]> = std::sync::OnceLock::new();
    let ln = LN.get_or_init(|| std::array::from_fn(|i| decode(i as u8).ln()));
    if b <= 0.0 {
        return [0f64.powf(gamma); 256];
    }
    let ln_b = b.ln();
    std::array::from_fn(|i| {
        if i == 0 {
            0f64.powf(gamma)
        } else {
            (gamma * (ln[i] + ln_b)).exp()
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Response, Vignetting};

    fn camera() -> Camera {
        serde_json::from_value(serde_json::json!({"type": "perspective",
            "position": [0.0, 0.0, 5.0], "look_at": [0.0, 0.0, 0.0], "fov_y_deg": 40.0}))
        .unwrap()
    }

    #[test]
    fn identity_leaves_pixels_alone() {
        let mut cam = camera();
        cam.response = Some(Response::default());
        cam.vignetting = Some(Vignetting { strength: 0.0 });
        let img0 = Image::from_fn(8, 6, |x, y| {
            image::Rgb([(x * 30) as u8, (y * 40) as u8, 77])
        });
        let mut img = img0.clone();
        apply(&cam, &mut img);
        assert_eq!(img, img0);
    }

    #[test]
    fn vignetting_darkens_corners_not_centre() {
        let mut cam = camera();
        cam.vignetting = Some(Vignetting { strength: 0.5 });
        let mut img = Image::from_pixel(64, 48, image::Rgb([200, 200, 200]));
        apply(&cam, &mut img);
        assert!(img.get_pixel(32, 24)[0] >= 199);
        // r ~ 1 at the corner: half the linear value.
        let expect = encode(decode(200) * 0.5) as i32;
        assert!((img.get_pixel(0, 0)[0] as i32 - expect).abs() <= 3);
    }

    #[test]
    fn response_gain_scales_linear_values() {
        let mut cam = camera();
        cam.response = Some(Response {
            gain: 0.5,
            ..Response::default()
        });
        let mut img = Image::from_pixel(2, 2, image::Rgb([188, 188, 188]));
        apply(&cam, &mut img);
        assert_eq!(img.get_pixel(0, 0)[0], encode(decode(188) * 0.5));
    }

    #[test]
    fn a_linear_response_writes_linear_levels() {
        let mut cam = camera();
        cam.response = Some(Response {
            encoding: ResponseEncoding::Linear,
            ..Response::default()
        });
        // sRGB level 188 is linear 0.5029: level 128 when written as is.
        let mut img = Image::from_pixel(2, 2, image::Rgb([188, 0, 255]));
        apply(&cam, &mut img);
        assert_eq!(img.get_pixel(1, 1).0, [128, 0, 255]);
        // A black level below 0 is subtracted and clips at 0: 128.24 - 2.55.
        cam.response = Some(Response {
            black: -0.01,
            encoding: ResponseEncoding::Linear,
            ..Response::default()
        });
        let mut img = Image::from_pixel(1, 1, image::Rgb([188, 10, 255]));
        apply(&cam, &mut img);
        assert_eq!(img.get_pixel(0, 0).0, [126, 0, 252]);
    }
}
