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

use super::backend::Backend;
use super::external::{started, Process};
use super::worker_start::PythonWorker;
use super::RenderSession;
use crate::error::Result;
use crate::exec::discover;
use crate::exec::process::CommandSpec;
use std::time::Duration;

/// The registry's entry (`registry::ALL`).
pub const BACKEND: Backend = Backend {
    name: "blender",
    arg: None,
    about: "Blender's Cycles path tracer, through persistent headless Blender workers",
    build: |_, opts| Box::new(Blender(opts)),
    supports: super::pbr_fields::blender,
};

/// The worker as shipped in blender_scripts/, with its process limits:
/// a 128x96 render takes ~0.1 s, big images with many samples minutes;
/// Blender's start-up over a second alone, more on a busy machine.
const WORKER: PythonWorker = PythonWorker {
    name: "blender",
    file: "blender_worker.py",
    script: include_str!("../../blender_scripts/worker.py"),
    timeouts: (Duration::from_secs(600), Duration::from_secs(120)),
    max_renders: None,
};

/// The Blender backend, with the caller's process options.
pub struct Blender(pub super::RenderOptions);

impl Process for Blender {
    fn name(&self) -> String {
        "blender".into()
    }

    fn start(&self, jobs: usize) -> Result<Box<dyn RenderSession>> {
        let program = discover::find("blender", &discover::apt_hint("blender"))?;
        let command = |dir: &std::path::Path, script| {
            CommandSpec::new(program)
                .cwd(dir)
                // Blender makes a temp dir per process and leaves it when
                // killed (restarts, timeouts): keep those inside the run's
                // own dir.
                .env("TMPDIR", dir)
                .args([
                    "-b",
                    "--factory-startup",
                    "-noaudio",
                    "--python-exit-code",
                    "1",
                    "-P",
                ])
                .arg(script)
                .args(["--", "--threads", "1"])
        };
        started(WORKER.start(jobs, &self.0, command))
    }
}
