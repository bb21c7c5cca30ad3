//! The HTML report of a run: `report.html` in a fit directory (one stage)
//! or a pipeline directory (two stages), with its figures beside it as
//! PNG (shown) and SVG (linked) files, all linked relatively so that the
//! directory can be moved or zipped whole.
//!
//! Figures: target and best renders side by side (upscaled, nearest
//! neighbour), signed difference heatmaps, the evolution strip (the paper's
//! Fig. 4), convergence against renders and seconds, and the final
//! population's light-versus-albedo scatter. Tables: the paper's Table I
//! (%R %G %B average), the fitted parameters side by side, time and
//! renders per stage, and the parameter trade-offs.

mod alternatives;
pub mod data;
mod figure;
pub mod font;
mod format;
pub mod heatmap;
pub(crate) mod held_out;
pub(crate) mod html;
mod identifiability;
pub mod images;
mod page;
pub mod plots;
pub mod population;
mod stage2;
mod tradeoffs;

use crate::error::{Error, Result};
use crate::metric::Mask;
use crate::pipeline::Comparison;
use crate::raster::io as image_io;
use crate::rundir::{RunDir, COMPARISON, REPORT, RESULT};
pub use data::Run;
use data::Stage;
use std::path::{Path, PathBuf};

pub const FILE: &str = REPORT;

/// Where the target and mask are when the run directory does not say.
#[derive(Clone, Debug, Default)]
pub struct ReportOptions {
    pub target: Option<PathBuf>,
    pub mask: Option<PathBuf>,
}

/// (Re)writes DIR/report.html and its figures; returns the page's path.
pub fn write(dir: &Path, options: &ReportOptions) -> Result<PathBuf> {
    let run = load(dir, options)?;
    remove_old_figures(dir)?;
    let html = page::render(&run)?;
    let path = dir.join(FILE);
    crate::fsio::write_atomic(&path, html.as_bytes())?;
    Ok(path)
}

fn load(dir: &Path, options: &ReportOptions) -> Result<Run> {
    if !dir.is_dir() {
        return Err(Error::Usage(format!(
            "{}: not a directory; expected a fit or pipeline run directory",
            dir.display()
        )));
    }
    let run = RunDir::existing(dir)?;
    let (stages, comparison) = if run.file(COMPARISON).is_file() {
        let c = Comparison::load(&run)?;
        let s1 = Stage::load(&dir.join(&c.stage1.dir), "Stage 1")?;
        let s2 = Stage::load(&dir.join(&c.stage2.dir), "Stage 2")?;
        (vec![s1, s2], Some(c))
    } else if run.file(RESULT).is_file() {
        (vec![Stage::load(dir, "Fit")?], None)
    } else {
        return Err(Error::Usage(format!(
            "{}: neither a fit directory ({RESULT}) nor a pipeline directory ({COMPARISON}); has the run finished?",
            dir.display()
        )));
    };
    let stage2_de = match comparison.as_ref().and_then(|c| c.stage2_de.as_ref()) {
        Some(s) => Some(Stage::load(&dir.join(&s.dir), "Stage 2")?),
        None => None,
    };
    let target_path = match (&options.target, &comparison) {
        (Some(p), _) => Ok(p.clone()),
        (None, Some(c)) => Ok(dir.join(&c.target)),
        (None, None) => run
            .find_target(stages[0].result.target.as_deref())
            .map_err(|e| e.to_string()),
    };
    let best = &stages[0].best;
    // Read as the fit read it: a linear PNG is not sRGB.
    let encoding = match options.target {
        Some(_) => None,
        None => stages[0].result.target_encoding,
    };
    let target = target_path.and_then(|p| {
        image_io::read_photo(&p, "target", best.dimensions(), encoding)
            .map(|photo| photo.image)
            .map_err(|e| e.to_string())
    });
    if let (Some(p), Err(m)) = (&options.target, &target) {
        return Err(Error::Usage(format!("--target {}: {m}", p.display())));
    }
    let mask_path = match (&options.mask, &comparison) {
        (Some(p), _) => Some(p.clone()),
        (None, Some(c)) => c.mask.as_ref().map(|m| dir.join(m)),
        (None, None) => None,
    };
    let mask = mask_path
        .map(|p| Mask::load(&p, best.width(), best.height()))
        .transpose()?;
    Ok(Run {
        dir: dir.to_path_buf(),
        stages,
        comparison,
        stage2_de,
        target,
        mask,
    })
}

/// Removes the figures of an earlier report, so that none outlives the
/// data it showed (a figure this run cannot draw is left out, not stale).
fn remove_old_figures(dir: &Path) -> Result<()> {
    for e in std::fs::read_dir(dir)
        .map_err(|e| Error::io(dir, e))?
        .flatten()
    {
        let name = e.file_name().to_string_lossy().to_string();
        if name.starts_with("fig_") && (name.ends_with(".png") || name.ends_with(".svg")) {
            let _ = std::fs::remove_file(e.path());
        }
    }
    Ok(())
}
