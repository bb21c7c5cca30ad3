//! Reading and writing images with errors that name the file and what was
//! expected.

use super::{Encoding, Image, Photo};
use crate::error::{Error, Result};
use crate::fsio::{self, CappedRead};
use crate::input::decode;
use std::path::Path;

/// The largest image file read, bytes.
pub const MAX_IMAGE_FILE_BYTES: u64 = 1 << 30;
/// The largest width or height decoded, pixels (the scene's own limit).
const MAX_SIDE: u32 = crate::scene::limits::MAX_IMAGE_SIDE;

/// Reads an image file of any size as 8-bit sRGB RGB, in its format's
/// default encoding (an OpenEXR is converted from linear); `what` names it
/// in errors (`--target`).
pub fn read_image(path: &Path, what: &str) -> Result<Image> {
    let (img, format) = read_decoded(path, what, None)?;
    Ok(Photo::from_decoded(img, Encoding::default_for(format)).image)
}

/// Reads at most `MAX_IMAGE_FILE_BYTES` of the regular file `path` and
/// decodes it (PNG, BMP, TIFF or OpenEXR, at any depth), after checking the
/// dimensions the header declares (at most `MAX_SIDE`, and `expect` when
/// given) so that nothing large is allocated for a bad file, and with the
/// memory its size needs (`decode`). Returns the image and its format.
pub fn read_decoded(
    path: &Path,
    what: &str,
    expect: Option<(u32, u32)>,
) -> Result<(image::DynamicImage, image::ImageFormat)> {
    let bad = |message: String| Error::Image {
        path: path.to_path_buf(),
        message: format!("{what}: {message}"),
    };
    let bytes = fsio::read_capped(path, MAX_IMAGE_FILE_BYTES).map_err(|e| match e {
        // not a regular file: said with the option that named it
        CappedRead::Io(e) if e.kind() == std::io::ErrorKind::InvalidInput => bad(e.to_string()),
        CappedRead::Io(e) => Error::io(path, e),
        CappedRead::Directory => bad("is a directory; expected an image file".into()),
        CappedRead::TooLarge => bad(format!(
            "larger than {} MiB; expected an image file",
            MAX_IMAGE_FILE_BYTES >> 20
        )),
    })?;
    if bytes.is_empty() {
        return Err(bad(format!("empty; expected {}", decode::FORMATS)));
    }
    let (format, w, h) =
        decode::header(&bytes, None).map_err(|r| bad(r.describe(decode::FORMATS)))?;
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(bad(format!(
            "expected width and height between 1 and {MAX_SIDE}, got {w}x{h}"
        )));
    }
    if let Some((ew, eh)) = expect {
        if (w, h) != (ew, eh) {
            return Err(bad(format!(
                "expected {ew}x{eh} (the scene's image size), got {w}x{h}; resize it or change the scene's \"image\""
            )));
        }
    }
    let img = decode::decode(&bytes, format, MAX_SIDE, crate::scene::memory::available())
        .map_err(|r| bad(r.describe(decode::FORMATS)))?;
    Ok((img, format))
}

/// Reads the target photograph and checks its size against the scene's.
pub fn read_target(path: &Path, width: u32, height: u32) -> Result<Image> {
    Ok(read_photo(path, "--target", (width, height), None)?.image)
}

/// Reads a photograph of the scene's `size` (`what` names it in errors):
/// 8- or 16-bit PNG or TIFF, float TIFF or OpenEXR, in `encoding` (when
/// none is given: linear for OpenEXR, sRGB for the rest).
pub fn read_photo(
    path: &Path,
    what: &str,
    size: (u32, u32),
    encoding: Option<Encoding>,
) -> Result<Photo> {
    let (img, format) = read_decoded(path, what, Some(size))?;
    let encoding = encoding.unwrap_or(Encoding::default_for(format));
    Ok(Photo::from_decoded(img, encoding))
}

/// The format a file name asks for: PNG or BMP by the extension. Checked
/// before any work whose result would go there.
pub fn output_format(path: &Path) -> Result<image::ImageFormat> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .as_deref()
    {
        Some("bmp") => Ok(image::ImageFormat::Bmp),
        Some("png") => Ok(image::ImageFormat::Png),
        _ => Err(Error::Image {
            path: path.to_path_buf(),
            message: "expected a file name ending in .png or .bmp".into(),
        }),
    }
}

/// Writes an image atomically (`fsio`), as PNG or BMP by the extension.
pub fn write_image(img: &Image, path: &Path) -> Result<()> {
    let format = output_format(path)?;
    fsio::write_atomic_with(path, |w| {
        let mut buf = std::io::Cursor::new(Vec::new());
        img.write_to(&mut buf, format)
            .map_err(std::io::Error::other)?;
        w.write_all(buf.get_ref())
    })
}
