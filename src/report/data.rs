//! What the report reads from a fit directory: result.json, the fitted
//! scene, best.png, the best_gNNNN.bmp snapshots, and the convergence curve
//! from trace.tsv (written by the pipeline, one line per generation with
//! seconds) or else from progress.txt (every 10 generations, no seconds:
//! seconds are then spread evenly over the generations from result.json's
//! `wall_seconds`, and the report says so); and all of a run directory,
//! loaded (`Run`).

use crate::error::{Error, Result};
use crate::fit::FitResult;
use crate::metric::{Deviation, Mask};
use crate::pipeline::Comparison;
use crate::raster::Image;
use crate::rundir::{snapshot_generation, RunDir, BEST, FITTED_SCENE, PROGRESS, TRACE};
use crate::scene::Scene;
use std::path::{Path, PathBuf};

/// What a run directory holds, loaded.
pub struct Run {
    pub dir: PathBuf,
    pub stages: Vec<Stage>,
    pub comparison: Option<Comparison>,
    /// The DE stage 2 run beside the mapped one (`--stage2-method both`).
    pub stage2_de: Option<Stage>,
    /// The target, or why there is none.
    pub target: std::result::Result<Image, String>,
    pub mask: Option<Mask>,
}

/// One point of a convergence curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurvePoint {
    pub generation: usize,
    pub evaluations: usize,
    pub seconds: f64,
    pub deviation: Deviation,
}

/// A fit directory, loaded.
pub struct Stage {
    pub dir: PathBuf,
    /// "Stage 1", "Stage 2" or "Fit".
    pub label: String,
    pub result: FitResult,
    pub fitted: Scene,
    pub best: Image,
    pub curve: Vec<CurvePoint>,
    /// False when the seconds of `curve` were spread evenly (no trace.tsv).
    pub seconds_measured: bool,
    /// (generation, file name) of every best_gNNNN.bmp, ascending.
    pub snapshots: Vec<(usize, String)>,
}

impl Stage {
    pub fn load(dir: &Path, label: &str) -> Result<Stage> {
        let run = RunDir::existing(dir)?;
        let result = FitResult::load(&run)?;
        let fitted = crate::scene::load(&run.file(FITTED_SCENE))?;
        // the page holds a few images of the fit's size: less than one
        // render of it, so checked as one
        let size = (fitted.image.width, fitted.image.height);
        let file = run.file(FITTED_SCENE).display().to_string();
        crate::scene::memory::check(&file, size, crate::scene::memory::Population::SINGLE, 1)?;
        let best = run.read_image(BEST)?;
        let (curve, seconds_measured) = match read_trace(&run.file(TRACE))? {
            Some(c) if !c.is_empty() => (c, true),
            _ => (read_progress(&run.file(PROGRESS), &result)?, false),
        };
        Ok(Stage {
            dir: dir.to_path_buf(),
            label: label.into(),
            result,
            fitted,
            best,
            curve,
            seconds_measured,
            snapshots: snapshots(dir)?,
        })
    }

    /// "Stage 1 (phong)".
    pub fn title(&self) -> String {
        format!("{} ({})", self.label, self.result.renderer)
    }
}

/// trace.tsv, or None when there is none.
fn read_trace(path: &Path) -> Result<Option<Vec<CurvePoint>>> {
    if !path.exists() {
        return Ok(None);
    }
    let text = crate::input::read_text_capped(path, crate::input::MAX_TEXT_BYTES)?;
    let mut points = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.starts_with('#') || line.trim().is_empty() {
            continue;
        }
        let f: Vec<&str> = line.split_whitespace().collect();
        let bad = || {
            Error::invalid(
                path.display().to_string(),
                format!("line {}", i + 1),
                "expected: generation evaluations seconds average r g b",
            )
        };
        if f.len() < 7 {
            return Err(bad());
        }
        let num = |k: usize| f[k].parse::<f64>().map_err(|_| bad());
        points.push(CurvePoint {
            generation: f[0].parse().map_err(|_| bad())?,
            evaluations: f[1].parse().map_err(|_| bad())?,
            seconds: num(2)?,
            deviation: Deviation {
                average: num(3)?,
                r: num(4)?,
                g: num(5)?,
                b: num(6)?,
            },
        });
    }
    Ok(Some(points))
}

/// progress.txt: `generation evaluations average r g b {params}` every 10
/// generations. Seconds: the run's `wall_seconds` spread evenly over its
/// generations (generation 0, the initial population, counts as one).
pub fn read_progress(path: &Path, result: &FitResult) -> Result<Vec<CurvePoint>> {
    let text = crate::input::read_text_capped(path, crate::input::MAX_TEXT_BYTES)?;
    let per_generation = result.wall_seconds / (result.generations + 1) as f64;
    let mut points = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.starts_with('#') || line.trim().is_empty() {
            continue;
        }
        let f: Vec<&str> = line.splitn(7, char::is_whitespace).collect();
        let bad = || {
            Error::invalid(
                path.display().to_string(),
                format!("line {}", i + 1),
                "expected: generation evaluations average r g b {params}",
            )
        };
        if f.len() < 6 {
            return Err(bad());
        }
        let num = |k: usize| f[k].parse::<f64>().map_err(|_| bad());
        let generation: usize = f[0].parse().map_err(|_| bad())?;
        points.push(CurvePoint {
            generation,
            evaluations: f[1].parse().map_err(|_| bad())?,
            seconds: per_generation * (generation + 1) as f64,
            deviation: Deviation {
                average: num(2)?,
                r: num(3)?,
                g: num(4)?,
                b: num(5)?,
            },
        });
    }
    Ok(points)
}

/// best_gNNNN.bmp files, by generation.
fn snapshots(dir: &Path) -> Result<Vec<(usize, String)>> {
    let mut v: Vec<(usize, String)> = std::fs::read_dir(dir)
        .map_err(|e| Error::io(dir, e))?
        .flatten()
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().to_string();
            Some((snapshot_generation(&name)?, name))
        })
        .collect();
    v.sort();
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn progress_lines_parse_and_get_even_seconds() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("progress.txt");
        std::fs::write(
            &p,
            "# header\n0 20 6.3 6.4 6.3 6.2 {\"a\":1}\n10 220 0.47 0.53 0.44 0.43 {\"a\": [1, 2]}\n",
        )
        .unwrap();
        let result = FitResult {
            renderer: "phong".into(),
            strategy: "rand1bin".into(),
            seed: 1,
            params: Default::default(),
            deviation: Deviation::default(),
            deviation_precise: None,
            evaluations: 220,
            generations: 10,
            wall_seconds: 1.1,
            stop_reason: String::new(),
            target: None,
            target_encoding: None,
            failed_renders: 0,
            identifiability: None,
            shots: None,
            alternatives: Vec::new(),
            held_out: Vec::new(),
        };
        let c = read_progress(&p, &result).unwrap();
        assert_eq!(c.len(), 2);
        assert_eq!((c[1].generation, c[1].evaluations), (10, 220));
        assert!((c[1].seconds - 1.1).abs() < 1e-12);
        assert!((c[0].seconds - 0.1).abs() < 1e-12);
        assert!((c[1].deviation.r - 0.53).abs() < 1e-12);
        std::fs::write(&p, "0 20 x\n").unwrap();
        assert!(matches!(
            read_progress(&p, &result),
            Err(Error::Invalid { .. })
        ));
    }
}
