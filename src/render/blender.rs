//! The Blender (Cycles) backend: a pool of headless Blender processes, each
//! running the persistent worker `blender_scripts/worker.py` (embedded in
//! the binary and written into the run's temporary directory), started as
//! `blender -b --factory-startup -noaudio --python-exit-code 1 -P worker.py
//! -- --threads 1`. Blender's start-up (over a second) is paid once per
//! worker, not per render.
//!
//! Scene fields: all but what `pbr_fields.rs` refuses, mapped by the worker (its module docstring;
//! docs/renderers.md, "Blender"): camera, `image`, `ambient`, `render.samples`
//! and `render.indirect`, point (power 4 pi I W) and directional lights,
//! `falloff`, `falloff_power`, `radius`, spheres, planes, quads, boxes,
//! materials (Lambertian Diffuse BSDF; the built-in tracer's lobes, with
//! `fresnel` and `specular2`, through a node graph of the worker's own;
//! Principled BSDF for glass). `render.antialias` and `render.max_depth`
//! are the built-in tracer's and unused here.

use super::external::{python_worker_dir, ExternalSession};
use super::{RenderSession, Renderer};
use crate::error::Result;
use crate::exec::discover;
use crate::exec::process::CommandSpec;
use crate::scene::{ParamSpace, Scene};
use std::time::Duration;

/// The worker script, as shipped in blender_scripts/.
const WORKER: &str = include_str!("../../blender_scripts/worker.py");

/// Default per-render timeout: a 128x96 render takes ~0.1 s; big images
/// with many samples take minutes.
const RENDER_TIMEOUT: Duration = Duration::from_secs(600);
/// Blender's start-up: over a second alone, more on a busy machine.
const STARTUP_TIMEOUT: Duration = Duration::from_secs(120);

/// The Blender backend, with the caller's process options.
pub struct Blender(pub super::RenderOptions);

impl Renderer for Blender {
    fn name(&self) -> String {
        "blender".into()
    }

    fn session(
        &self,
        base: &Scene,
        _varying: &ParamSpace,
        jobs: usize,
    ) -> Result<Box<dyn RenderSession>> {
        super::pbr_fields::check(base, "blender")?;
        let program = discover::find("blender", &discover::apt_hint("blender"))?;
        let (cfg, dir, script) = python_worker_dir(
            jobs,
            (RENDER_TIMEOUT, STARTUP_TIMEOUT),
            &self.0,
            "blender_worker.py",
            WORKER,
        )?;
        let spec = CommandSpec::new(program)
            .cwd(dir.path())
            // Blender makes a temp dir per process and leaves it when killed
            // (restarts, timeouts): keep those inside the run's own dir.
            .env("TMPDIR", dir.path())
            .args([
                "-b",
                "--factory-startup",
                "-noaudio",
                "--python-exit-code",
                "1",
                "-P",
            ])
            .arg(script)
            .args(["--", "--threads", "1"]);
        match ExternalSession::persistent("blender", spec, cfg, dir) {
            Ok(s) => Ok(Box::new(s)),
            Err((e, _)) => Err(e),
        }
    }
}
