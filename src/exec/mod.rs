//! Where renderer processes run: a pool on tokio, of local processes or of
//! Slurm tasks (`launcher`, `slurm`). One-shot renderers
//! get one process per render (`oneshot`), persistent workers answer
//! JSON-lines requests (`worker`, `pool`); both with a concurrency limit, a
//! per-render timeout, one retry, stderr drained and kept (`tail`), and
//! every process killed when its run ends (`process`, and `watchdog` when
//! scenefit itself is killed), every wait cut short by `cancel`. `discover`
//! finds the programs, `output` checks the image a renderer wrote, `result`
//! is what a render gives back.
//!
//! The render sessions are synchronous (`RenderSession::render_batch`); each
//! owns a small tokio runtime (`runtime`) and blocks on it per batch, so the
//! rest of scenefit never sees async code.

pub mod cancel;
pub mod discover;
pub mod launcher;
pub mod oneshot;
pub mod output;
pub mod pool;
pub mod process;
pub mod result;
pub mod slurm;
pub mod slurm_cancel;
pub mod stats;
pub mod tail;
pub mod watchdog;
pub mod worker;

use crate::error::{Error, Result};
pub use launcher::{Executor, Launcher};
pub use result::{RenderFailure, RenderResult};
use std::path::PathBuf;
use std::time::Duration;

/// How renderer processes are run.
#[derive(Clone, Debug)]
pub struct ExecConfig {
    /// Processes (one-shot) or workers (persistent) at once.
    pub jobs: usize,
    /// One render may take this long; then its process is killed.
    pub render_timeout: Duration,
    /// A persistent worker must print its ready line within this.
    pub startup_timeout: Duration,
    /// A persistent worker is restarted after this many renders (bounds
    /// leaks in long-running renderers).
    pub max_renders: usize,
    /// A failed render is tried again this many times.
    pub retries: usize,
    /// Where the processes run (here, or as Slurm tasks).
    pub launcher: Launcher,
}

/// How renderer processes run, as the caller chose (the command line's
/// flags over its environment variables, both read in `cli::env`, the only
/// place that reads the environment); each None leaves the choice to the
/// backend's default.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderOptions {
    /// One render may take this long; then its process is killed.
    pub render_timeout: Option<Duration>,
    /// A persistent worker is restarted after this many renders.
    pub worker_max_renders: Option<usize>,
    /// The Python that runs a Python worker (Mitsuba's).
    pub python: Option<PathBuf>,
    /// Renderer processes or workers at once, over the session's number.
    pub workers: Option<usize>,
    /// Where renderer processes run (local, or Slurm tasks).
    pub executor: Executor,
    /// The run directory's record of its Slurm jobs (`rundir::SLURM_JOBS`).
    pub slurm_ledger: Option<PathBuf>,
}

impl ExecConfig {
    /// The backend's defaults, overridden by the caller's options.
    pub fn new(
        jobs: usize,
        render_timeout: Duration,
        startup_timeout: Duration,
        over: &RenderOptions,
    ) -> Result<ExecConfig> {
        if over.workers == Some(0) {
            return Err(Error::Usage(
                "workers: expected a whole number of workers >= 1, e.g. 8".into(),
            ));
        }
        let mut c = ExecConfig {
            jobs: over.workers.unwrap_or(jobs).max(1),
            render_timeout,
            startup_timeout,
            max_renders: 200,
            retries: 1,
            launcher: Launcher::default(),
        };
        if let Some(t) = over.render_timeout {
            if t.is_zero() {
                return Err(Error::Usage(
                    "render timeout: expected a number of seconds > 0, e.g. 120".into(),
                ));
            }
            c.render_timeout = t;
        }
        if let Some(n) = over.worker_max_renders {
            if n == 0 {
                return Err(Error::Usage(
                    "worker max renders: expected a whole number of renders >= 1, e.g. 200".into(),
                ));
            }
            c.max_renders = n;
        }
        c.launcher = Launcher::new(&over.executor, over.slurm_ledger.clone())?;
        Ok(c)
    }
}

/// A number of seconds > 0 (and finite), as the environment and the
/// command line give it.
pub fn parse_seconds(s: &str) -> Option<Duration> {
    let v: f64 = s.trim().parse().ok()?;
    (v.is_finite() && v > 0.0 && v < 1e9).then(|| Duration::from_secs_f64(v))
}

/// The runtime a session blocks on: two threads are plenty, the work is
/// waiting on processes (and decoding small PNGs).
pub fn runtime() -> Result<tokio::runtime::Runtime> {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .thread_name("scenefit-exec")
        .enable_all()
        .build()
        .map_err(|e| Error::Run(format!("cannot start the process runtime: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seconds() {
        assert_eq!(parse_seconds("2.5"), Some(Duration::from_millis(2500)));
        assert_eq!(parse_seconds(" 10 "), Some(Duration::from_secs(10)));
        assert_eq!(parse_seconds("0"), None);
        assert_eq!(parse_seconds("-1"), None);
        assert_eq!(parse_seconds("abc"), None);
        assert_eq!(parse_seconds("inf"), None);
    }

    #[test]
    fn overrides_win_and_are_checked() {
        let d = Duration::from_secs(7);
        let over = RenderOptions {
            render_timeout: Some(Duration::from_secs(3)),
            worker_max_renders: Some(5),
            workers: Some(4),
            ..Default::default()
        };
        let c = ExecConfig::new(2, d, d, &over).unwrap();
        assert_eq!(
            (c.render_timeout, c.max_renders, c.jobs),
            (Duration::from_secs(3), 5, 4)
        );
        assert!(!c.launcher.is_slurm());
        let zero = RenderOptions {
            render_timeout: Some(Duration::ZERO),
            ..Default::default()
        };
        let e = ExecConfig::new(2, d, d, &zero).unwrap_err().to_string();
        assert!(e.contains("render timeout") && !e.contains("--"), "{e}");
    }
}
