//! OpenCV calibration YAML, as `cv::FileStorage` writes it (`%YAML:1.0`,
//! matrices as `!!opencv-matrix` nodes with rows, cols, dt and data), read
//! into one calibrated camera. Parsed here by hand: `%YAML:1.0` is not a
//! valid YAML directive and the tag is OpenCV's own, so general YAML
//! parsers refuse or mistype these files; the subset OpenCV writes (top-level
//! keys, matrix nodes, flow sequences, scalars) is small.
//!
//! Keys read: `camera_matrix` (or `cameraMatrix`, `K`), 3x3 without skew;
//! `distortion_coefficients` (or `dist_coeffs`, `distCoeffs`, `D`), 4 or 5
//! coefficients (or 8, 12, 14 with all beyond the fifth zero);
//! `image_width`, `image_height` if present; `rvec` and `tvec` (3 numbers
//! each) if present, else the camera sits at the origin looking along +z
//! (the scene in the camera's coordinates). Other keys are ignored.

use super::camera::Calibrated;
use crate::error::{Error, Result};
use std::collections::BTreeMap;
use std::path::Path;

const MATRIX_KEYS: [&str; 3] = ["camera_matrix", "cameraMatrix", "K"];
const DISTORTION_KEYS: [&str; 4] = ["distortion_coefficients", "dist_coeffs", "distCoeffs", "D"];

/// A top-level value: its first line's number and its text (the rest of
/// its key's line and every indented line below it).
struct Node {
    line: usize,
    text: String,
}

/// Reads the calibration in `path`; the bool is true when the file gave
/// the pose (rvec and tvec).
pub fn read(path: &Path) -> Result<(Calibrated, bool)> {
    let text = super::read_text(path, "an OpenCV calibration file (YAML)")?;
    parse(&text, &path.display().to_string())
}

/// The calibration in `text` (file named `file` in errors).
pub fn parse(text: &str, file: &str) -> Result<(Calibrated, bool)> {
    let nodes = top_level(text, file)?;
    let matrix = |keys: &[&str]| -> Result<Option<(String, Vec<f64>)>> {
        match keys.iter().find_map(|k| nodes.get(*k).map(|n| (*k, n))) {
            Some((k, n)) => Ok(Some((k.to_string(), numbers(n, file, k)?))),
            None => Ok(None),
        }
    };
    let Some((mk, m)) = matrix(&MATRIX_KEYS)? else {
        return Err(Error::invalid(
            file,
            "camera_matrix",
            "missing; expected an OpenCV calibration (camera_matrix: !!opencv-matrix, 3x3)",
        ));
    };
    if m.len() != 9 || m[1] != 0.0 || m[3] != 0.0 || m[6] != 0.0 || m[7] != 0.0 || m[8] != 1.0 {
        return Err(Error::invalid(
            file,
            mk,
            "expected a 3x3 camera matrix [fx 0 cx; 0 fy cy; 0 0 1] (no skew)",
        ));
    }
    if m[0] <= 0.0 || m[4] <= 0.0 {
        return Err(Error::invalid(file, mk, "expected positive fx and fy"));
    }
    let distortion = match matrix(&DISTORTION_KEYS)? {
        None => [0.0; 5],
        Some((k, d)) => five(&d).map_err(|m| Error::invalid(file, k, m))?,
    };
    let size = match (
        scalar(&nodes, "image_width", file)?,
        scalar(&nodes, "image_height", file)?,
    ) {
        (Some(w), Some(h)) => Some((w as u32, h as u32)),
        _ => None,
    };
    let pose = |k: &str| -> Result<Option<[f64; 3]>> {
        let Some(n) = nodes.get(k) else {
            return Ok(None);
        };
        let v = numbers(n, file, k)?;
        <[f64; 3]>::try_from(v.as_slice())
            .map(Some)
            .map_err(|_| Error::invalid(file, k, format!("expected 3 numbers, got {}", v.len())))
    };
    let (rvec, tvec) = (pose("rvec")?, pose("tvec")?);
    if rvec.is_some() != tvec.is_some() {
        return Err(Error::invalid(
            file,
            if rvec.is_some() { "tvec" } else { "rvec" },
            "missing; expected both rvec and tvec, or neither (the camera at the origin)",
        ));
    }
    let cam = Calibrated {
        size,
        fx: m[0],
        fy: m[4],
        cx: m[2],
        cy: m[5],
        distortion,
        rotation: rvec.unwrap_or([0.0; 3]),
        translation: tvec.unwrap_or([0.0; 3]),
    };
    Ok((cam, rvec.is_some()))
}

/// OpenCV's 4, 5, 8, 12 or 14 coefficients as the five the scene holds.
fn five(d: &[f64]) -> Result<[f64; 5], String> {
    match d.len() {
        4 => Ok([d[0], d[1], d[2], d[3], 0.0]),
        5 | 8 | 12 | 14 if d[5.min(d.len())..].iter().all(|&x| x == 0.0) => {
            Ok([d[0], d[1], d[2], d[3], d[4]])
        }
        5 | 8 | 12 | 14 => Err("coefficients beyond k3 (rational, thin-prism or tilt) are not zero; the scene's pinhole holds OpenCV's five-coefficient model only".into()),
        n => Err(format!("expected 4 or 5 coefficients (k1 k2 p1 p2 [k3]), got {n}")),
    }
}

/// A top-level number, if the key is present.
fn scalar(nodes: &BTreeMap<String, Node>, key: &str, file: &str) -> Result<Option<f64>> {
    let Some(n) = nodes.get(key) else {
        return Ok(None);
    };
    let t = n.text.trim();
    match t.parse::<f64>() {
        Ok(x) if x.is_finite() && x >= 1.0 && x <= u32::MAX as f64 && x.fract() == 0.0 => {
            Ok(Some(x))
        }
        _ => Err(Error::invalid(
            file,
            key,
            format!(
                "expected a whole number of pixels, got {}",
                crate::scene::limits::quote(t)
            ),
        )),
    }
}

/// The top-level keys of the file and their values' text.
fn top_level(text: &str, file: &str) -> Result<BTreeMap<String, Node>> {
    let mut nodes: BTreeMap<String, Node> = BTreeMap::new();
    let mut current: Option<String> = None;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let l = raw.split_once('#').map_or(raw, |(a, _)| a).trim_end();
        if l.trim().is_empty() || l.starts_with('%') || l == "---" || l == "..." {
            continue;
        }
        if l.starts_with([' ', '\t']) {
            match current.as_ref().and_then(|k| nodes.get_mut(k)) {
                Some(n) => {
                    n.text.push('\n');
                    n.text.push_str(l.trim());
                }
                None => return Err(Error::invalid(
                    file,
                    format!("line {line}"),
                    "an indented line before any key; expected an OpenCV calibration file (YAML)",
                )),
            }
            continue;
        }
        let Some((key, rest)) = l.split_once(':') else {
            return Err(Error::invalid(
                file,
                format!("line {line}"),
                "expected KEY: VALUE; not an OpenCV calibration file (YAML)",
            ));
        };
        let key = key.trim().trim_matches('"').to_string();
        nodes.insert(
            key.clone(),
            Node {
                line,
                text: rest.trim().to_string(),
            },
        );
        current = Some(key);
    }
    Ok(nodes)
}

/// The numbers of a value: an `!!opencv-matrix` node's `data` (checked
/// against rows x cols) or a flow sequence `[a, b, ...]`.
fn numbers(n: &Node, file: &str, key: &str) -> Result<Vec<f64>> {
    let bad = |m: String| Error::invalid(file, format!("{key} (line {})", n.line), m);
    let t = n.text.as_str();
    let (data, shape) = if t.starts_with("!!opencv-matrix")
        || t.starts_with("!<tag:yaml.org,2002:opencv-matrix>")
    {
        let field = |f: &str| -> Option<&str> {
            t.lines()
                .find_map(|l| l.strip_prefix(f).and_then(|r| r.strip_prefix(':')))
                .map(str::trim)
        };
        let dim = |f: &str| -> Result<usize> {
            field(f)
                .and_then(|v| v.parse().ok())
                .ok_or_else(|| bad(format!("expected {f}: N in the matrix node")))
        };
        let shape = (dim("rows")?, dim("cols")?);
        let start = t
            .find("data:")
            .ok_or_else(|| bad("expected data: [...] in the matrix node".into()))?;
        (&t[start + 5..], Some(shape))
    } else {
        (t, None)
    };
    let data = data.trim_start();
    let inner = data
        .strip_prefix('[')
        .and_then(|r| r.split_once(']'))
        .map(|(a, _)| a)
        .ok_or_else(|| bad("expected a list of numbers [a, b, ...]".into()))?;
    let v = inner
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| {
                    bad(format!(
                        "expected a number, got {}",
                        crate::scene::limits::quote(s)
                    ))
                })
        })
        .collect::<Result<Vec<f64>>>()?;
    if let Some((r, c)) = shape {
        if r * c != v.len() {
            return Err(bad(format!(
                "rows x cols is {r} x {c} but data holds {} numbers",
                v.len()
            )));
        }
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILE: &str = "%YAML:1.0\n---\ncalibration_time: \"Thu 01 Jan\"\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 5.2e+02, 0., 3.195e+02, 0.,\n       5.3e+02, 2.395e+02, 0., 0., 1. ]\ndistortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n   data: [ -0.28, 0.095, -1.5e-03, 4.2e-04, 0. ]\n";

    #[test]
    fn a_file_storage_calibration_is_read_whole() {
        let (c, posed) = parse(FILE, "calib.yml").unwrap();
        assert!(!posed);
        assert_eq!((c.fx, c.fy, c.cx, c.cy), (520.0, 530.0, 319.5, 239.5));
        assert_eq!(c.distortion, [-0.28, 0.095, -1.5e-3, 4.2e-4, 0.0]);
        assert_eq!(c.size, Some((640, 480)));
        let with_pose = format!("{FILE}rvec: !!opencv-matrix\n   rows: 3\n   cols: 1\n   dt: d\n   data: [ 0.1, -0.2, 0.3 ]\ntvec: [ 1, 2, 3 ]\n");
        let (c, posed) = parse(&with_pose, "calib.yml").unwrap();
        assert!(posed);
        assert_eq!(
            (c.rotation, c.translation),
            ([0.1, -0.2, 0.3], [1.0, 2.0, 3.0])
        );
    }

    #[test]
    fn broken_files_name_the_key() {
        let e = parse("image_width: 640\n", "c.yml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.yml: camera_matrix: missing"), "{e}");
        let e = parse(&FILE.replace("cols: 5", "cols: 4"), "c.yml")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("c.yml: distortion_coefficients (line 12): rows x cols is 1 x 4"),
            "{e}"
        );
        let e = parse(&format!("{FILE}rvec: [0, 0, 0]\n"), "c.yml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.yml: tvec: missing"), "{e}");
        let e = parse("\u{1}\u{2}garbage", "c.yml").unwrap_err().to_string();
        assert!(e.contains("not an OpenCV calibration file"), "{e}");
    }
}
