//! How a photograph's values relate to light: sRGB-encoded (what cameras and
//! image editors write to PNG and TIFF) or linear (what OpenEXR holds, and
//! what a raw converter writes when asked for linear output). Renders are
//! compared in 8-bit sRGB, so a linear file goes through the sRGB transfer
//! function first.

use serde::{Deserialize, Serialize};
use std::str::FromStr;

/// The encoding of a photograph's values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Encoding {
    Srgb,
    Linear,
}

impl Encoding {
    /// The encoding of a file of `format` when none is given: OpenEXR is
    /// linear (the format stores scene light), everything else sRGB.
    pub fn default_for(format: image::ImageFormat) -> Encoding {
        if format == image::ImageFormat::OpenExr {
            Encoding::Linear
        } else {
            Encoding::Srgb
        }
    }

    /// A value of this encoding (0..1 at the format's maximum) as an sRGB
    /// value in 0..1; out-of-range values are clipped first.
    pub fn to_srgb(self, v: f32) -> f32 {
        let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        match self {
            Encoding::Srgb => v,
            Encoding::Linear => srgb_from_linear(v),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Encoding::Srgb => "srgb",
            Encoding::Linear => "linear",
        }
    }
}

impl std::fmt::Display for Encoding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Encoding {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "srgb" => Ok(Encoding::Srgb),
            "linear" => Ok(Encoding::Linear),
            _ => Err(format!("expected srgb or linear, got \"{s}\"")),
        }
    }
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value in 0..1.
pub fn srgb_from_linear(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// The inverse of [`srgb_from_linear`]: an sRGB value in 0..1 as linear.
pub fn linear_from_srgb(v: f32) -> f32 {
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_both_names_and_refuses_others() {
        assert_eq!("srgb".parse::<Encoding>(), Ok(Encoding::Srgb));
        assert_eq!("Linear".parse::<Encoding>(), Ok(Encoding::Linear));
        let e = "gamma".parse::<Encoding>().unwrap_err();
        assert!(e.contains("srgb or linear") && e.contains("gamma"), "{e}");
        let j: Encoding = serde_json::from_str("\"linear\"").unwrap();
        assert_eq!(j, Encoding::Linear);
        assert_eq!(serde_json::to_string(&Encoding::Srgb).unwrap(), "\"srgb\"");
    }

    #[test]
    fn transfer_function_round_trips_and_has_its_fixed_points() {
        assert_eq!(srgb_from_linear(0.0), 0.0);
        assert!((srgb_from_linear(1.0) - 1.0).abs() < 1e-6);
        // Linear 0.2140 is sRGB 0.5 (mid grey, 8-bit level 128).
        assert!((srgb_from_linear(0.214_041) - 0.5).abs() < 1e-4);
        for i in 0..=100 {
            let v = i as f32 / 100.0;
            assert!((linear_from_srgb(srgb_from_linear(v)) - v).abs() < 1e-5);
        }
    }

    #[test]
    fn exr_defaults_to_linear() {
        use image::ImageFormat as F;
        assert_eq!(Encoding::default_for(F::OpenExr), Encoding::Linear);
        for f in [F::Png, F::Tiff, F::Bmp] {
            assert_eq!(Encoding::default_for(f), Encoding::Srgb);
        }
    }
}
