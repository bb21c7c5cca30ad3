//! One run of a Python script of workers/ for an import or export, by the
//! one interchange runner (`script_run`: a private directory, a time
//! limit, the process group killed); its answer read from a small JSON file it writes
//! (`{"ok": true, ...}` or `{"ok": false, "error": "...", "user": bool}`),
//! so that nothing the renderer's package prints can be taken for it.

use super::script_run;
use crate::error::{Error, Result};
use crate::exec::process::CommandSpec;
use std::ffi::OsString;
use std::path::Path;

/// The modules the Mitsuba scripts import, as shipped in workers/.
pub const MITSUBA_MODULES: &[(&str, &str)] = &[
    ("jsonlines.py", include_str!("../../workers/jsonlines.py")),
    (
        "scene_common.py",
        include_str!("../../workers/scene_common.py"),
    ),
    (
        "mitsuba_worker.py",
        include_str!("../../workers/mitsuba_worker.py"),
    ),
];

/// An answer is a few warnings and a scene: far below this.
const MAX_ANSWER_BYTES: u64 = 64 << 20;

/// Runs `script` (a file name and its text) with `args` after the
/// directory's own paths: `python SCRIPT ARGS... ANSWER.json`; `what`
/// names the job in errors. Returns the answer's object.
pub fn run(
    python: &Path,
    modules: &[(&str, &str)],
    script: (&str, &str),
    args: &[OsString],
    what: &str,
) -> Result<serde_json::Value> {
    let dir = tempfile::Builder::new()
        .prefix("scenefit-interchange-")
        .tempdir()
        .map_err(|e| Error::Run(format!("{what}: cannot make a temporary directory: {e}")))?;
    script_run::write_files(dir.path(), modules)?;
    script_run::write_files(dir.path(), &[script])?;
    let answer = dir.path().join("answer.json");
    let spec = CommandSpec::new(python)
        .cwd(dir.path())
        .arg(dir.path().join(script.0))
        .args(args.iter().cloned())
        .arg(&answer);
    let ran = script_run::run(&spec, script_run::TIME_LIMIT)?;
    let stderr = &ran.text;
    if stderr.contains("No module named 'mitsuba'") || stderr.contains("No module named 'drjit'") {
        return Err(Error::Usage(format!(
            "{what}: the mitsuba Python package is not installed for {}; install it with `python3 -m pip install mitsuba` or name another Python with --python",
            python.display()
        )));
    }
    let bytes = crate::input::read_capped(&answer, MAX_ANSWER_BYTES).map_err(|_| {
        Error::Run(format!(
            "{what}: {} {} without an answer: {}",
            python.display(),
            ran.failure.as_deref().unwrap_or("exited 0"),
            script_run::last_lines(stderr, 3)
        ))
    })?;
    let value: serde_json::Value = serde_json::from_slice(&bytes)
        .map_err(|e| Error::Run(format!("{what}: unreadable answer: {e}")))?;
    if value["ok"] == serde_json::Value::Bool(true) {
        return Ok(value);
    }
    let message = value["error"].as_str().unwrap_or("failed").to_string();
    if value["user"] == serde_json::Value::Bool(true) {
        Err(Error::Usage(message))
    } else {
        Err(Error::Run(format!("{what}: {message}")))
    }
}

/// The answer's `warnings`, as strings.
pub fn warnings(answer: &serde_json::Value) -> Vec<String> {
    answer["warnings"]
        .as_array()
        .map(|a| {
            a.iter()
                .filter_map(|w| w.as_str().map(str::to_string))
                .collect()
        })
        .unwrap_or_default()
}
