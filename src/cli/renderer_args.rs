//! The options of the process-backed renderers, shared by every command
//! that renders (render, fit, pipeline, diagnose). Each overrides its
//! environment variable, which overrides the backend's default. Also where
//! the renderer processes run (`--executor`, `--workers`, `--slurm-args`).

use crate::error::Result;
use crate::exec::slurm;
use crate::exec::Executor;
use crate::render::RenderOptions;
use clap::{Args, ValueEnum};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Where the renderer processes run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
enum ExecutorName {
    /// Child processes of scenefit.
    #[default]
    Local,
    /// Slurm tasks, each started with srun (a job step inside an
    /// allocation, a job of its own outside one).
    Slurm,
}

#[derive(Args, Debug, Clone, Default)]
pub struct RendererArgs {
    /// Seconds one render may take before its process is killed (default:
    /// the backend's; env SCENEFIT_RENDER_TIMEOUT).
    #[arg(long, value_name = "SECONDS", value_parser = seconds, allow_hyphen_values = true)]
    render_timeout: Option<Duration>,
    /// Renders a persistent worker serves before it is restarted (default
    /// 200; env SCENEFIT_WORKER_MAX_RENDERS).
    #[arg(long, value_name = "N", value_parser = at_least_one, allow_hyphen_values = true)]
    worker_max_renders: Option<usize>,
    /// The Python that runs the Mitsuba worker (default python3; env
    /// SCENEFIT_PYTHON).
    #[arg(long, value_name = "PATH")]
    python: Option<PathBuf>,
    /// Where the renderer processes run: here, or as Slurm tasks through
    /// srun.
    #[arg(long, value_enum, default_value_t = ExecutorName::Local)]
    executor: ExecutorName,
    /// Renderer workers (or one-shot processes) at once (default: as many
    /// as --jobs renders at once; at most 65536).
    #[arg(long, value_name = "N", value_parser = super::numbers::workers, allow_hyphen_values = true)]
    workers: Option<usize>,
    /// Options passed to srun as given, e.g. "--partition=gpu
    /// --time=02:00:00 --gpus-per-task=1" (with --executor slurm).
    #[arg(long, value_name = "ARGS", value_parser = slurm_args, allow_hyphen_values = true)]
    slurm_args: Option<SlurmArgs>,
}

/// The words of `--slurm-args` (a type of its own: clap would take a
/// `Vec` for a list of values).
#[derive(Clone, Debug, Default)]
struct SlurmArgs(Vec<String>);

impl RendererArgs {
    /// The library's form of these options, the environment filling what
    /// the flags left unset (`env.rs`).
    pub fn options(&self) -> Result<RenderOptions> {
        super::env::render_options(RenderOptions {
            render_timeout: self.render_timeout,
            worker_max_renders: self.worker_max_renders,
            python: self.python.clone(),
            workers: self.workers,
            executor: match self.executor {
                ExecutorName::Local => Executor::Local,
                ExecutorName::Slurm => Executor::Slurm {
                    args: self.slurm_args.clone().unwrap_or_default().0,
                },
            },
            slurm_ledger: None,
        })
    }

    /// `options()` for a run into `run_dir`: its Slurm jobs are recorded
    /// there, and what a killed run there left on Slurm is cancelled now.
    pub fn options_in(&self, run_dir: &Path) -> Result<RenderOptions> {
        let options = self.options()?;
        let ledger = run_dir.join(crate::rundir::SLURM_JOBS);
        slurm::clean_ledger(&ledger);
        Ok(RenderOptions {
            slurm_ledger: Some(ledger),
            ..options
        })
    }
}

fn slurm_args(s: &str) -> std::result::Result<SlurmArgs, String> {
    slurm::split_args(s).map(SlurmArgs)
}

fn seconds(s: &str) -> std::result::Result<Duration, String> {
    crate::exec::parse_seconds(s).ok_or_else(|| "expected a number of seconds > 0, e.g. 120".into())
}

fn at_least_one(s: &str) -> std::result::Result<usize, String> {
    s.trim()
        .parse::<usize>()
        .ok()
        .filter(|n| *n > 0)
        .ok_or_else(|| "expected a whole number >= 1, e.g. 200".into())
}
