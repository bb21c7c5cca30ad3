//! Decoding an image read (`read_capped`) with limits taken from the
//! file's own header: the dimensions are read first and checked by the
//! caller, then the decoder is allowed exactly the memory its output needs
//! (plus its working room), provided the machine has it. A valid
//! 16384x16384 photograph decodes where memory allows; a tiny file
//! declaring 100000x100000 allocates nothing. The caller gives the largest
//! side and the memory available, so that this module needs no scene.

use image::{DynamicImage, ImageDecoder, ImageFormat, ImageReader, Limits};
use std::io::Cursor;

/// Room a decoder may take beside its output (row buffers, an OpenEXR
/// block), bytes.
const WORKING_ROOM: u64 = 64 << 20;

/// The formats read, for messages.
pub const FORMATS: &str = "a PNG, BMP, TIFF or OpenEXR image";

/// Why bytes were not decoded.
#[derive(Debug)]
pub enum Refusal {
    /// Not an image of the formats read: the decoder's words.
    Format(String),
    /// The machine has not the memory the decoded image needs.
    Memory(String),
}

impl Refusal {
    /// One line for the user; `expected` names what the file should be
    /// (`FORMATS`, "an OpenEXR image of linear multipliers").
    pub fn describe(&self, expected: &str) -> String {
        match self {
            Refusal::Format(e) => format!("expected {expected}, could not decode it ({e})"),
            Refusal::Memory(m) => m.clone(),
        }
    }
}

/// The limits a header is read with: enough for a decoder's set-up. The
/// sides are the caller's to check, with a message naming them.
fn header_limits() -> Limits {
    let mut l = Limits::default();
    l.max_alloc = Some(WORKING_ROOM);
    l
}

fn reader(bytes: &[u8], format: Option<ImageFormat>) -> ImageReader<Cursor<&[u8]>> {
    let mut r = ImageReader::new(Cursor::new(bytes));
    if let Some(f) = format {
        r.set_format(f);
    } else if let Ok(g) = ImageReader::new(Cursor::new(bytes)).with_guessed_format() {
        if let Some(f) = g.format() {
            r.set_format(f);
        }
    }
    r.limits(header_limits());
    r
}

/// The format (guessed from the bytes unless given) and the width and
/// height the header declares; an error says what is wrong.
pub fn header(
    bytes: &[u8],
    format: Option<ImageFormat>,
) -> Result<(ImageFormat, u32, u32), Refusal> {
    let r = reader(bytes, format);
    let format = r
        .format()
        .ok_or_else(|| Refusal::Format("none of these formats".into()))?;
    let d = r.into_decoder().map_err(undecodable)?;
    let (w, h) = d.dimensions();
    Ok((format, w, h))
}

/// Decodes `bytes` (of `format`, from [`header`]) of at most `max_side`
/// pixels a side, allowing the decoder the memory its output needs;
/// refused when the machine has not that much available (`avail` bytes,
/// None: unknown).
pub fn decode(
    bytes: &[u8],
    format: ImageFormat,
    max_side: u32,
    avail: Option<f64>,
) -> Result<DynamicImage, Refusal> {
    let d = reader(bytes, Some(format))
        .into_decoder()
        .map_err(undecodable)?;
    let need = d.total_bytes();
    drop(d);
    check_memory(need, avail).map_err(Refusal::Memory)?;
    let mut r = reader(bytes, Some(format));
    r.limits(limits_for(need, max_side));
    r.decode().map_err(undecodable)
}

/// The limits of a decode whose output takes `need` bytes.
fn limits_for(need: u64, max_side: u32) -> Limits {
    let mut l = header_limits();
    l.max_image_width = Some(max_side);
    l.max_image_height = Some(max_side);
    l.max_alloc = Some(need.saturating_add(WORKING_ROOM));
    l
}

/// Refuses a decode of `need` bytes (held twice: decoded, then converted)
/// when `avail` (None: unknown) is less.
fn check_memory(need: u64, avail: Option<f64>) -> Result<(), String> {
    let want = 2.0 * need as f64;
    match avail {
        Some(a) if want > a => Err(format!(
            "decoding it needs {:.1} GiB, only {:.1} GiB of memory is available",
            want / f64::from(1 << 30),
            a / f64::from(1 << 30)
        )),
        _ => Ok(()),
    }
}

fn undecodable(e: image::ImageError) -> Refusal {
    Refusal::Format(e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn png(w: u32, h: u32) -> Vec<u8> {
        let mut buf = Cursor::new(Vec::new());
        image::GrayImage::new(w, h)
            .write_to(&mut buf, ImageFormat::Png)
            .unwrap();
        buf.into_inner()
    }

    #[test]
    fn the_largest_image_is_allowed_what_it_needs() {
        // 16384x16384 RGBA float: 4 GiB of output, over the image crate's
        // default 512 MiB.
        let need = 16384u64 * 16384 * 16;
        assert!(limits_for(need, 16384).max_alloc.unwrap() >= need);
        assert!(check_memory(need, Some(9.0 * f64::from(1 << 30))).is_ok());
        let e = check_memory(need, Some(f64::from(1 << 30))).unwrap_err();
        assert!(e.contains("needs 8.0 GiB") && e.contains("1.0 GiB"), "{e}");
        assert!(check_memory(need, None).is_ok());
    }

    #[test]
    fn an_image_over_the_default_limit_decodes() {
        // 11600x11600 RGBA 8-bit: 513 MiB of output, just over the image
        // crate's default limit.
        let img = image::RgbaImage::new(11600, 11600);
        let mut buf = Cursor::new(Vec::new());
        img.write_to(&mut buf, ImageFormat::Png).unwrap();
        let bytes = buf.into_inner();
        let (f, w, h) = header(&bytes, None).unwrap();
        assert_eq!((f, w, h), (ImageFormat::Png, 11600, 11600));
        assert!(ImageReader::new(Cursor::new(&bytes[..]))
            .with_guessed_format()
            .unwrap()
            .decode()
            .is_err());
        assert_eq!(decode(&bytes, f, 16384, None).unwrap().width(), 11600);
    }

    #[test]
    fn a_header_is_read_and_garbage_refused() {
        let (f, w, h) = header(&png(3, 2), None).unwrap();
        assert_eq!((f, w, h), (ImageFormat::Png, 3, 2));
        let e = header(b"not an image at all", None).unwrap_err();
        assert!(
            e.describe(FORMATS).contains("none of these formats"),
            "{e:?}"
        );
        let e = header(&png(3, 2)[..40], None).unwrap_err();
        assert!(e.describe(FORMATS).contains("could not decode"), "{e:?}");
    }
}
