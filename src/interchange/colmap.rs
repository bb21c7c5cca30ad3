//! COLMAP's text model (`cameras.txt`, `images.txt`; colmap.github.io,
//! "Output format") read into one calibrated camera per photograph.
//!
//! COLMAP's pose is OpenCV's (Xc = R X + t, camera x right, y down, z
//! forward; R given as a quaternion qw qx qy qz) and its lens models are
//! OpenCV's, but its pixel coordinates put the centre of the top-left pixel
//! at (0.5, 0.5) where OpenCV's (and the scene's pinhole) put it at (0, 0):
//! cx and cy lose half a pixel here.

use super::camera::{quaternion_to_rodrigues, Calibrated};
use crate::error::{Error, Result};
use std::collections::BTreeMap;
use std::path::Path;

/// The lens models read, and their parameter lists.
pub const MODELS: &str = "SIMPLE_PINHOLE (f cx cy), PINHOLE (fx fy cx cy), SIMPLE_RADIAL (f cx cy k), RADIAL (f cx cy k1 k2), OPENCV (fx fy cx cy k1 k2 p1 p2), FULL_OPENCV with k4 = k5 = k6 = 0";

/// COLMAP's pixel centre (0.5, 0.5) less OpenCV's (0, 0).
const CENTRE_SHIFT: f64 = 0.5;

/// One photograph of the model: its name in images.txt and its camera.
#[derive(Clone, Debug)]
pub struct Image {
    pub name: String,
    pub camera: Calibrated,
}

/// Reads the model in `dir` (cameras.txt and images.txt), in the order
/// images.txt lists the photographs.
pub fn read(dir: &Path) -> Result<Vec<Image>> {
    let cameras_path = dir.join("cameras.txt");
    let images_path = dir.join("images.txt");
    let cameras = parse_cameras(
        &super::read_text(&cameras_path, "COLMAP's cameras.txt")?,
        &cameras_path.display().to_string(),
    )?;
    parse_images(
        &super::read_text(&images_path, "COLMAP's images.txt")?,
        &images_path.display().to_string(),
        &cameras,
    )
}

/// The lines that hold data, numbered from 1; comments (#) left out.
fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.starts_with('#'))
}

fn number<T: std::str::FromStr>(tok: &str, file: &str, line: usize, what: &str) -> Result<T> {
    tok.parse().map_err(|_| {
        Error::invalid(
            file,
            format!("line {line}"),
            format!(
                "{what}: expected a number, got {}",
                crate::scene::limits::quote(tok)
            ),
        )
    })
}

/// cameras.txt: CAMERA_ID MODEL WIDTH HEIGHT PARAMS..., by id.
pub fn parse_cameras(text: &str, file: &str) -> Result<BTreeMap<u64, Calibrated>> {
    let mut out = BTreeMap::new();
    for (line, l) in data_lines(text).filter(|(_, l)| !l.is_empty()) {
        let tok: Vec<&str> = l.split_whitespace().collect();
        if tok.len() < 4 {
            return Err(Error::invalid(
                file,
                format!("line {line}"),
                "expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS...",
            ));
        }
        let id: u64 = number(tok[0], file, line, "CAMERA_ID")?;
        let w: u32 = number(tok[2], file, line, "WIDTH")?;
        let h: u32 = number(tok[3], file, line, "HEIGHT")?;
        let p = tok[4..]
            .iter()
            .map(|t| number::<f64>(t, file, line, "a parameter"))
            .collect::<Result<Vec<f64>>>()?;
        if p.iter().any(|x| !x.is_finite()) {
            return Err(Error::invalid(
                file,
                format!("line {line}"),
                "expected finite parameters",
            ));
        }
        let cam =
            intrinsics(tok[1], &p).map_err(|m| Error::invalid(file, format!("line {line}"), m))?;
        let cam = Calibrated {
            size: Some((w, h)),
            ..cam
        };
        if out.insert(id, cam).is_some() {
            return Err(Error::invalid(
                file,
                format!("line {line}"),
                format!("CAMERA_ID {id} is listed twice"),
            ));
        }
    }
    Ok(out)
}

/// A lens model's parameters as OpenCV's intrinsics (identity pose).
fn intrinsics(model: &str, p: &[f64]) -> Result<Calibrated, String> {
    let want = match model {
        "SIMPLE_PINHOLE" => 3,
        "PINHOLE" | "SIMPLE_RADIAL" => 4,
        "RADIAL" => 5,
        "OPENCV" => 8,
        "FULL_OPENCV" => 12,
        other => {
            return Err(format!(
                "lens model {} is not read; expected {MODELS}",
                crate::scene::limits::quote(other)
            ))
        }
    };
    if p.len() != want {
        return Err(format!("{model} has {want} parameters, got {}", p.len()));
    }
    // (fx, fy, cx, cy, [k1, k2, p1, p2, k3])
    let (fx, fy, cx, cy, d) = match model {
        "SIMPLE_PINHOLE" => (p[0], p[0], p[1], p[2], [0.0; 5]),
        "PINHOLE" => (p[0], p[1], p[2], p[3], [0.0; 5]),
        "SIMPLE_RADIAL" => (p[0], p[0], p[1], p[2], [p[3], 0.0, 0.0, 0.0, 0.0]),
        "RADIAL" => (p[0], p[0], p[1], p[2], [p[3], p[4], 0.0, 0.0, 0.0]),
        "OPENCV" => (p[0], p[1], p[2], p[3], [p[4], p[5], p[6], p[7], 0.0]),
        _ => {
            if p[9..12].iter().any(|&k| k != 0.0) {
                return Err("FULL_OPENCV with k4, k5 or k6 not zero: the scene's pinhole holds OpenCV's five-coefficient model only".into());
            }
            (p[0], p[1], p[2], p[3], [p[4], p[5], p[6], p[7], p[8]])
        }
    };
    if fx <= 0.0 || fy <= 0.0 {
        return Err(format!(
            "{model}: expected positive focal lengths, got {fx} and {fy}"
        ));
    }
    Ok(Calibrated {
        size: None,
        fx,
        fy,
        cx: cx - CENTRE_SHIFT,
        cy: cy - CENTRE_SHIFT,
        distortion: d,
        rotation: [0.0; 3],
        translation: [0.0; 3],
    })
}

/// images.txt: two lines per photograph, IMAGE_ID QW QX QY QZ TX TY TZ
/// CAMERA_ID NAME, then its 2-D points (ignored; the line may be empty).
pub fn parse_images(
    text: &str,
    file: &str,
    cameras: &BTreeMap<u64, Calibrated>,
) -> Result<Vec<Image>> {
    let mut out: Vec<Image> = Vec::new();
    let mut points_next = false;
    for (line, l) in data_lines(text) {
        if points_next {
            points_next = false;
            continue;
        }
        if l.is_empty() {
            continue;
        }
        let tok: Vec<&str> = l.split_whitespace().collect();
        if tok.len() < 10 {
            return Err(Error::invalid(
                file,
                format!("line {line}"),
                "expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME",
            ));
        }
        let v = tok[1..8]
            .iter()
            .map(|t| number::<f64>(t, file, line, "QW QX QY QZ TX TY TZ"))
            .collect::<Result<Vec<f64>>>()?;
        let q_norm = v[..4].iter().map(|a| a * a).sum::<f64>().sqrt();
        if !v.iter().all(|x| x.is_finite()) || (q_norm - 1.0).abs() > 1e-3 {
            return Err(Error::invalid(
                file,
                format!("line {line}"),
                "expected a unit quaternion QW QX QY QZ and a finite TX TY TZ",
            ));
        }
        let cam_id: u64 = number(tok[8], file, line, "CAMERA_ID")?;
        let Some(intr) = cameras.get(&cam_id) else {
            return Err(Error::invalid(
                file,
                format!("line {line}"),
                format!("CAMERA_ID {cam_id} is not in cameras.txt"),
            ));
        };
        let name = tok[9..].join(" ");
        if out.iter().any(|i| i.name == name) {
            return Err(Error::invalid(
                file,
                format!("line {line}"),
                format!("{} is listed twice", crate::scene::limits::quote(&name)),
            ));
        }
        out.push(Image {
            name,
            camera: Calibrated {
                rotation: quaternion_to_rodrigues(v[0], v[1], v[2], v[3]),
                translation: [v[4], v[5], v[6]],
                ..intr.clone()
            },
        });
        points_next = true;
    }
    if out.is_empty() {
        return Err(Error::invalid(
            file,
            "(file)",
            "lists no photograph; expected a COLMAP images.txt",
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const CAMERAS: &str =
        "# Camera list\n1 PINHOLE 64 48 70 72 32.5 24.5\n2 SIMPLE_RADIAL 64 48 80 31 23 -0.1\n";

    #[test]
    fn models_map_to_opencv_intrinsics_half_a_pixel_up_and_left() {
        let c = parse_cameras(CAMERAS, "cameras.txt").unwrap();
        assert_eq!(
            (c[&1].fx, c[&1].fy, c[&1].cx, c[&1].cy),
            (70.0, 72.0, 32.0, 24.0)
        );
        assert_eq!(c[&2].distortion, [-0.1, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(c[&2].size, Some((64, 48)));
    }

    #[test]
    fn empty_point_lines_do_not_shift_the_pairs() {
        let c = parse_cameras(CAMERAS, "cameras.txt").unwrap();
        let images = "# c\n1 1 0 0 0 0 0 2 1 a.png\n\n2 1 0 0 0 1 0 2 2 b.png\n10 20 -1\n";
        let got = parse_images(images, "images.txt", &c).unwrap();
        assert_eq!(got.len(), 2);
        assert_eq!(got[1].name, "b.png");
        assert_eq!(got[1].camera.translation, [1.0, 0.0, 2.0]);
        assert_eq!(got[1].camera.fx, 80.0);
    }

    #[test]
    fn unread_models_and_unknown_cameras_name_their_line() {
        let e = parse_cameras("1 OPENCV_FISHEYE 4 4 1 1 1 1 0 0 0 0\n", "c.txt").unwrap_err();
        assert!(
            e.to_string()
                .starts_with("c.txt: line 1: lens model \"OPENCV_FISHEYE\""),
            "{e}"
        );
        let c = parse_cameras(CAMERAS, "c.txt").unwrap();
        let e = parse_images("\n1 1 0 0 0 0 0 2 7 a.png\n", "i.txt", &c).unwrap_err();
        assert_eq!(
            e.to_string(),
            "i.txt: line 2: CAMERA_ID 7 is not in cameras.txt"
        );
    }
}
