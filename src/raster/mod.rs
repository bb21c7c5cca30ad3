//! The image every module passes around (8-bit sRGB RGB, as compared with
//! the photograph), photographs (any depth, sRGB or linear) and how they
//! become that image, and reading and writing image files. A leaf: it knows
//! nothing of scenes, renderers or fits.

pub mod encoding;
pub mod io;
pub mod photo;

pub use encoding::Encoding;
pub use photo::Photo;

/// An 8-bit sRGB RGB image.
pub type Image = image::RgbImage;
