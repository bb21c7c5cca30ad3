//! Calibrated cameras matched to photographs and written as a shots file
//! (`scenefit-shots/1`, fit/set/shots.rs): one shot per photograph, its
//! camera under `set`, its target relative to the shots file.
//!
//! A photograph is found by the name the calibration gives it, under the
//! images directory; failing that, by the same name with another image
//! extension the tool reads (a COLMAP model of JPEGs and the PNGs made from
//! them). A photograph the calibration lists but the directory lacks is an
//! error: a set fitted without it would be another set than the user asked.

use super::camera::Calibrated;
use crate::error::{Error, Result};
use crate::fit::set::shots::{Entry, ShotsFile, FORMAT, MAX_SHOTS};
use crate::scene::limits::{quote, valid_name};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Image files the tool reads, tried in this order when the calibration's
/// own name is not in the directory.
const EXTENSIONS: [&str; 6] = ["png", "PNG", "tif", "tiff", "bmp", "exr"];

/// One photograph as a calibration names it, and its camera.
pub struct Named {
    pub name: String,
    pub camera: Calibrated,
    /// The file the camera's intrinsics (and image size) were read from,
    /// named in errors about them.
    pub from: std::path::PathBuf,
}

/// The photograph `name` under `images`: the name itself, else its stem
/// with an extension from [`EXTENSIONS`].
pub fn find_image(images: &Path, name: &str) -> Option<PathBuf> {
    let exact = images.join(name);
    if exact.is_file() {
        return Some(exact);
    }
    EXTENSIONS
        .iter()
        .map(|e| exact.with_extension(e))
        .find(|p| p.is_file())
}

/// A shot name (A-Z a-z 0-9 _ -, at most 64) for a photograph's name:
/// its path without the extension, other characters as `_`, made unique
/// by a numeric suffix.
fn shot_name(name: &str, taken: &mut BTreeSet<String>) -> String {
    let stem = Path::new(name).with_extension("");
    let base: String = stem
        .to_string_lossy()
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .take(56)
        .collect();
    let base = if base.is_empty() {
        "shot".to_string()
    } else {
        base
    };
    let mut n = base.clone();
    let mut i = 2;
    while !taken.insert(n.clone()) {
        n = format!("{base}_{i}");
        i += 1;
    }
    debug_assert!(valid_name(&n));
    n
}

/// `path` relative to `dir` when it lies below it, else absolute.
fn relative_to(path: &Path, dir: &Path) -> PathBuf {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let (p, d) = (abs(path), abs(dir));
    p.strip_prefix(&d).map(Path::to_path_buf).unwrap_or(p)
}

/// The shots file for `cameras` (named by `source` in errors), their
/// photographs under `images`, written at `out`.
pub fn build(cameras: Vec<Named>, images: &Path, out: &Path, source: &str) -> Result<ShotsFile> {
    if cameras.len() > MAX_SHOTS {
        return Err(Error::invalid(
            source,
            "(file)",
            format!(
                "lists {} photographs; a set holds at most {MAX_SHOTS}",
                cameras.len()
            ),
        ));
    }
    let out_dir = out
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut taken = BTreeSet::new();
    let mut shots = Vec::with_capacity(cameras.len());
    for c in cameras {
        let Some(target) = find_image(images, &c.name) else {
            return Err(Error::Usage(format!(
                "{source}: photograph {} is not in {} (nor with the extension png, tif, tiff, bmp or exr); expected every photograph the calibration lists",
                quote(&c.name),
                images.display()
            )));
        };
        shots.push(Entry {
            name: shot_name(&c.name, &mut taken),
            target: relative_to(&target, out_dir),
            mask: None,
            encoding: None,
            set: c.camera.set_values(),
            hold_out: false,
        });
    }
    Ok(ShotsFile {
        format: FORMAT.into(),
        shots,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shot_names_are_valid_and_unique() {
        let mut t = BTreeSet::new();
        assert_eq!(shot_name("cam 1/IMG.0001.JPG", &mut t), "cam_1_IMG_0001");
        assert_eq!(shot_name("cam_1/IMG_0001.png", &mut t), "cam_1_IMG_0001_2");
        assert_eq!(shot_name(".jpg", &mut t), "_jpg");
        let long = "x".repeat(300);
        assert!(valid_name(&shot_name(&long, &mut t)));
    }
}
