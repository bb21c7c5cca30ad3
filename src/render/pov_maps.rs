//! The texture maps POV-Ray reads (`pov_sdl.rs`): each map decoded as
//! scenefit decodes it (`scene::texture`), its `range` applied, written
//! once per session into the run directory as 16-bit grey PNGs, one per
//! channel used, each value divided by the map's largest (that factor
//! goes into the SDL), so that POV-Ray's `image_pattern` (`gamma 1.0`,
//! bilinear) reads scenefit's linear values to 1/65535. The SDL names
//! only these files (`m0r.png`, ...), never a path from the scene.

use super::pov_bumps::{self, Lay};
use crate::scene::texture::{self, Encoding, MapKind, TextureRef};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// A map as written: the files of its channels (R, G, B for a colour
/// map; R alone otherwise) and the factor they were divided by; for a
/// shininess map, the exponents its `texture_map` holds (`levels`).
#[derive(Clone, Debug, PartialEq)]
pub struct Channels {
    pub files: Vec<String>,
    pub scale: f64,
    pub levels: Vec<f64>,
}

/// Most entries of a shininess map's `texture_map` (POV-Ray takes 256).
pub const MAX_LEVELS: usize = 64;

/// The exponents a shininess map's texture blends between: each value
/// the map holds when there are at most `MAX_LEVELS` (a texel at one is
/// drawn with exactly that lobe: the diagnosis writes a few grid values),
/// else `MAX_LEVELS` spaced evenly in the logarithm from the least to the
/// largest (a lobe's width goes as the exponent's logarithm).
pub fn levels(values: &[f64]) -> Vec<f64> {
    let mut v: Vec<f64> = values.iter().map(|&x| x.max(1e-6)).collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    if v.len() <= MAX_LEVELS {
        return v;
    }
    let (lo, hi) = (v[0].ln(), v[v.len() - 1].ln());
    (0..MAX_LEVELS)
        .map(|k| (lo + (hi - lo) * k as f64 / (MAX_LEVELS - 1) as f64).exp())
        .collect()
}

/// (file, encoding, range bits, channels, whether its `levels` are
/// wanted, a normal map's lay as bits): what decides a written map. The
/// same file may be a specular map and a shininess map of one scene, and
/// a normal map's height depends on the surface it lies on.
type Key = (String, Encoding, [u64; 2], usize, bool, [u64; 5]);

/// The maps written into one run directory.
pub struct PovMaps {
    dir: PathBuf,
    written: Mutex<HashMap<Key, Arc<Channels>>>,
}

impl PovMaps {
    pub fn new(dir: &Path) -> PovMaps {
        PovMaps {
            dir: dir.to_path_buf(),
            written: Mutex::new(HashMap::new()),
        }
    }

    /// The files POV-Ray reads for map `t` of kind `kind`, written on
    /// first use in this session.
    /// A normal map (`kind` Normal) is written as the height field of its
    /// slopes as it lies (`lay`: `pov_bumps`), `scale` its range in
    /// world length. Another map with a sphere's lay is written laid over
    /// the whole sphere as the normal map's heights are
    /// (`pov_bumps::over_sphere`), for a spherical image about its centre.
    pub fn get(
        &self,
        t: &TextureRef,
        kind: MapKind,
        lay: Option<Lay>,
    ) -> Result<Arc<Channels>, String> {
        let channels = if kind == MapKind::Color { 3 } else { 1 };
        let [lo, hi] = t.range();
        let enc = t.encoding(kind);
        let shininess = kind == MapKind::Shininess;
        let key = (
            t.file().to_string(),
            enc,
            [lo.to_bits(), hi.to_bits()],
            channels,
            shininess,
            lay.map_or([0; 5], |l| l.bits()),
        );
        let mut written = self.written.lock().expect("pov maps");
        if let Some(c) = written.get(&key) {
            return Ok(c.clone());
        }
        if kind == MapKind::Normal {
            let lay = lay.ok_or("normal_map: drawn by POV-Ray on a plane, quad or sphere only")?;
            let name = format!("m{}h.png", written.len());
            let c = Arc::new(self.write_heights(t, lay, &name)?);
            written.insert(key, c.clone());
            return Ok(c);
        }
        let texels = texture::get(Path::new(t.file()), enc)
            .map_err(|e| format!("{}: {}: {e}", kind.key(), t.file()))?;
        let texels = match lay {
            Some(pov_bumps::Lay::Sphere { scale, .. }) => pov_bumps::over_sphere(&texels, scale),
            _ => texels,
        };
        let values: Vec<f64> = texels
            .values
            .iter()
            .map(|&v| lo + v as f64 * (hi - lo))
            .collect();
        let largest = values.iter().fold(0.0f64, |a, &b| a.max(b));
        let scale = if largest > 0.0 { largest } else { 1.0 };
        let n = written.len();
        let mut files = Vec::new();
        for c in 0..channels {
            let name = format!("m{n}{}.png", ['r', 'g', 'b'][c]);
            let px: Vec<u16> = values
                .chunks_exact(3)
                .map(|p| ((p[c] / scale).clamp(0.0, 1.0) * 65535.0).round() as u16)
                .collect();
            let img = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(
                texels.width,
                texels.height,
                px,
            )
            .ok_or("internal error: texel count")?;
            img.save(self.dir.join(&name))
                .map_err(|e| format!("{}: writing {name} for POV-Ray: {e}", kind.key()))?;
            files.push(name);
        }
        let levels = if shininess {
            levels(&values.iter().step_by(3).copied().collect::<Vec<_>>())
        } else {
            Vec::new()
        };
        let c = Arc::new(Channels {
            files,
            scale,
            levels,
        });
        written.insert(key, c.clone());
        Ok(c)
    }

    /// The height field of the normal map `t` as it lies, written as one
    /// 16-bit grey PNG spanning [0, 1] (`scale`: its range). The refusal
    /// is the scene check's (`maps::povray_refusals`); this is its guard.
    fn write_heights(&self, t: &TextureRef, lay: Lay, name: &str) -> Result<Channels, String> {
        let h = pov_bumps::solved(t, lay).map_err(|e| format!("normal_map: {}: {e}", t.file()))?;
        if pov_bumps::refused(&h) {
            let why = pov_bumps::not_a_height_field(h.missed);
            return Err(format!("normal_map: {why}"));
        }
        let lo = h.values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = h.values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let range = if hi > lo { hi - lo } else { 0.0 };
        let px: Vec<u16> = h
            .values
            .iter()
            .map(|&v| match range > 0.0 {
                true => (((v - lo) / range).clamp(0.0, 1.0) * 65535.0).round() as u16,
                false => 0,
            })
            .collect();
        let img = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(h.width, h.height, px)
            .ok_or("internal error: height count")?;
        img.save(self.dir.join(name))
            .map_err(|e| format!("normal_map: writing {name} for POV-Ray: {e}"))?;
        Ok(Channels {
            files: vec![name.to_string()],
            scale: range,
            levels: Vec::new(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One file as a specular map and then as a shininess map (same
    /// range): the second gets its own levels, not the first's none.
    #[test]
    fn a_file_read_as_both_maps_has_levels_as_a_shininess_map() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("g.png");
        image::GrayImage::from_fn(2, 1, |x, _| image::Luma([if x == 0 { 51 } else { 204 }]))
            .save(&file)
            .unwrap();
        let t = TextureRef::File(file.to_string_lossy().into_owned());
        let maps = PovMaps::new(dir.path());
        assert!(maps
            .get(&t, MapKind::Specular, None)
            .unwrap()
            .levels
            .is_empty());
        let l = &maps.get(&t, MapKind::Shininess, None).unwrap().levels;
        assert_eq!(l.len(), 2, "{l:?}");
    }

    #[test]
    fn a_few_exponents_are_each_a_level() {
        assert_eq!(levels(&[40.0, 10.0, 40.0, 20.0]), vec![10.0, 20.0, 40.0]);
    }

    /// More exponents than entries: `MAX_LEVELS` from the least to the
    /// largest, evenly in the logarithm.
    #[test]
    fn many_exponents_are_spread_over_their_range() {
        let values: Vec<f64> = (1..=500).map(f64::from).collect();
        let l = levels(&values);
        assert_eq!(l.len(), MAX_LEVELS);
        assert!((l[0] - 1.0).abs() < 1e-9 && (l[MAX_LEVELS - 1] - 500.0).abs() < 1e-9);
        let ratio = l[1] / l[0];
        assert!(l.windows(2).all(|w| (w[1] / w[0] - ratio).abs() < 1e-9));
    }
}
