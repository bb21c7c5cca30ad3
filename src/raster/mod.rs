//! The image every module passes around (8-bit sRGB RGB, as compared with
//! the photograph), and reading and writing image files. A leaf: it knows
//! nothing of scenes, renderers or fits.

pub mod io;

/// An 8-bit sRGB RGB image.
pub type Image = image::RgbImage;

/// How a photograph's values encode light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Encoding {
    /// sRGB-encoded values, as renders are written.
    Srgb,
    /// Values proportional to light.
    Linear,
}

impl std::str::FromStr for Encoding {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "srgb" => Ok(Encoding::Srgb),
            "linear" => Ok(Encoding::Linear),
            other => Err(format!(
                "expected \"srgb\" or \"linear\", got {}",
                crate::scene::limits::quote(other)
            )),
        }
    }
}
