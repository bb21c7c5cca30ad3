//! A photograph and its optional mask as a fit's target: what every
//! command that fits a photograph (one, or each of a set) reads through.

use crate::error::{Error, Result};
use crate::metric::Mask;
use crate::raster::{io as image_io, Encoding, Image};
use std::path::{Path, PathBuf};

/// What the fit compares against.
#[derive(Clone, Debug)]
pub struct FitTarget {
    pub image: Image,
    /// The photograph's unrounded 8-bit sRGB levels (3 per pixel) when it
    /// is finer than 8-bit sRGB (16-bit, float, linear); None otherwise.
    pub levels: Option<Vec<f32>>,
    pub mask: Option<Mask>,
    /// For result.json.
    pub path: Option<PathBuf>,
    /// How the photograph's values were read (for result.json, so that
    /// `diagnose` and `report` read it the same way); None for an image
    /// made in memory.
    pub encoding: Option<Encoding>,
}

impl FitTarget {
    /// Reads the photograph `photo` (`what` names it in errors, e.g.
    /// `--target`) in `encoding` (None: by its format) and the mask
    /// `mask` (its path and name), both the scene's `size`. The pixels
    /// that count are the mask's (every pixel without one) minus the
    /// photograph's NaN or infinite ones, which say nothing, and its
    /// saturated ones, whose true value the camera lost. Returns the
    /// target and, when pixels were dropped, one line saying how many of
    /// each kind, for the user.
    pub fn from_photo(
        photo: &Path,
        what: &str,
        mask: Option<(&Path, &str)>,
        encoding: Option<Encoding>,
        size: (u32, u32),
    ) -> Result<(FitTarget, Option<String>)> {
        let p = image_io::read_photo(photo, what, size, encoding)?;
        let refuse = |message: String| Error::Image {
            path: photo.to_path_buf(),
            message: format!("{what}: {message}"),
        };
        if p.non_finite.len() as u64 == size.0 as u64 * size.1 as u64 {
            return Err(refuse(
                "every pixel is NaN or infinite; expected finite values to fit".into(),
            ));
        }
        let mask = mask
            .map(|(m, name)| Mask::read(m, name, size.0, size.1))
            .transpose()?;
        let (mask, nan) = Mask::without(mask, size.0, size.1, &p.non_finite);
        let (mask, dropped) = Mask::without(mask, size.0, size.1, &p.saturated);
        let maximum = if p.bits == 16 { "65535" } else { "255" };
        if mask.as_ref().is_some_and(|m| m.pixels().is_empty()) {
            return Err(refuse(format!(
                "every pixel that counts is saturated (a channel at {maximum}) or not finite; expected some unclipped pixels to fit"
            )));
        }
        let plural = |n: usize| if n == 1 { "" } else { "s" };
        let mut kinds = Vec::new();
        if nan > 0 {
            kinds.push(format!(
                "{nan} pixel{} with a NaN or infinite channel",
                plural(nan)
            ));
        }
        if dropped > 0 {
            kinds.push(format!(
                "{dropped} saturated pixel{} (a channel at {maximum})",
                plural(dropped)
            ));
        }
        let note = (!kinds.is_empty()).then(|| {
            format!(
                "{what} {}: {} left out of the fit",
                photo.display(),
                kinds.join(" and ")
            )
        });
        let target = FitTarget {
            levels: (!p.is_plain()).then_some(p.levels),
            image: p.image,
            mask,
            path: Some(photo.to_path_buf()),
            encoding: Some(p.encoding),
        };
        Ok((target, note))
    }
}
