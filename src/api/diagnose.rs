//! A diagnosis through the API: a finished fit's directory (one photograph
//! or a set) read, the memory checked, the output directory held by the
//! run-directory rule (locked, fresh unless `overwrite`, never the fit
//! directory, no input inside it replaced), then `crate::diagnose` run.

use crate::diagnose::{self, DiagnoseConfig, Diagnosis, Inputs, SetInputs};
use crate::error::{Error, Result};
use crate::rundir::{Kind, Mode, RunDir, SHOTS};
use crate::scene::memory::Population;
use std::path::{Path, PathBuf};

/// What a diagnosis reads and where it writes.
#[derive(Clone, Debug)]
pub struct DiagnoseRequest {
    /// A directory written by a fit.
    pub fit_dir: PathBuf,
    /// Where the diagnosis goes.
    pub output: PathBuf,
    /// The target (default: the one the fit's result.json names); not for a set.
    pub target: Option<PathBuf>,
    /// The mask (default: the fit directory's); not for a set.
    pub mask: Option<PathBuf>,
    /// Replace an earlier diagnosis in `output`.
    pub overwrite: bool,
    /// A set's shots held out of the diagnosis besides those the fit held
    /// out (names as in its shots file).
    pub hold_out: Vec<String>,
    pub config: DiagnoseConfig,
}

/// Diagnoses the fit in `r.fit_dir` (one photograph or a set) into
/// `r.output`; returned as its pooled part.
pub fn diagnose(r: &DiagnoseRequest) -> Result<Diagnosis> {
    check_effects(&r.config)?;
    let set = SetInputs::from_fit_dir(&r.fit_dir, &r.hold_out)?;
    if set.is_none() && !r.hold_out.is_empty() {
        return Err(Error::Usage(
            "--hold-out: applies to a set of photographs; the fit directory holds one".into(),
        ));
    }
    if set.is_some() && (r.target.is_some() || r.mask.is_some()) {
        return Err(Error::Usage(format!(
            "--target/--mask: the fit directory holds a set of photographs; each one's target and mask come from its {SHOTS}"
        )));
    }
    check_memory(&r.fit_dir, &r.config, set.as_ref())?;
    // The output is held and checked before the photograph is read: a
    // refused diagnosis says only why.
    let out = open_output(r)?;
    refuse_inputs(&out, r, set.as_ref())?;
    // One photograph is a set of one, read once the output is held.
    let inputs = match set {
        Some(s) => s,
        None => SetInputs::one(&Inputs::from_fit_dir(
            &r.fit_dir,
            r.target.as_deref(),
            r.mask.as_deref(),
        )?),
    };
    // An earlier diagnosis's files go only once this one has its inputs.
    if r.overwrite {
        out.clear()?;
    }
    Ok(diagnose::run(&inputs, &r.output, &r.config)?.diagnosis)
}

/// Every effect `config` names is one the registry holds, and it names
/// at least one.
fn check_effects(config: &DiagnoseConfig) -> Result<()> {
    let Some(names) = &config.effects else {
        return Ok(());
    };
    let known = diagnose::effects::names();
    match names.iter().find(|e| !known.contains(&e.as_str())) {
        Some(bad) => Err(Error::Usage(format!(
            "--effects: no effect named {bad:?}; expected one or more of {}",
            known.join(", ")
        ))),
        None if names.is_empty() => Err(Error::Usage(
            "--effects: expected one or more effect names".into(),
        )),
        None => Ok(()),
    }
}

/// The output directory, locked, by the run-directory rule; never the fit
/// directory itself (the diagnosis's report.html would replace the fit's).
fn open_output(r: &DiagnoseRequest) -> Result<RunDir> {
    let same = |p: &Path| p.canonicalize().ok();
    if same(&r.output).is_some() && same(&r.output) == same(&r.fit_dir) {
        return Err(Error::Usage(format!(
            "-o {}: this is the fit directory; give the diagnosis a directory of its own",
            r.output.display()
        )));
    }
    let mode = if r.overwrite {
        Mode::Overwrite
    } else {
        Mode::Fresh
    };
    RunDir::open_as(&r.output, mode, Kind::Named(crate::rundir::diagnosis_owns))
}

/// Refuses an input (the target, the mask, a shot's photograph or mask)
/// that the diagnosis would overwrite in its output directory.
fn refuse_inputs(out: &RunDir, r: &DiagnoseRequest, set: Option<&SetInputs>) -> Result<()> {
    let mut inputs: Vec<(String, &Path)> = [("--target", &r.target), ("--mask", &r.mask)]
        .into_iter()
        .filter_map(|(what, p)| p.as_deref().map(|p| (what.to_string(), p)))
        .collect();
    for s in set.iter().flat_map(|s| s.shots.iter().chain(&s.held_out)) {
        inputs.push((format!("shot {}'s target", s.name), &s.entry.target));
        if let Some(m) = &s.entry.mask {
            inputs.push((format!("shot {}'s mask", s.name), m));
        }
    }
    inputs
        .into_iter()
        .try_for_each(|(what, p)| out.refuse_overwritten_input(p, &what))
}

/// Refuses a diagnosis that would not fit in memory. Its refits run side
/// by side, up to one per job and no more than a round's refits (each
/// effect and the unchanged model, warm and from scratch), each with the
/// largest of its populations and each candidate drawn once per
/// photograph: counted as that many images of each candidate at once.
/// Checked before a single fit's target is read, from its fitted scene.
fn check_memory(fit_dir: &Path, c: &DiagnoseConfig, set: Option<&SetInputs>) -> Result<()> {
    let file = fit_dir.join(crate::rundir::FITTED_SCENE);
    let (scene, shots) = match set {
        Some(s) => (s.scene.clone(), s.shots.len()),
        None => (crate::scene::load(&file)?, 1),
    };
    let lanes = c.jobs.min(2 * (crate::diagnose::effects::ALL.len() + 1));
    let pop = Population {
        option: "--population",
        size: c
            .population
            .max(c.search_population)
            .max(c.restart_population),
        copies: lanes.saturating_mul(shots),
    };
    let size = (scene.image.width, scene.image.height);
    crate::scene::memory::check(&file.display().to_string(), size, pop, c.jobs)
}
