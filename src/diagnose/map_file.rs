//! The files of a texture the diagnosis solved (`texels.rs`), a colour
//! map or a specular one (grey: R = G = B), and the one owner of their
//! names: 16-bit PNG holding linear values, declared `"encoding": "linear"` with
//! a `range` of [0, the largest multiplier] (a stored value v means
//! v × that maximum: a PNG holds [0, 1] only, a multiplier up to
//! `texels::MAX_MULTIPLIER`), so every backend reads them as the built-in
//! tracer does; the probe that sets every covered colour to 0; and the
//! scene as improved_scene.json names them, by paths relative to it.

use super::texels::ObjectMap;
use crate::error::{Error, Result};
use crate::scene::texture::{Encoding, MapKind, TextureRef, TextureSpec};
use crate::scene::Scene;
use std::path::{Path, PathBuf};

/// Writes `pixels` (RGB 16-bit, rows top to bottom) to `path` as PNG.
fn write_png(path: &Path, side: u32, pixels: Vec<u16>) -> Result<()> {
    let img = image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(side, side, pixels)
        .ok_or_else(|| Error::Run("color map: values do not fill the image".into()))?;
    crate::fsio::write_atomic_with(path, |w| {
        let mut buf = std::io::Cursor::new(Vec::new());
        image::DynamicImage::ImageRgb16(img)
            .write_to(&mut buf, image::ImageFormat::Png)
            .map_err(std::io::Error::other)?;
        w.write_all(buf.get_ref())
    })
}

/// The reference a scene holds to a linear map at `path`.
fn reference(path: &Path, scale: [f64; 2], hi: f64) -> TextureRef {
    TextureRef::Spec(TextureSpec {
        file: path.display().to_string(),
        encoding: Some(Encoding::Linear),
        scale: (scale != [1.0, 1.0]).then_some(scale),
        range: Some([0.0, hi]),
    })
}

/// Writes `map` to `path`; the reference to it.
pub fn write(path: &Path, map: &ObjectMap) -> Result<TextureRef> {
    let hi = map.values.iter().fold(1.0_f32, |a, &v| a.max(v)) as f64;
    let pixels = map
        .values
        .iter()
        .map(|&v| ((v as f64 / hi).clamp(0.0, 1.0) * 65535.0).round() as u16)
        .collect();
    write_png(path, map.layout.side, pixels)?;
    Ok(reference(path, map.layout.scale, hi))
}

/// The prefix of every file of a map of `kind` the diagnosis writes: the
/// effect's name.
fn prefix(kind: MapKind) -> &'static str {
    match kind {
        MapKind::Specular => "specular_map_",
        _ => "albedo_map_",
    }
}

/// True when `name` is a map file the diagnosis writes (of any kind).
pub fn is_map_file(name: &str) -> bool {
    let ours = [MapKind::Color, MapKind::Specular]
        .iter()
        .any(|&k| name.starts_with(prefix(k)));
    ours && (name.ends_with(".exr") || name.ends_with(".png"))
}

/// The file of object `object`'s map of `kind` at side `side` for the
/// solve `tag` names, in `out` (each solve and side its own file: texels
/// are read once per process and path).
pub fn path(out: &Path, kind: MapKind, tag: &str, object: usize, side: u32) -> PathBuf {
    let p = out.join(format!(
        "{}{tag}_object{object}_side{side}.png",
        prefix(kind)
    ));
    std::path::absolute(&p).unwrap_or(p)
}

/// Writes the zero map of `kind` (one texel) into `out`; its reference.
pub fn zero(out: &Path, kind: MapKind) -> Result<(PathBuf, TextureRef)> {
    let path = out.join(format!("{}zero.png", prefix(kind)));
    let path = std::path::absolute(&path).unwrap_or(path);
    write_png(&path, 1, vec![0; 3])?;
    let r = reference(&path, [1.0, 1.0], 1.0);
    Ok((path, r))
}

/// `scene` with each map that lies in `out` named by its file name: what
/// improved_scene.json, written into `out`, holds (a scene's map paths
/// are read relative to the scene file), so the directory can move.
pub fn beside(scene: &Scene, out: &Path) -> Scene {
    let mut s = scene.clone();
    let out_abs = std::path::absolute(out).unwrap_or(out.to_path_buf());
    for o in &mut s.objects {
        for kind in [MapKind::Color, MapKind::Specular] {
            let Some(t) = o.material.map_mut(kind) else {
                continue;
            };
            let file = PathBuf::from(t.file());
            if let (Some(dir), Some(name)) = (file.parent(), file.file_name()) {
                if dir == out_abs || dir == out {
                    *t.file_mut() = name.to_string_lossy().into_owned();
                }
            }
        }
    }
    s
}
