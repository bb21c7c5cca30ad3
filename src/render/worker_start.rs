//! One start-up path for the persistent Python workers (Blender's and
//! Mitsuba's): the run's private directory with the worker script and the
//! modules it imports written beside it, the process limits (the backend's
//! defaults under the caller's options), and the pool of workers.

use super::external::{session_dir, ExternalSession};
use super::{RenderFailure, RenderOptions};
use crate::error::Error;
use crate::exec::process::CommandSpec;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The modules every Python worker imports, written beside it: the
/// JSON-lines protocol and the shared scene translation.
const MODULES: &[(&str, &str)] = &[
    ("jsonlines.py", include_str!("../../workers/jsonlines.py")),
    (
        "scene_common.py",
        include_str!("../../workers/scene_common.py"),
    ),
];

/// A persistent Python worker as a backend ships it.
pub struct PythonWorker {
    /// The backend's name, for errors.
    pub name: &'static str,
    /// The file name the script is written under.
    pub file: &'static str,
    /// The script, embedded in the binary.
    pub script: &'static str,
    /// The default per-render and start-up timeouts.
    pub timeouts: (Duration, Duration),
    /// Renders a worker serves before it is restarted, when the caller did
    /// not choose; None keeps the general default.
    pub max_renders: Option<usize>,
}

impl PythonWorker {
    /// Starts `jobs` workers, each run by the command `command` builds
    /// from the run directory and the script's path. Err carries the first
    /// failure too, for a backend to recognise (a missing package).
    pub fn start(
        &self,
        jobs: usize,
        opts: &RenderOptions,
        command: impl FnOnce(&Path, PathBuf) -> CommandSpec,
    ) -> std::result::Result<ExternalSession, (Error, RenderFailure)> {
        let no_failure = |e| {
            let f = RenderFailure {
                message: String::new(),
                stderr: String::new(),
            };
            (e, f)
        };
        let (mut cfg, dir) = session_dir(jobs, self.timeouts, opts).map_err(no_failure)?;
        if let (None, Some(n)) = (opts.worker_max_renders, self.max_renders) {
            cfg.max_renders = n;
        }
        for (name, text) in MODULES {
            write_script(dir.path(), name, text).map_err(no_failure)?;
        }
        let script = write_script(dir.path(), self.file, self.script).map_err(no_failure)?;
        let spec = command(dir.path(), script);
        ExternalSession::persistent(self.name, spec, cfg, dir)
    }
}

/// Writes an embedded script into the run directory.
fn write_script(dir: &Path, name: &str, text: &str) -> crate::error::Result<PathBuf> {
    let path = dir.join(name);
    std::fs::write(&path, text).map_err(|e| Error::io(&path, e))?;
    Ok(path)
}
