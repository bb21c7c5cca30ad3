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
    /// The pixels as runs of consecutive indices (start, length): a
    /// photograph's mask is a few runs a row, which the metric sums as
    /// slices, in a loop the compiler vectorises, instead of one gathered
    /// pixel at a time.
    runs: Vec<(u32, u32)>,
}

impl Mask {
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<u32>) -> Mask {
        let runs = runs_of(&pixels);
        Mask {
            width,
            height,
            pixels,
            runs,
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
        Ok(Mask::from_pixels(width, height, pixels))
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

    /// Whether each of the `len` pixels of an image (row-major) counts:
    /// all of them without a mask.
    pub fn counted(mask: Option<&Mask>, len: usize) -> Vec<bool> {
        let Some(m) = mask else {
            return vec![true; len];
        };
        let mut inside = vec![false; len];
        for &p in m.pixels() {
            if let Some(k) = inside.get_mut(p as usize) {
                *k = true;
            }
        }
        inside
    }

    /// The pixels as runs of consecutive indices: (first, count).
    pub fn runs(&self) -> &[(u32, u32)] {
        &self.runs
    }

    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Removes pixels where `keep` is false (e.g. saturated ones).
    pub fn retain(&mut self, mut keep: impl FnMut(u32) -> bool) {
        self.pixels.retain(|&p| keep(p));
        self.runs = runs_of(&self.pixels);
    }
}

/// `pixels` as runs of consecutive indices, in their order.
fn runs_of(pixels: &[u32]) -> Vec<(u32, u32)> {
    let mut runs: Vec<(u32, u32)> = Vec::new();
    for &p in pixels {
        match runs.last_mut() {
            Some((start, len)) if *start + *len == p => *len += 1,
            _ => runs.push((p, 1)),
        }
    }
    runs
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

    #[test]
    fn runs_cover_the_pixels_in_order() {
        let mut m = Mask::from_pixels(4, 2, vec![0, 1, 2, 5, 6, 3]);
        assert_eq!(m.runs(), &[(0, 3), (5, 2), (3, 1)]);
        m.retain(|p| p != 1);
        assert_eq!(m.runs(), &[(0, 1), (2, 1), (5, 2), (3, 1)]);
    }
}
