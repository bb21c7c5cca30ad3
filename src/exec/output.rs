//! Checking what a renderer wrote: the file exists, decodes as an image,
//! and has the scene's size. Anything else fails the render with a message
//! that says which. A persistent worker may instead write raw pixels
//! (docs/plugins.md, "Raw pixels"): exactly width x height x 3 bytes,
//! nothing to decode.

use crate::raster::io::MAX_IMAGE_FILE_BYTES;
use crate::raster::Image;
use std::path::Path;

/// Reads the file a renderer wrote through the one opener (`input`): a
/// regular file of at most `limit` bytes, so that a FIFO, `/dev/zero` or a
/// 20 GB sparse file in its place fails the render at once. `what` names
/// the contents in the missing-file message.
fn read_bounded(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>, String> {
    use crate::input::{read_capped, CappedRead};
    read_capped(path, limit).map_err(|e| match e {
        CappedRead::Io(e) if e.kind() == std::io::ErrorKind::NotFound => {
            format!("no {what} written to {}", path.display())
        }
        CappedRead::Io(e) => format!("cannot read {}: {e}", path.display()),
        CappedRead::Directory => format!("{} is a directory, not {what}", path.display()),
        CappedRead::TooLarge => format!(
            "{} holds more than {limit} bytes; expected a rendered image of at most that size",
            path.display()
        ),
    })
}

/// Reads the image at `path` as 8-bit RGB and checks its size before
/// decoding it.
pub fn read(path: &Path, width: u32, height: u32) -> Result<Image, String> {
    use crate::input::decode;
    let bytes = read_bounded(path, MAX_IMAGE_FILE_BYTES, "image was")?;
    if bytes.is_empty() {
        return Err(format!("{} is empty, not an image", path.display()));
    }
    let not_image = |r: decode::Refusal| {
        format!(
            "{} is not an image the reader understands ({})",
            path.display(),
            r.describe(decode::FORMATS)
        )
    };
    let (format, w, h) = decode::header(&bytes, None).map_err(not_image)?;
    if w != width || h != height {
        return Err(format!(
            "{} is {w}x{h}, expected {width}x{height}",
            path.display()
        ));
    }
    Ok(decode::decode(
        &bytes,
        format,
        width.max(height),
        crate::scene::memory::available(),
    )
    .map_err(not_image)?
    .to_rgb8())
}

/// Reads raw pixels at `path`: 8-bit sRGB RGB, rows top to bottom, no
/// header, so the size must be exactly `width * height * 3` bytes; a
/// short or long file is refused with both sizes in the message (a long
/// one without being read past the expected size and one byte).
pub fn read_raw(path: &Path, width: u32, height: u32) -> Result<Image, String> {
    let expected = width as usize * height as usize * 3;
    let bytes = match read_bounded(path, expected as u64, "raw pixels were") {
        Ok(b) => b,
        // a long file: its size, for the message, without reading it
        Err(_)
            if path
                .metadata()
                .is_ok_and(|m| m.is_file() && m.len() > expected as u64) =>
        {
            let len = path.metadata().map(|m| m.len()).unwrap_or_default();
            return Err(too_many(path, len, width, height));
        }
        Err(e) => return Err(e),
    };
    if bytes.len() != expected {
        return Err(too_many(path, bytes.len() as u64, width, height));
    }
    Image::from_raw(width, height, bytes)
        .ok_or_else(|| format!("{}: raw pixels do not fit {width}x{height}", path.display()))
}

fn too_many(path: &Path, len: u64, width: u32, height: u32) -> String {
    let expected = width as u64 * height as u64 * 3;
    format!(
        "{} holds {len} bytes of raw pixels, expected {expected} ({width}x{height} RGB, 3 bytes a pixel)",
        path.display()
    )
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

    /// What a worker may leave in place of its output: refused at once,
    /// so a render never waits on it past its timeout.
    #[test]
    fn a_fifo_a_device_or_a_sparse_file_fails_the_render_at_once() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("fifo.png");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let zero = dir.path().join("zero.png");
        std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
        let sparse = dir.path().join("sparse.png");
        std::fs::File::create(&sparse)
            .unwrap()
            .set_len(20 << 30)
            .unwrap();
        let t = std::time::Instant::now();
        for (p, says) in [
            (&fifo, "a FIFO"),
            (&zero, "a device"),
            (&sparse, "more than"),
        ] {
            for e in [read(p, 4, 2).unwrap_err(), read_raw(p, 4, 2).unwrap_err()] {
                assert!(
                    e.contains(says) || e.contains("holds 21474836480 bytes"),
                    "{e}"
                );
            }
        }
        assert!(t.elapsed() < std::time::Duration::from_secs(2));
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
