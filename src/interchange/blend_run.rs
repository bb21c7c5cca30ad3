//! Runs one of the Blender scripts of `scenefit import` / `export` once,
//! headless (the backend's persistent worker serves renders; these run one
//! job): the script and the modules it imports (the worker itself, whose
//! scene build the export reuses, and scene_common / jsonlines) written
//! into a private temporary directory, Blender started as the backend
//! starts it plus `--disable-autoexec` (a .blend's own Python never runs),
//! run by the one interchange runner (`script_run`: a time limit, the
//! process group killed), its output read for the script's own error.

use super::script_run;
use crate::error::{Error, Result};
use crate::exec::process::CommandSpec;
use std::ffi::OsString;
use std::path::Path;

/// The scripts and the modules they import, as shipped.
const FILES: &[(&str, &str)] = &[
    ("worker.py", include_str!("../../blender_scripts/worker.py")),
    (
        "export_blend.py",
        include_str!("../../blender_scripts/export_blend.py"),
    ),
    (
        "import_blend.py",
        include_str!("../../blender_scripts/import_blend.py"),
    ),
    ("jsonlines.py", include_str!("../../workers/jsonlines.py")),
    (
        "scene_common.py",
        include_str!("../../workers/scene_common.py"),
    ),
];

/// The line a script prints before a user's error (a file it cannot map),
/// to be shown as scenefit's one-line error.
const USER_ERROR: &str = "scenefit-error: ";

/// Runs `blender -b [blend] ... -P script -- args` in the temporary
/// directory `dir` (which receives the scripts). Err(Usage) carries a
/// script's own user error; Err(Run) the end of Blender's output.
pub fn run(dir: &Path, blend: Option<&Path>, script: &str, args: &[OsString]) -> Result<()> {
    let program =
        crate::exec::discover::find("blender", &crate::exec::discover::apt_hint("blender"))?;
    script_run::write_files(dir, FILES)?;
    let mut spec = CommandSpec::new(program).arg("-b");
    if let Some(b) = blend {
        spec = spec.arg(b);
    }
    let spec = spec
        .args(["--factory-startup", "--disable-autoexec", "-noaudio"])
        .args(["--python-exit-code", "1", "-P"])
        .arg(dir.join(script))
        .arg("--")
        .args(args.iter().cloned())
        .cwd(dir)
        .env("TMPDIR", dir);
    let ran = script_run::run(&spec, script_run::TIME_LIMIT)?;
    let text = &ran.text;
    if let Some(line) = text.lines().rev().find_map(|l| l.strip_prefix(USER_ERROR)) {
        return Err(Error::Usage(line.trim().to_string()));
    }
    if let (Some(b), Some(why)) = (blend, unreadable(text)) {
        return Err(Error::Usage(format!(
            "{}: Blender cannot read it ({why}); expected a .blend file saved by Blender",
            b.display()
        )));
    }
    match ran.failure {
        None => Ok(()),
        Some(failure) => Err(Error::Run(format!(
            "Blender running {script} {failure}: {}",
            script_run::last_lines(text, 3)
        ))),
    }
}

/// Blender's reason for not loading the file it was given, from its log
/// ("Error: Failed to read blend file 'F': Missing DNA block").
fn unreadable(log: &str) -> Option<String> {
    let line = log
        .lines()
        .find(|l| l.contains("Failed to read blend file") || l.contains("Cannot read file"))?;
    let why = line.rsplit(": ").next().unwrap_or(line).trim();
    Some(why.to_string())
}
