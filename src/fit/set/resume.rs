//! A resumed run's saved state checked against this run's inputs: the
//! same kind of fit (one photograph or a set), the same photographs,
//! scene and search options (`identity`), and values that fit the scene.
//! Each refusal is one line naming the file and what differs.

use super::run::Run;
use super::state::{search_fits, FitState};
use crate::error::{Error, Result};
use crate::rundir::RunDir;
use crate::scene::ParamSpace;

/// The refusal of a resume whose inputs differ (`what`) from those of the
/// run saved in `file`.
pub fn refuse(file: &str, what: &str) -> Error {
    Error::Usage(format!(
        "cannot resume the run saved in {file}: {what}; resume with the same inputs and options, or start afresh with --overwrite"
    ))
}

/// Checks the state `s` read from `file` against `run`; `fresh` is the
/// state this run would start from.
pub fn check(s: &FitState, file: &str, run: &Run, fresh: &FitState) -> Result<()> {
    let holds = match (s.base.is_some(), run.alone) {
        (true, false) => Some("one photograph's fit (fit --target)"),
        (false, true) => Some("a set's fit (fit --shots)"),
        _ => None,
    };
    if let Some(holds) = holds {
        return Err(Error::Usage(format!(
            "cannot resume the run saved in {file}: it holds {holds}; resume it with the inputs it was started with, or start afresh with --overwrite"
        )));
    }
    if run.alone {
        check_one(s, file)?;
    }
    let mismatch = |what: String| refuse(file, &what);
    if s.held_out != fresh.held_out {
        return Err(mismatch(format!(
            "the photographs held out were [{}], now [{}]",
            s.held_out.join(", "),
            fresh.held_out.join(", ")
        )));
    }
    if s.identities.len() != fresh.identities.len() {
        return Err(mismatch(format!(
            "the shots file listed {} photographs, now {}",
            s.identities.len(),
            fresh.identities.len()
        )));
    }
    for ((was, is), shot) in s.identities.iter().zip(&fresh.identities).zip(run.shots) {
        if let Some(what) = was.mismatch(is) {
            // One photograph needs no name.
            return Err(mismatch(match run.alone {
                true => what,
                false => format!("shot {}: {what}", shot.name),
            }));
        }
    }
    if !run.alone && s.rounds != run.config.rounds {
        return Err(mismatch(format!(
            "--rounds was {}, now {}",
            s.rounds, run.config.rounds
        )));
    }
    if run.alone {
        check_image(s, file, run)
    } else {
        check_set(s, file, run, fresh)
    }
}

/// One photograph's state: a valid base scene, a phase it has, a search
/// over that phase's coordinates.
fn check_one(s: &FitState, file: &str) -> Result<()> {
    let Some(base) = &s.base else { return Ok(()) };
    crate::scene::validate::validate(base, &format!("{file} (base)"))?;
    let space = ParamSpace::from_scene(base);
    let Some(&phase) = space.phases().get(s.blocks_done) else {
        return Err(Error::invalid(
            file,
            "blocks_done",
            "past the scene's phases",
        ));
    };
    let dim = space.phase(phase).dim();
    if s.within
        .search
        .as_ref()
        .is_some_and(|q| !search_fits(q, dim))
    {
        return Err(Error::invalid(
            file,
            "within.search",
            format!("does not match the scene's {dim} free coordinates of phase {phase}"),
        ));
    }
    Ok(())
}

/// Refuses a state whose scene declares another image size than the
/// run's scene: the size the run's memory was checked for
/// (`scene::memory`) is the size it renders at.
fn check_image(s: &FitState, file: &str, run: &Run) -> Result<()> {
    let Some(base) = &s.base else { return Ok(()) };
    let (b, now) = (&base.image, &run.scene.image);
    if (b.width, b.height) == (now.width, now.height) {
        return Ok(());
    }
    Err(Error::invalid(
        file,
        "base.image",
        format!(
            "declares {}x{} pixels; expected the scene's {}x{}",
            b.width, b.height, now.width, now.height
        ),
    ))
}

/// A set's state: unit-cube values for every free parameter, the
/// progress within a block that fits the set.
fn check_set(s: &FitState, file: &str, run: &Run, fresh: &FitState) -> Result<()> {
    let bad = |key: &str, what: &str| Error::invalid(file, key, what);
    let unit = |v: &[f64]| v.iter().all(|x| (0.0..=1.0).contains(x));
    let sizes_ok = s.shared.len() == fresh.shared.len()
        && unit(&s.shared)
        && s.own.len() == fresh.own.len()
        && s.own
            .iter()
            .zip(&fresh.own)
            .all(|(a, b)| a.len() == b.len() && unit(a));
    if !sizes_ok {
        return Err(bad(
            "shared",
            "expected unit-cube values for every free parameter of the scene",
        ));
    }
    let w = &s.within;
    let parts_ok = w.own_parts.len() <= run.shots.len()
        && w.own_parts
            .iter()
            .all(|p| p.len() == 4 && p.iter().all(|x| x.is_finite() && *x >= 0.0));
    if !parts_ok {
        return Err(bad(
            "within.own_parts",
            "expected four deviations >= 0 for each photograph fitted so far",
        ));
    }
    let fits = |q: &crate::optimize::Searcher| search_fits(q, fresh.shared.len());
    let search_ok = w.search.as_ref().is_none_or(fits) && s.last_shared.as_ref().is_none_or(fits);
    if !search_ok || (w.search.is_some() && !w.own_parts.is_empty()) {
        return Err(bad(
            "within.search",
            "expected a search over the scene's shared coordinates",
        ));
    }
    if !s.history.iter().all(|h| h.is_finite() && *h >= 0.0) {
        return Err(bad("history", "expected deviations >= 0"));
    }
    Ok(())
}

/// The file a refusal names.
pub fn file_of(dir: &RunDir) -> String {
    dir.file(super::state::saved_in(dir)).display().to_string()
}
