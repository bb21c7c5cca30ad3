//! Masks: which pixels count. Read from an image of any depth (luma above
//! half the format's maximum counts), kept as the list of pixel indices
//! that count.

use crate::error::{Error, Result};
use std::path::Path;

#[derive(Clone, Debug, PartialEq)]
pub struct Mask {
    width: u32,
    height: u32,
    pixels: Vec<u32>,
}

impl Mask {
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<u32>) -> Mask {
        Mask {
            width,
            height,
            pixels,
        }
    }

    /// Reads the `--mask` image; it must be `width` x `height`.
    pub fn load(path: &Path, width: u32, height: u32) -> Result<Mask> {
        Mask::read(path, "--mask", width, height)
    }

    /// Reads a mask image (8/16-bit PNG or TIFF, BMP, OpenEXR) that `what`
    /// names in errors; it must be `width` x `height`.
    pub fn read(path: &Path, what: &str, width: u32, height: u32) -> Result<Mask> {
        let (img, _) = crate::raster::io::read_decoded(path, what, Some((width, height)))?;
        let pixels = crate::raster::photo::mask_pixels(&img);
        if pixels.is_empty() {
            return Err(Error::Image {
                path: path.to_path_buf(),
                message: format!("{what}: no pixel is set (expected white where pixels count)"),
            });
        }
        Ok(Mask {
            width,
            height,
            pixels,
        })
    }

    /// The pixels that count when `mask` (every pixel of `width` x `height`
    /// when None) loses `drop` (ascending pixel indices, e.g. a
    /// photograph's saturated pixels), and how many it lost. None when
    /// every pixel still counts.
    pub fn without(
        mask: Option<Mask>,
        width: u32,
        height: u32,
        drop: &[u32],
    ) -> (Option<Mask>, usize) {
        if drop.is_empty() {
            return (mask, 0);
        }
        let mut m =
            mask.unwrap_or_else(|| Mask::from_pixels(width, height, (0..width * height).collect()));
        let before = m.pixels.len();
        m.retain(|p| drop.binary_search(&p).is_err());
        let dropped = before - m.pixels.len();
        (Some(m), dropped)
    }

    pub fn pixels(&self) -> &[u32] {
        &self.pixels
    }

    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Removes pixels where `keep` is false (e.g. saturated ones).
    pub fn retain(&mut self, mut keep: impl FnMut(u32) -> bool) {
        self.pixels.retain(|&p| keep(p));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_drops_only_the_listed_pixels_that_counted() {
        let (m, n) = Mask::without(None, 3, 2, &[1, 4]);
        assert_eq!(m.unwrap().pixels(), &[0, 2, 3, 5]);
        assert_eq!(n, 2);
        let given = Mask::from_pixels(3, 2, vec![0, 1, 2]);
        let (m, n) = Mask::without(Some(given.clone()), 3, 2, &[1, 4]);
        assert_eq!((m.unwrap().pixels(), n), (&[0u32, 2][..], 1));
        assert_eq!(
            Mask::without(Some(given.clone()), 3, 2, &[]),
            (Some(given), 0)
        );
        assert_eq!(Mask::without(None, 3, 2, &[]), (None, 0));
    }
}
