//! Checking what a renderer wrote: the file exists, decodes as an image,
//! and has the scene's size. Anything else fails the render with a message
//! that says which. A persistent worker may instead write raw pixels
//! (docs/plugins.md, "Raw pixels"): exactly width x height x 3 bytes,
//! nothing to decode.

use crate::raster::Image;
use std::path::Path;

/// Reads the image at `path` as 8-bit RGB and checks its size.
pub fn read(path: &Path, width: u32, height: u32) -> Result<Image, String> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(format!("no image was written to {}", path.display()))
        }
        Err(e) => return Err(format!("cannot read {}: {e}", path.display())),
    };
    if bytes.is_empty() {
        return Err(format!("{} is empty, not an image", path.display()));
    }
    let img = image::load_from_memory(&bytes).map_err(|e| {
        format!(
            "{} is not an image the reader understands ({e})",
            path.display()
        )
    })?;
    if img.width() != width || img.height() != height {
        return Err(format!(
            "{} is {}x{}, expected {width}x{height}",
            path.display(),
            img.width(),
            img.height()
        ));
    }
    Ok(img.to_rgb8())
}

/// Reads raw pixels at `path`: 8-bit sRGB RGB, rows top to bottom, no
/// header, so the size must be exactly `width * height * 3` bytes; a
/// short or long file is refused with both sizes in the message.
pub fn read_raw(path: &Path, width: u32, height: u32) -> Result<Image, String> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(format!("no raw pixels were written to {}", path.display()))
        }
        Err(e) => return Err(format!("cannot read {}: {e}", path.display())),
    };
    let expected = width as usize * height as usize * 3;
    if bytes.len() != expected {
        return Err(format!(
            "{} holds {} bytes of raw pixels, expected {expected} ({width}x{height} RGB, 3 bytes a pixel)",
            path.display(),
            bytes.len()
        ));
    }
    Image::from_raw(width, height, bytes)
        .ok_or_else(|| format!("{}: raw pixels do not fit {width}x{height}", path.display()))
}

/// Removes a render's file; a file that is already gone is fine.
pub fn remove(path: &Path) {
    let _ = std::fs::remove_file(path);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checks() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.png");
        assert!(read(&p, 4, 2).unwrap_err().contains("no image"));
        std::fs::write(&p, b"").unwrap();
        assert!(read(&p, 4, 2).unwrap_err().contains("empty"));
        std::fs::write(&p, b"hello, not a png").unwrap();
        assert!(read(&p, 4, 2).unwrap_err().contains("not an image"));
        Image::from_pixel(3, 2, image::Rgb([1, 2, 3]))
            .save(&p)
            .unwrap();
        assert!(read(&p, 4, 2).unwrap_err().contains("is 3x2, expected 4x2"));
        assert_eq!(read(&p, 3, 2).unwrap().get_pixel(0, 0).0, [1, 2, 3]);
    }

    #[test]
    fn raw_pixels_must_have_the_exact_size() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.rgb");
        assert!(read_raw(&p, 2, 1).unwrap_err().contains("no raw pixels"));
        std::fs::write(&p, [1, 2, 3, 4, 5]).unwrap();
        let e = read_raw(&p, 2, 1).unwrap_err();
        assert!(
            e.contains("holds 5 bytes") && e.contains("expected 6"),
            "{e}"
        );
        std::fs::write(&p, [1, 2, 3, 4, 5, 6, 7]).unwrap();
        assert!(read_raw(&p, 2, 1).unwrap_err().contains("holds 7 bytes"));
        std::fs::write(&p, [1, 2, 3, 4, 5, 6]).unwrap();
        let img = read_raw(&p, 2, 1).unwrap();
        assert_eq!(img.get_pixel(1, 0).0, [4, 5, 6]);
    }
}
