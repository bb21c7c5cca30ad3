//! Reading a map: through `input::read_capped` (a regular file of at most
//! `MAX_TEXTURE_BYTES`), its header's size checked before anything is
//! decoded (at most `MAX_TEXTURE_SIDE` a side, and the memory its texels
//! take available), then decoded (`input::decode`) to linear RGB floats,
//! once per process and encoding. A bad file is refused in one line
//! naming the scene file, the key and the map's file.

use super::{Encoding, MapKind, Texels, TextureRef};
use crate::error::{Error, Result};
use crate::input::{decode, read_capped, CappedRead, MAX_TEXTURE_BYTES};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

/// The largest side of a map, texels: 8192 x 8192 RGB floats is 768 MiB.
pub const MAX_TEXTURE_SIDE: u32 = 8192;

type Cache = Mutex<HashMap<(PathBuf, Encoding), Arc<Texels>>>;

fn cache() -> &'static Cache {
    static CACHE: OnceLock<Cache> = OnceLock::new();
    CACHE.get_or_init(Default::default)
}

/// The texels of the map file `path` (absolute, as the scene holds it)
/// read with `encoding`, once per process. The error is one line saying
/// what is wrong with the file (the caller names the file and key).
pub fn get(path: &Path, encoding: Encoding) -> std::result::Result<Arc<Texels>, String> {
    let key = (path.to_path_buf(), encoding);
    if let Some(t) = cache().lock().expect("texture cache").get(&key) {
        return Ok(t.clone());
    }
    let t = Arc::new(read(path, encoding)?);
    cache()
        .lock()
        .expect("texture cache")
        .insert(key, t.clone());
    Ok(t)
}

const EXPECTED: &str = "a PNG (8 or 16 bits) or OpenEXR image";

fn read(path: &Path, encoding: Encoding) -> std::result::Result<Texels, String> {
    let bytes = read_capped(path, MAX_TEXTURE_BYTES).map_err(|e| match e {
        CappedRead::Io(e) => format!("{e}; expected {EXPECTED}"),
        CappedRead::Directory => format!("a directory; expected {EXPECTED}"),
        CappedRead::TooLarge => format!(
            "larger than {} MiB; expected {EXPECTED}",
            MAX_TEXTURE_BYTES >> 20
        ),
    })?;
    let (format, w, h) = decode::header(&bytes, None).map_err(|r| r.describe(EXPECTED))?;
    if !matches!(
        format,
        image::ImageFormat::Png | image::ImageFormat::OpenExr
    ) {
        return Err(format!("a {format:?} image; expected {EXPECTED}"));
    }
    if w == 0 || h == 0 || w > MAX_TEXTURE_SIDE || h > MAX_TEXTURE_SIDE {
        return Err(format!(
            "{w}x{h} texels; expected width and height between 1 and {MAX_TEXTURE_SIDE}"
        ));
    }
    // the texels are kept as RGB floats: 12 bytes each
    let need = 12.0 * w as f64 * h as f64;
    if let Some(avail) = crate::scene::memory::available() {
        if need > avail {
            return Err(format!(
                "its {w}x{h} texels need {:.1} GiB, only {:.1} GiB of memory is available",
                need / f64::from(1 << 30),
                avail / f64::from(1 << 30)
            ));
        }
    }
    let avail = crate::scene::memory::available();
    let img = decode::decode(&bytes, format, MAX_TEXTURE_SIDE, avail)
        .map_err(|r| r.describe(EXPECTED))?;
    let mut values = img.to_rgb32f().into_raw();
    if encoding == Encoding::Srgb {
        for v in &mut values {
            *v = srgb_to_linear(*v);
        }
    }
    Ok(Texels {
        width: w,
        height: h,
        values,
    })
}

/// The sRGB transfer function inverted, for a value in [0, 1].
fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Checks the map at `key` of `file`: readable, its settings sane, its
/// values (after `range`) finite and within what `kind` allows.
pub fn check(map: &TextureRef, kind: MapKind, file: &str, key: &str) -> Result<()> {
    let path = map.file();
    let quoted = crate::scene::limits::quote(path);
    let bad = |m: String| Error::invalid(file, key, format!("{quoted}: {m}"));
    if path.trim().is_empty() {
        return Err(Error::invalid(
            file,
            key,
            format!("expected {EXPECTED}'s path"),
        ));
    }
    let [su, sv] = map.scale();
    if !(su.is_finite() && sv.is_finite() && su != 0.0 && sv != 0.0) {
        return Err(Error::invalid(
            file,
            format!("{key}.scale"),
            format!("expected two finite numbers other than 0, got [{su}, {sv}]"),
        ));
    }
    let [lo, hi] = map.range();
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(Error::invalid(
            file,
            format!("{key}.range"),
            "expected two finite numbers",
        ));
    }
    let t = get(Path::new(path), map.encoding(kind)).map_err(bad)?;
    let (min, max) = t
        .values
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    // f32::min passes over NaN: look for it apart
    if !(min.is_finite() && max.is_finite()) || t.values.iter().any(|v| v.is_nan()) {
        return Err(bad("expected finite values".into()));
    }
    let (vmin, vmax) = (lo + min as f64 * (hi - lo), lo + max as f64 * (hi - lo));
    let least = vmin.min(vmax);
    match kind {
        MapKind::Color | MapKind::Specular if least < 0.0 => Err(bad(format!(
            "expected values of 0 or more (after range), got {least}"
        ))),
        MapKind::Shininess if least <= 0.0 => Err(bad(format!(
            "expected exponents above 0 (after range [lo, hi]: lo + value (hi - lo)), got {least}"
        ))),
        // a grey image (R = G = B everywhere) holds no direction: never a
        // normal map, whose flat texel is (0.5, 0.5, 1)
        MapKind::Normal if t.values.chunks_exact(3).all(|c| c[0] == c[1] && c[1] == c[2]) => {
            Err(bad(
                "a grey image (R = G = B in every texel); expected a normal map's RGB vectors (tangent space, flat = 0.5, 0.5, 1)".into(),
            ))
        }
        _ => Ok(()),
    }
}
