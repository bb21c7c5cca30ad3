//! The Mitsuba 3 backend: a pool of Python processes, each running the
//! persistent worker `workers/mitsuba_worker.py` (embedded in the binary and
//! written into the run's temporary directory) as `python3
//! mitsuba_worker.py --threads 1`; `RenderOptions::python` (the command
//! line's `--python` or `SCENEFIT_PYTHON`) names another Python.
//! The worker keeps the loaded scene and only updates changed values.
//!
//! Scene fields: all but what `pbr_fields.rs` refuses, mapped by the worker
//! (its module docstring; docs/renderers.md, "Mitsuba"): camera, `image`,
//! `ambient`, `render.samples` and `render.indirect`, point lights (W/sr;
//! any falloff through the worker's own `scenefit_point` emitter), spheres
//! as area lights for `radius` > 0, directional lights, spheres, planes,
//! quads, boxes, materials (the built-in tracer's lobes through the
//! worker's own `scenefit_phong` BSDF; principled for glass).
//! `render.antialias` and `render.max_depth` are unused here.

use super::backend::Backend;
use super::external::Process;
use super::worker_start::PythonWorker;
use super::RenderSession;
use crate::error::{Error, Result};
use crate::exec::discover;
use crate::exec::process::CommandSpec;
use std::time::Duration;

/// The registry's entry (`registry::ALL`).
pub const BACKEND: Backend = Backend {
    name: "mitsuba",
    arg: None,
    about: "Mitsuba 3's path tracer (CPU, LLVM), through persistent Python workers",
    build: |_, opts| Box::new(Mitsuba(opts)),
    supports: super::pbr_fields::mitsuba,
};

/// The worker as shipped in workers/, with its process limits: a 128x96
/// render takes ~15 ms, a new scene structure a JIT compile of ~0.3 s, big
/// images with many samples minutes; start-up is importing Mitsuba and
/// starting LLVM. A restart costs ~0.5 s of CPU (importing Mitsuba,
/// starting LLVM, the first kernel), 2.5 ms a render at 200 renders a
/// worker, and the worker's memory stayed flat over 1200 renders
/// (measured): hence 2000 renders unless the caller chooses.
const WORKER: PythonWorker = PythonWorker {
    name: "mitsuba",
    file: "mitsuba_worker.py",
    script: include_str!("../../workers/mitsuba_worker.py"),
    timeouts: (Duration::from_secs(300), Duration::from_secs(60)),
    max_renders: Some(2000),
};

const INSTALL: &str = "install it with `python3 -m pip install mitsuba` (and `apt-get install libllvm19`) or run scripts/install-renderers.sh";

/// The Mitsuba backend, with the caller's process options.
pub struct Mitsuba(pub super::RenderOptions);

impl Process for Mitsuba {
    fn name(&self) -> String {
        "mitsuba".into()
    }

    fn start(&self, jobs: usize) -> Result<Box<dyn RenderSession>> {
        let python = match &self.0.python {
            Some(p) => p.to_string_lossy().into_owned(),
            None => "python3".into(),
        };
        let program = discover::find(
            &python,
            &format!("name a Python 3 with Mitsuba (--python or SCENEFIT_PYTHON), or {INSTALL}"),
        )?;
        let command = |dir: &std::path::Path, script| {
            CommandSpec::new(program)
                .cwd(dir)
                .arg(script)
                .args(["--threads", "1"])
        };
        match WORKER.start(jobs, &self.0, command) {
            Ok(s) => Ok(Box::new(s)),
            Err((_, f))
                if f.stderr.contains("No module named 'mitsuba'")
                    || f.stderr.contains("No module named 'drjit'") =>
            {
                Err(Error::Usage(format!(
                    "mitsuba: the Python package is not installed for {python}; {INSTALL}"
                )))
            }
            Err((e, _)) => Err(e),
        }
    }
}
