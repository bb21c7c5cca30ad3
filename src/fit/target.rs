//! What a fit compares against: a photograph, the pixels that count, and
//! where it came from; read from files the same way for one photograph
//! (`--target`) and for each photograph of a set (`--shots`).

use crate::error::Result;
use crate::metric::Mask;
use crate::raster::{io as image_io, Encoding, Image};
use crate::scene::Scene;
use std::path::{Path, PathBuf};

/// What the fit compares against.
#[derive(Clone, Debug)]
pub struct FitTarget {
    pub image: Image,
    pub mask: Option<Mask>,
    /// For result.json.
    pub path: Option<PathBuf>,
}

impl FitTarget {
    /// Reads the photograph at `path` (and its mask), checked against the
    /// scene's image size; linear values are sRGB-encoded as renders are.
    pub fn read(
        path: &Path,
        mask: Option<&Path>,
        encoding: Option<Encoding>,
        scene: &Scene,
    ) -> Result<FitTarget> {
        let (w, h) = (scene.image.width, scene.image.height);
        let mut image = image_io::read_target(path, w, h)?;
        if encoding == Some(Encoding::Linear) {
            for v in image.iter_mut() {
                *v = crate::render::srgb::encode(*v as f64 / 255.0);
            }
        }
        let mask = mask.map(|m| Mask::load(m, w, h)).transpose()?;
        Ok(FitTarget {
            image,
            mask,
            path: Some(path.to_path_buf()),
        })
    }
}
