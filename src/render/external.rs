//! The session of every renderer that runs as a separate process (POV-Ray,
//! Blender, Mitsuba, plug-ins): a private temporary directory for the run,
//! a tokio runtime, and either one process per render or a pool of
//! persistent workers (`crate::exec`). Renders that fail cost their
//! candidate only; the processes are killed when the session is dropped.

use super::{RenderFailure, RenderOptions, RenderResult, RenderSession};
use crate::error::{Error, Result};
use crate::exec::oneshot::{self, OneShotJob};
use crate::exec::pool::{WorkerJob, WorkerPool};
use crate::exec::process::CommandSpec;
use crate::exec::{self, ExecConfig};
use crate::scene::Scene;
use std::path::{Path, PathBuf};
use std::time::Duration;
use tempfile::TempDir;
use tokio::runtime::Runtime;

/// A one-shot renderer: how one render is set up.
pub trait OneShotBackend: Send {
    /// Writes what the renderer reads for render `id` of `scene` into `dir`
    /// and returns the command that renders it and the image it writes.
    /// An Err fails that render (the scene cannot be expressed).
    fn prepare(
        &self,
        dir: &Path,
        id: u64,
        scene: &Scene,
        seed: u64,
    ) -> std::result::Result<(CommandSpec, PathBuf), String>;
}

enum Mode {
    OneShot(Box<dyn OneShotBackend>),
    Persistent(WorkerPool),
}

/// A running process-backed session.
pub struct ExternalSession {
    mode: Mode,
    cfg: ExecConfig,
    describe: String,
    next_id: u64,
    // Dropped last: the runtime after the workers are stopped, the
    // directory after both.
    rt: Runtime,
    dir: TempDir,
}

/// The run's private temporary directory (removed when the session ends).
fn run_dir() -> Result<TempDir> {
    let dir = tempfile::Builder::new()
        .prefix("scenefit-run-")
        .tempdir()
        .map_err(|e| Error::io(&std::env::temp_dir(), e))?;
    // removed by the watchdog should scenefit be killed outright
    exec::watchdog::watch_dir(dir.path());
    Ok(dir)
}

/// A backend's process limits (its default render and start-up timeouts,
/// overridden by the caller's options) and the run's private directory.
pub fn session_dir(
    jobs: usize,
    (render_timeout, startup_timeout): (Duration, Duration),
    opts: &RenderOptions,
) -> Result<(ExecConfig, TempDir)> {
    let cfg = ExecConfig::new(jobs, render_timeout, startup_timeout, opts)?;
    let dir = run_dir()?;
    cfg.launcher.use_dir(dir.path());
    Ok((cfg, dir))
}

impl ExternalSession {
    /// A session that runs one process per render.
    pub fn one_shot(
        backend: Box<dyn OneShotBackend>,
        cfg: ExecConfig,
        describe: String,
        dir: TempDir,
    ) -> Result<ExternalSession> {
        Ok(ExternalSession {
            mode: Mode::OneShot(backend),
            cfg,
            describe,
            next_id: 1,
            rt: exec::runtime()?,
            dir,
        })
    }

    /// A session served by `cfg.jobs` persistent workers running `spec`;
    /// `name` labels errors. Fails when no worker starts.
    pub fn persistent(
        name: &str,
        spec: CommandSpec,
        cfg: ExecConfig,
        dir: TempDir,
    ) -> std::result::Result<ExternalSession, (Error, RenderFailure)> {
        let rt = exec::runtime().map_err(|e| {
            (
                e,
                RenderFailure {
                    message: String::new(),
                    stderr: String::new(),
                },
            )
        })?;
        match WorkerPool::start(&rt, spec, cfg.clone()) {
            Ok(pool) => {
                let describe = if pool.renderer.is_empty() {
                    name.to_string()
                } else {
                    pool.renderer.clone()
                };
                Ok(ExternalSession {
                    mode: Mode::Persistent(pool),
                    cfg,
                    describe,
                    next_id: 1,
                    rt,
                    dir,
                })
            }
            Err(f) => Err((Error::Run(format!("{name}: no worker started: {f}")), f)),
        }
    }

    /// The run directory.
    pub fn dir(&self) -> &Path {
        self.dir.path()
    }

    fn take_id(&mut self) -> u64 {
        let id = self.next_id;
        self.next_id += 1;
        id
    }
}

/// The request line of the plug-in protocol for one render. It offers the
/// raw-pixel extension (`"pixels": "raw"`, docs/plugins.md): a worker that
/// knows it skips image encoding and decoding and says so in its answer;
/// one that does not ignores the key and writes an image file.
pub fn request_line(id: u64, scene: &Scene, output: &Path, seed: u64) -> String {
    let scene = plain_scene(scene);
    serde_json::json!({"id": id, "scene": scene, "output": output.to_string_lossy(), "seed": seed, "pixels": "raw"})
        .to_string()
}

/// The scene a renderer sees: without the search's `free` list.
pub fn plain_scene(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    s.free.clear();
    s
}

impl RenderSession for ExternalSession {
    fn describe(&self) -> String {
        self.describe.clone()
    }

    fn render_batch(&mut self, scenes: &[Scene], seed: u64) -> Vec<RenderResult> {
        let mut results: Vec<Option<RenderResult>> = (0..scenes.len()).map(|_| None).collect();
        let ids: Vec<u64> = scenes.iter().map(|_| self.take_id()).collect();
        let dir = self.dir.path().to_path_buf();
        match &mut self.mode {
            Mode::OneShot(backend) => {
                let mut jobs = Vec::new();
                let mut slots = Vec::new();
                for (i, (scene, id)) in scenes.iter().zip(&ids).enumerate() {
                    match backend.prepare(&dir, *id, scene, seed) {
                        Ok((command, output)) => {
                            jobs.push(OneShotJob {
                                command,
                                output,
                                width: scene.image.width,
                                height: scene.image.height,
                            });
                            slots.push(i);
                        }
                        Err(message) => {
                            results[i] = Some(Err(RenderFailure {
                                message,
                                stderr: String::new(),
                            }))
                        }
                    }
                }
                let rendered = oneshot::run_batch(&self.rt, &self.cfg, jobs);
                for (i, r) in slots.into_iter().zip(rendered) {
                    results[i] = Some(r);
                }
                cleanup_inputs(&dir, &ids);
            }
            Mode::Persistent(pool) => {
                let jobs: Vec<WorkerJob> = scenes
                    .iter()
                    .zip(&ids)
                    .map(|(scene, id)| {
                        let output = dir.join(format!("r{id}.png"));
                        WorkerJob {
                            line: request_line(*id, scene, &output, seed),
                            id: *id,
                            output,
                            width: scene.image.width,
                            height: scene.image.height,
                        }
                    })
                    .collect();
                for (i, r) in pool.run_batch(&self.rt, jobs).into_iter().enumerate() {
                    results[i] = Some(r);
                }
            }
        }
        results
            .into_iter()
            .map(|r| {
                r.unwrap_or_else(|| {
                    Err(RenderFailure {
                        message: "not rendered".into(),
                        stderr: String::new(),
                    })
                })
            })
            .collect()
    }
}

/// Removes the per-render input files (`r{id}.*`) a one-shot backend wrote.
fn cleanup_inputs(dir: &Path, ids: &[u64]) {
    for id in ids {
        for ext in ["pov", "json", "png"] {
            let _ = std::fs::remove_file(dir.join(format!("r{id}.{ext}")));
        }
    }
}

impl Drop for ExternalSession {
    fn drop(&mut self) {
        // the TempDir removes the directory right after this
        exec::watchdog::forget_dir(self.dir.path());
        if let Mode::Persistent(pool) = &mut self.mode {
            if tokio::runtime::Handle::try_current().is_ok() {
                // inside another runtime we cannot block: the workers are
                // killed when their handles drop (kill_on_drop)
                return;
            }
            pool.shutdown(&self.rt);
        }
    }
}
