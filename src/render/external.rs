//! The session of every renderer that runs as a separate process (POV-Ray,
//! Blender, Mitsuba, plug-ins): a private temporary directory for the run,
//! a tokio runtime, and either one process per render or a pool of
//! persistent workers (`crate::exec`). Renders that fail cost their
//! candidate only; the processes are killed when the session is dropped.

use super::{RenderFailure, RenderOptions, RenderResult, RenderSession, Renderer};
use crate::error::{Error, Result};
use crate::exec::oneshot::{self, OneShotJob};
use crate::exec::pool::{WorkerJob, WorkerPool};
use crate::exec::process::CommandSpec;
use crate::exec::{self, ExecConfig};
use crate::scene::{ParamSpace, Scene};
use std::path::Path;
use std::time::Duration;
use tempfile::TempDir;
use tokio::runtime::Runtime;

/// A renderer whose renders run in other processes. Each render reads its
/// scene whole, so starting a session needs only how many renders run at
/// once: the base scene and what varies are the in-process tracer's
/// concern. Every such backend is a [`Renderer`] through this.
pub trait Process: Send + Sync {
    /// The name given on the command line.
    fn name(&self) -> String;

    /// Renders at once by default; None: the number of cores.
    fn default_jobs(&self) -> Option<usize> {
        None
    }

    /// Starts the processes (or prepares to) for up to `jobs` renders at once.
    fn start(&self, jobs: usize) -> Result<Box<dyn RenderSession>>;
}

impl<P: Process> Renderer for P {
    fn name(&self) -> String {
        Process::name(self)
    }

    fn default_jobs(&self) -> usize {
        Process::default_jobs(self)
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
    }

    fn session(&self, _: &Scene, _: &ParamSpace, jobs: usize) -> Result<Box<dyn RenderSession>> {
        self.start(jobs)
    }
}

/// A pool's start-up result as a session: the start-up failure's error
/// (its stderr already in the message).
pub fn started<S: RenderSession + 'static>(
    r: std::result::Result<S, (Error, RenderFailure)>,
) -> Result<Box<dyn RenderSession>> {
    match r {
        Ok(s) => Ok(Box::new(s)),
        Err((e, _)) => Err(e),
    }
}

/// A one-shot renderer: how one render is set up. The session writes the
/// scene file and names the files, the same way for every backend.
pub trait OneShotBackend: Send {
    /// The scene file's extension, e.g. `pov`.
    fn extension(&self) -> &'static str;

    /// The scene file's text for `scene`; an Err fails that render (the
    /// scene cannot be expressed).
    fn scene_text(&self, scene: &Scene) -> std::result::Result<String, String>;

    /// The command that renders `files.scene` into `files.image`.
    fn command(&self, files: &Files, scene: &Scene, seed: u64) -> CommandSpec;
}

/// One render's files: names inside the run's directory `dir`.
pub struct Files<'a> {
    pub dir: &'a Path,
    pub scene: String,
    pub image: String,
}

impl Files<'_> {
    /// Writes render `id`'s scene file for `backend` into `dir`.
    fn write<'a>(
        dir: &'a Path,
        id: u64,
        backend: &dyn OneShotBackend,
        scene: &Scene,
    ) -> std::result::Result<Files<'a>, String> {
        let text = backend.scene_text(scene)?;
        let files = Files {
            dir,
            scene: format!("r{id}.{}", backend.extension()),
            image: format!("r{id}.png"),
        };
        let path = dir.join(&files.scene);
        std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        Ok(files)
    }
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
                    match Files::write(&dir, *id, backend.as_ref(), scene) {
                        Ok(files) => {
                            jobs.push(OneShotJob {
                                command: backend.command(&files, scene, seed),
                                output: dir.join(&files.image),
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
                cleanup_inputs(&dir, &ids, backend.extension());
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
fn cleanup_inputs(dir: &Path, ids: &[u64], scene_extension: &str) {
    for id in ids {
        for ext in [scene_extension, "png"] {
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
