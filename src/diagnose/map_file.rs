//! The files of a texture the diagnosis solved (`texels.rs`), a colour
//! map or a specular one (grey: R = G = B), and the one owner of their
//! names: 16-bit PNG holding linear values, declared `"encoding": "linear"` with
//! a `range` of [0, the largest multiplier] (a stored value v means
//! v × that maximum: a PNG holds [0, 1] only, a multiplier up to
//! `texels::MAX_MULTIPLIER`), so every backend reads them as the built-in
//! tracer does; the probe that sets every covered colour to 0; and the
//! scene as improved_scene.json names them, by paths relative to it.

use super::effects;
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

/// The kinds of map the diagnosis solves and writes, each with the name
/// of the effect that solves it ([`effects::Effect::map_kind`]): the one table
/// the file names are read from, so a new map effect needs no edit here.
fn solved_kinds() -> impl Iterator<Item = (MapKind, &'static str)> {
    effects::ALL.iter().flat_map(|e| {
        let name = e.name();
        e.written_kinds().into_iter().map(move |k| (k, name))
    })
}

/// The prefix of every file of a map of `kind` the diagnosis writes: the
/// name of the effect that solves it, and the kind's key when the effect
/// writes it beside its own kind (`specular_map_shininess_map_…`); an
/// error for a kind no effect solves (no file of it is ever written).
fn prefix(kind: MapKind) -> Result<String> {
    let (_, name) = solved_kinds()
        .find(|&(k, _)| k == kind)
        .ok_or_else(|| Error::Run(format!("no effect solves a {}", kind.key())))?;
    let own = effects::by_name(name).and_then(|e| e.map_kind()) == Some(kind);
    Ok(match own {
        true => format!("{name}_"),
        false => format!("{name}_{}_", kind.key()),
    })
}

/// True when `name` is a map file the diagnosis writes (of any kind).
pub fn is_map_file(name: &str) -> bool {
    let ours = solved_kinds().any(|(_, effect)| name.starts_with(&format!("{effect}_")));
    ours && (name.ends_with(".exr") || name.ends_with(".png"))
}

/// The file of object `object`'s map of `kind` at side `side` for the
/// solve `tag` names, in `out` (each solve and side its own file: texels
/// are read once per process and path).
pub fn path(out: &Path, kind: MapKind, tag: &str, object: usize, side: u32) -> Result<PathBuf> {
    let p = out.join(format!(
        "{}{tag}_object{object}_side{side}.png",
        prefix(kind)?
    ));
    Ok(std::path::absolute(&p).unwrap_or(p))
}

/// Removes a map file no model names any longer (best effort: a file
/// already gone is what was asked).
pub fn discard(path: &Path) {
    let _ = std::fs::remove_file(path);
}

/// Writes the zero map of `kind` (one texel) into `out`; its reference.
pub fn zero(out: &Path, kind: MapKind) -> Result<(PathBuf, TextureRef)> {
    let path = out.join(format!("{}zero.png", prefix(kind)?));
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
        for (kind, _) in solved_kinds() {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The names outside scripts read: for every kind, the map files of
    /// the effect that solves it (a shininess map is written beside the
    /// specular map, and named so), or none when no effect does.
    #[test]
    fn every_map_kind_names_its_files_as_before() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path();
        for kind in MapKind::ALL {
            let expected = match kind {
                MapKind::Color => Some("albedo_map_"),
                MapKind::Specular => Some("specular_map_"),
                MapKind::Shininess => Some("specular_map_shininess_map_"),
                MapKind::Normal => None,
            };
            let file = path(out, kind, "round2", 1, 64);
            let zero = zero(out, kind);
            let Some(p) = expected else {
                assert!(file.is_err() && zero.is_err(), "{kind:?} has files");
                continue;
            };
            let name = |p: &Path| p.file_name().unwrap().to_string_lossy().into_owned();
            let file = name(&file.unwrap());
            assert_eq!(file, format!("{p}round2_object1_side64.png"));
            let (zero_path, _) = zero.unwrap();
            assert_eq!(name(&zero_path), format!("{p}zero.png"));
            assert!(zero_path.exists());
            assert!(is_map_file(&file) && is_map_file(&name(&zero_path)));
        }
        assert!(!is_map_file("albedo_map.png") && !is_map_file("albedo_map_x.json"));
        assert!(!is_map_file("shininess_map_zero.png"));
    }

    /// A map in the diagnosis directory is named by its file name alone,
    /// for every kind an effect solves.
    #[test]
    fn beside_names_every_solved_kind_by_its_file_name() {
        let dir = tempfile::tempdir().unwrap();
        let out = std::path::absolute(dir.path()).unwrap();
        let mut scene = crate::scene::test_scene::ball(r#""color": [0.5, 0.5, 0.5]"#, "");
        for kind in [MapKind::Color, MapKind::Specular] {
            let (_, r) = zero(&out, kind).unwrap();
            *scene.objects[0].material.map_slot(kind) = Some(r);
        }
        let s = beside(&scene, &out);
        let m = &s.objects[0].material;
        assert_eq!(m.map(MapKind::Color).unwrap().file(), "albedo_map_zero.png");
        assert_eq!(
            m.map(MapKind::Specular).unwrap().file(),
            "specular_map_zero.png"
        );
    }
}
