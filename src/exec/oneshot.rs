//! One process per render (POV-Ray, `cmd:TEMPLATE` plug-ins): up to `jobs`
//! at once, each with a timeout, its output checked, a failure retried once.

use super::launcher::Launcher;
use super::process::CommandSpec;
use super::tail::{drain, Tail};
use super::{output, pool, ExecConfig};
use super::{RenderFailure, RenderResult};
use std::path::PathBuf;
use std::time::Duration;
use tokio::runtime::Runtime;

/// One render: the command that makes it and the image it must write.
#[derive(Clone, Debug)]
pub struct OneShotJob {
    pub command: CommandSpec,
    pub output: PathBuf,
    pub width: u32,
    pub height: u32,
}

/// How long to wait for a finished process's pipes to close: longer only
/// when something it started still holds them.
const PIPE_GRACE: Duration = Duration::from_millis(500);

/// Runs `spec` to its end, where `launcher` runs processes; Ok when it
/// exits with status 0. The error keeps what it printed.
pub async fn run_process(
    spec: &CommandSpec,
    launcher: &Launcher,
    timeout: Duration,
) -> Result<String, RenderFailure> {
    let launched = launcher.launch(spec);
    let spec = &launched.spec;
    // `group` kills whatever the process left running when this returns
    let (mut child, group) = spec.spawn(false).map_err(|e| RenderFailure {
        message: format!("cannot start {}: {e}", spec.display()),
        stderr: String::new(),
    })?;
    let started = super::stats::begin();
    let tail = Tail::new();
    let mut drains: Vec<_> = [
        drain(child.stdout.take(), tail.clone()),
        drain(child.stderr.take(), tail.clone()),
    ]
    .into_iter()
    .flatten()
    .collect();
    let status = tokio::time::timeout(timeout, child.wait()).await;
    super::stats::end(started);
    // a finished process closes its pipes; if they stay open, something it
    // started still runs
    let mut lingering = false;
    if status.is_ok() {
        let mut open = Vec::new();
        for mut d in drains {
            if tokio::time::timeout(PIPE_GRACE, &mut d).await.is_err() {
                open.push(d);
            }
        }
        lingering = !open.is_empty();
        drains = open;
    }
    if status.is_err() || lingering {
        group.kill();
        launcher.cancel(launched.task.as_ref());
        let _ = child.start_kill();
        let _ = tokio::time::timeout(Duration::from_secs(5), child.wait()).await;
        // collect what it printed last
        for mut d in drains {
            let _ = tokio::time::timeout(PIPE_GRACE, &mut d).await;
        }
    }
    let mut text = tail.text();
    if let Some(t) = &launched.task {
        // a Slurm task's stderr is in its file
        text.push_str(&t.stderr_tail());
        if let Some(f) = &t.stderr {
            let _ = std::fs::remove_file(f);
        }
    }
    match status {
        Err(_) => Err(RenderFailure {
            message: format!("timed out after {} s and was killed", timeout.as_secs_f64()),
            stderr: text,
        }),
        Ok(Err(e)) => Err(RenderFailure {
            message: format!("lost track of the process: {e}"),
            stderr: text,
        }),
        Ok(Ok(s)) if s.success() => Ok(text),
        Ok(Ok(s)) => Err(RenderFailure {
            message: describe_exit(s),
            stderr: text,
        }),
    }
}

fn describe_exit(s: std::process::ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt;
    match (s.code(), s.signal()) {
        (Some(c), _) => format!("exited with status {c}"),
        (None, Some(sig)) => format!("was killed by signal {sig}"),
        _ => format!("ended with {s}"),
    }
}

/// One render with its retries: the process must exit 0 and leave an
/// image of the right size.
pub async fn render(job: &OneShotJob, cfg: &ExecConfig) -> RenderResult {
    let mut failures = Vec::new();
    for _ in 0..=cfg.retries {
        output::remove(&job.output);
        let result = match run_process(&job.command, &cfg.launcher, cfg.render_timeout).await {
            Ok(text) => {
                output::read(&job.output, job.width, job.height).map_err(|m| RenderFailure {
                    message: format!("exited 0 but {m}"),
                    stderr: text,
                })
            }
            Err(f) => Err(f),
        };
        output::remove(&job.output);
        match result {
            Ok(img) => return Ok(img),
            Err(f) => failures.push(f),
        }
    }
    Err(pool::combine(failures))
}

/// Renders every job, up to `cfg.jobs` processes at once; results in job
/// order. Cancellation (`super::cancel`) kills the processes in flight.
pub fn run_batch(rt: &Runtime, cfg: &ExecConfig, jobs: Vec<OneShotJob>) -> Vec<RenderResult> {
    let runners = vec![(); cfg.jobs.min(jobs.len()).max(1)];
    let cfg = cfg.clone();
    let (_, results) = rt.block_on(pool::run_queue(
        runners,
        jobs,
        move |(), job: OneShotJob| {
            let cfg = cfg.clone();
            async move { ((), render(&job, &cfg).await) }
        },
    ));
    results
}
