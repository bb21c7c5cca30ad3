//! The Mitsuba 3 backend: a pool of Python processes, each running the
//! persistent worker `workers/mitsuba_worker.py` (embedded in the binary and
//! written into the run's temporary directory) as `python3
//! mitsuba_worker.py --threads 1`; `RenderOptions::python` (the command
//! line's `--python`), else `SCENEFIT_PYTHON`, names another Python.
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

use super::external::{python_worker_dir, ExternalSession};
use super::{RenderSession, Renderer};
use crate::error::{Error, Result};
use crate::exec::process::CommandSpec;
use crate::exec::{discover, ENV_MAX_RENDERS};
use crate::scene::{ParamSpace, Scene};
use std::time::Duration;

/// The worker script, as shipped in workers/.
const WORKER: &str = include_str!("../../workers/mitsuba_worker.py");

/// Environment variable: the Python that runs the worker (default python3).
pub const ENV_PYTHON: &str = "SCENEFIT_PYTHON";

/// Default per-render timeout: a 128x96 render takes ~15 ms, a new scene
/// structure a JIT compile of ~0.3 s; big images with many samples minutes.
const RENDER_TIMEOUT: Duration = Duration::from_secs(300);
/// Importing Mitsuba and starting LLVM.
const STARTUP_TIMEOUT: Duration = Duration::from_secs(60);

/// Renders a worker serves before it is restarted, unless the caller
/// chose: a restart costs ~0.5 s of CPU (importing Mitsuba, starting LLVM,
/// the first kernel), 2.5 ms a render at the general default of 200, and
/// the worker's memory stayed flat over 1200 renders (measured).
const MAX_RENDERS: usize = 2000;

const INSTALL: &str = "install it with `python3 -m pip install mitsuba` (and `apt-get install libllvm19`) or run scripts/install-renderers.sh";

/// The Mitsuba backend, with the caller's process options.
pub struct Mitsuba(pub super::RenderOptions);

impl Renderer for Mitsuba {
    fn name(&self) -> String {
        "mitsuba".into()
    }

    fn session(
        &self,
        base: &Scene,
        _varying: &ParamSpace,
        jobs: usize,
    ) -> Result<Box<dyn RenderSession>> {
        super::pbr_fields::check(base, "mitsuba")?;
        let python = match &self.0.python {
            Some(p) => p.to_string_lossy().into_owned(),
            None => std::env::var(ENV_PYTHON)
                .ok()
                .filter(|s| !s.trim().is_empty())
                .unwrap_or_else(|| "python3".into()),
        };
        let program = discover::find(
            &python,
            &format!(
                "name a Python 3 with Mitsuba (the Python option or {ENV_PYTHON}), or {INSTALL}"
            ),
        )?;
        let (mut cfg, dir, script) = python_worker_dir(
            jobs,
            (RENDER_TIMEOUT, STARTUP_TIMEOUT),
            &self.0,
            "mitsuba_worker.py",
            WORKER,
        )?;
        let chosen = std::env::var(ENV_MAX_RENDERS).is_ok_and(|v| !v.trim().is_empty());
        if self.0.worker_max_renders.is_none() && !chosen {
            cfg.max_renders = MAX_RENDERS;
        }
        let spec = CommandSpec::new(program)
            .cwd(dir.path())
            .arg(script)
            .args(["--threads", "1"]);
        match ExternalSession::persistent("mitsuba", spec, cfg, dir) {
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
