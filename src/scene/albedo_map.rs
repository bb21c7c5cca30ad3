//! `material.albedo_map`: an image of linear multipliers of a material's
//! diffuse colour, one per pixel and channel, in the image's frame (the
//! pixel a camera ray leaves from; a fixed camera). Stored as OpenEXR
//! (32-bit float RGB, the values as they are: 1 leaves the colour, 0.5
//! halves it, values above 1 allowed), so no scale has to be documented
//! or guessed.
//!
//! A scene holds only the map's path; the values are read once per
//! process and shared (a fit clones the scene for every candidate). The
//! path is made absolute when the scene is read, relative to the scene
//! file, so a scene written elsewhere (a fit's `fitted_scene.json`) still
//! finds its map.

use crate::error::{Error, Result};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

/// The values of one map.
#[derive(Clone, Debug, PartialEq)]
pub struct AlbedoMap {
    pub width: u32,
    pub height: u32,
    /// Linear multipliers, RGB per pixel, rows top to bottom.
    pub values: Vec<f32>,
}

impl AlbedoMap {
    /// A map of `width` x `height` with every value `v`.
    pub fn uniform(width: u32, height: u32, v: f32) -> AlbedoMap {
        AlbedoMap {
            width,
            height,
            values: vec![v; 3 * (width * height) as usize],
        }
    }

    /// The multipliers of pixel `p` (row-major index).
    pub fn at(&self, p: usize) -> [f32; 3] {
        let i = 3 * p;
        [self.values[i], self.values[i + 1], self.values[i + 2]]
    }
}

/// The largest map file read, bytes.
const MAX_MAP_BYTES: u64 = 1 << 30;

type Cache = Mutex<HashMap<PathBuf, Arc<AlbedoMap>>>;

fn cache() -> &'static Cache {
    static CACHE: OnceLock<Cache> = OnceLock::new();
    CACHE.get_or_init(Default::default)
}

/// `path` as the scene holds it: relative paths taken from the directory
/// of `scene_file`, then made absolute.
pub fn resolve(path: &str, scene_file: &str) -> PathBuf {
    let p = Path::new(path);
    let p = if p.is_absolute() {
        p.to_path_buf()
    } else {
        Path::new(scene_file)
            .parent()
            .unwrap_or(Path::new(""))
            .join(p)
    };
    std::path::absolute(&p).unwrap_or(p)
}

/// The map at `path` (absolute, as the scene holds it), read once per
/// process. Errors name the file and what was expected.
pub fn get(path: &Path) -> Result<Arc<AlbedoMap>> {
    if let Some(m) = cache().lock().expect("map cache").get(path) {
        return Ok(m.clone());
    }
    let map = Arc::new(read(path)?);
    cache()
        .lock()
        .expect("map cache")
        .insert(path.to_path_buf(), map.clone());
    Ok(map)
}

/// Reads an OpenEXR file of linear multipliers (a regular file of at
/// most `MAX_MAP_BYTES`, its header's size checked before decoding).
fn read(path: &Path) -> Result<AlbedoMap> {
    use crate::fsio::CappedRead;
    use crate::input::decode;
    let bad = |m: String| Error::Image {
        path: path.to_path_buf(),
        message: format!("albedo_map: {m}"),
    };
    let bytes = crate::fsio::read_capped(path, MAX_MAP_BYTES).map_err(|e| match e {
        CappedRead::Io(e) if e.kind() == std::io::ErrorKind::InvalidInput => bad(e.to_string()),
        CappedRead::Io(e) => Error::io(path, e),
        _ => bad(format!(
            "expected a file of at most {} MiB",
            MAX_MAP_BYTES >> 20
        )),
    })?;
    let exr = image::ImageFormat::OpenExr;
    let not_exr = |r: decode::Refusal| bad(r.describe("an OpenEXR image of linear multipliers"));
    let (_, w, h) = decode::header(&bytes, Some(exr)).map_err(not_exr)?;
    let side = crate::scene::limits::MAX_IMAGE_SIDE;
    if w == 0 || h == 0 || w > side || h > side {
        return Err(bad(format!(
            "expected width and height between 1 and {side}, got {w}x{h}"
        )));
    }
    let rgb = decode::decode(&bytes, exr, side, super::memory::available())
        .map_err(not_exr)?
        .to_rgb32f();
    Ok(AlbedoMap {
        width: rgb.width(),
        height: rgb.height(),
        values: rgb.into_raw(),
    })
}

/// Writes `map` to `path` as OpenEXR (atomically) and keeps its values for
/// this process, so the scenes that name it render without reading it.
pub fn write(path: &Path, map: AlbedoMap) -> Result<()> {
    let img = image::Rgb32FImage::from_raw(map.width, map.height, map.values.clone())
        .ok_or_else(|| Error::Run("albedo map: values do not fill the image".into()))?;
    crate::fsio::write_atomic_with(path, |w| {
        let mut buf = std::io::Cursor::new(Vec::new());
        image::DynamicImage::ImageRgb32F(img.clone())
            .write_to(&mut buf, image::ImageFormat::OpenExr)
            .map_err(std::io::Error::other)?;
        w.write_all(buf.get_ref())
    })?;
    let abs = std::path::absolute(path).unwrap_or(path.to_path_buf());
    cache()
        .lock()
        .expect("map cache")
        .insert(abs, Arc::new(map));
    Ok(())
}

/// Checks the map named at `key` of `file`: readable, of the image's
/// size, finite and non-negative.
pub fn check(path: &Path, size: (u32, u32), file: &str, key: &str) -> Result<()> {
    let bad = |what: String| {
        Error::invalid(
            file,
            key,
            format!(
                "{}: expected {what}",
                crate::scene::limits::quote(&path.display().to_string())
            ),
        )
    };
    let map = get(path).map_err(|e| match e {
        Error::Image { message, .. } => bad(format!(
            "an OpenEXR image of linear multipliers ({message})"
        )),
        Error::Io { source, .. } => {
            bad(format!("an OpenEXR image of linear multipliers ({source})"))
        }
        other => other,
    })?;
    if (map.width, map.height) != size {
        return Err(bad(format!(
            "{}x{} (the scene's image size), got {}x{}",
            size.0, size.1, map.width, map.height
        )));
    }
    if let Some(v) = map.values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
        return Err(bad(format!("finite non-negative multipliers, got {v}")));
    }
    Ok(())
}
