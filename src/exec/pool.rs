//! A pool of persistent workers, each serving one request at a time: one
//! worker is started with the pool (to fail early), the others when their
//! slot is first used (never more than there are renders in flight) or
//! their predecessor died; each is replaced after `max_renders` renders. A
//! request in flight when a worker dies or hangs counts as a failure and is
//! retried once on a fresh worker. Also the queue both pools share: N
//! runners taking jobs in turn, all stopped by `super::cancel`.

use super::cancel;
use super::output;
use super::process::CommandSpec;
use super::worker::{RequestError, Worker, Written};
use super::ExecConfig;
use super::{RenderFailure, RenderResult};
use std::collections::VecDeque;
use std::future::Future;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use tokio::runtime::Runtime;
use tokio::task::JoinSet;

/// Runs `jobs` on as many runners as there are `states`; each runner takes
/// the next job when it is done with the last. Returns the states and the
/// results in job order. A runner that panics loses its state and its job
/// (reported as a failure). On cancellation the renders in flight are
/// dropped (which kills their processes) with their states, and every job
/// not done fails at once.
pub async fn run_queue<S, J, F, Fut>(
    states: Vec<S>,
    jobs: Vec<J>,
    f: F,
) -> (Vec<S>, Vec<RenderResult>)
where
    S: Send + 'static,
    J: Send + 'static,
    F: Fn(S, J) -> Fut + Clone + Send + Sync + 'static,
    Fut: Future<Output = (S, RenderResult)> + Send + 'static,
{
    let n = jobs.len();
    let queue = Arc::new(Mutex::new(
        jobs.into_iter().enumerate().collect::<VecDeque<_>>(),
    ));
    let mut set = JoinSet::new();
    for state in states {
        let queue = queue.clone();
        let f = f.clone();
        set.spawn(async move {
            let mut state = state;
            let mut done = Vec::new();
            loop {
                if cancel::is_cancelled() {
                    return (None, done);
                }
                let next = queue.lock().unwrap_or_else(|p| p.into_inner()).pop_front();
                let Some((i, job)) = next else { break };
                tokio::select! {
                    (s, r) = f(state, job) => {
                        state = s;
                        done.push((i, r));
                    }
                    () = cancel::cancelled() => return (None, done),
                }
            }
            (Some(state), done)
        });
    }
    let mut states = Vec::new();
    let mut results: Vec<Option<RenderResult>> = (0..n).map(|_| None).collect();
    while let Some(joined) = set.join_next().await {
        if let Ok((state, done)) = joined {
            states.extend(state);
            for (i, r) in done {
                results[i] = Some(r);
            }
        }
    }
    let results = results
        .into_iter()
        .map(|r| {
            r.unwrap_or_else(|| {
                Err(RenderFailure::new(if cancel::is_cancelled() {
                    cancel::MESSAGE
                } else {
                    "internal error: the render task failed"
                }))
            })
        })
        .collect();
    (states, results)
}

/// One failure from the attempts at a render: the last, and what the
/// earlier ones said.
pub fn combine(mut failures: Vec<RenderFailure>) -> RenderFailure {
    let Some(mut last) = failures.pop() else {
        return RenderFailure {
            message: "no attempt was made".into(),
            stderr: String::new(),
        };
    };
    let attempts = failures.len() + 1;
    if attempts > 1 {
        let other: Vec<&str> = failures
            .iter()
            .map(|f| f.message.as_str())
            .filter(|m| *m != last.message)
            .collect();
        last.message = if other.is_empty() {
            format!("{} ({attempts} attempts, each the same)", last.message)
        } else {
            format!(
                "{} ({attempts} attempts; before: {})",
                last.message,
                other.join("; ")
            )
        };
    }
    last
}

/// One render for a persistent worker.
#[derive(Clone, Debug)]
pub struct WorkerJob {
    /// The request line, carrying `"id": id`.
    pub line: String,
    pub id: u64,
    pub output: PathBuf,
    pub width: u32,
    pub height: u32,
}

/// A slot of the pool: at most one worker.
#[derive(Default)]
struct Slot {
    worker: Option<Worker>,
}

/// What the slots share.
struct Shared {
    spec: CommandSpec,
    cfg: ExecConfig,
}

/// N persistent workers.
pub struct WorkerPool {
    shared: Arc<Shared>,
    slots: Vec<Slot>,
    /// The first ready line's "renderer".
    pub renderer: String,
}

impl WorkerPool {
    /// A pool of `cfg.jobs` slots with one worker started (the others start
    /// when used); fails when that one does not start.
    pub fn start(
        rt: &Runtime,
        spec: CommandSpec,
        cfg: ExecConfig,
    ) -> Result<WorkerPool, RenderFailure> {
        let n = cfg.jobs.max(1);
        let shared = Arc::new(Shared { spec, cfg });
        // on a cluster a task can die as it starts (preempted, cancelled,
        // its node lost): that costs a retry, not the run
        let tries = if shared.cfg.launcher.is_slurm() {
            1 + shared.cfg.retries
        } else {
            1
        };
        let first = rt.block_on(async {
            let mut failures = Vec::new();
            for _ in 0..tries {
                let started = tokio::select! {
                    r = Worker::start(&shared.spec, &shared.cfg.launcher, shared.cfg.startup_timeout) => r,
                    () = cancel::cancelled() => return Err(RenderFailure::new(cancel::MESSAGE)),
                };
                match started {
                    Ok(w) => return Ok(w),
                    // Slurm refused the request itself (bad partition,
                    // account, limits): asking again gives the same
                    Err(f) if f.stderr.contains("Unable to allocate resources") => {
                        failures.push(f);
                        break;
                    }
                    Err(f) => failures.push(f),
                }
            }
            Err(combine(failures))
        })?;
        let renderer = first.renderer.clone();
        let mut slots = vec![Slot {
            worker: Some(first),
        }];
        slots.resize_with(n, Slot::default);
        Ok(WorkerPool {
            shared,
            slots,
            renderer,
        })
    }

    /// Renders every job on the pool's workers; results in job order.
    /// Only as many slots run as there are jobs, those with a worker first,
    /// so that a small batch starts no idle workers.
    pub fn run_batch(&mut self, rt: &Runtime, jobs: Vec<WorkerJob>) -> Vec<RenderResult> {
        let n = self.slots.len();
        let mut slots = std::mem::take(&mut self.slots);
        slots.sort_by_key(|s| s.worker.is_none());
        let idle = slots.split_off(jobs.len().clamp(1, n));
        let shared = self.shared.clone();
        let (mut slots, results) = rt.block_on(run_queue(
            slots,
            jobs,
            move |mut slot: Slot, job: WorkerJob| {
                let shared = shared.clone();
                async move {
                    let r = slot.render(&job, &shared).await;
                    (slot, r)
                }
            },
        ));
        slots.extend(idle);
        slots.resize_with(n, Slot::default);
        self.slots = slots;
        results
    }

    /// Kills every worker.
    pub fn shutdown(&mut self, rt: &Runtime) {
        let workers: Vec<Worker> = self
            .slots
            .iter_mut()
            .filter_map(|s| s.worker.take())
            .collect();
        rt.block_on(async {
            for w in workers {
                w.stop().await;
            }
        });
    }
}

impl Slot {
    async fn render(&mut self, job: &WorkerJob, shared: &Shared) -> RenderResult {
        let cfg = &shared.cfg;
        let mut failures = Vec::new();
        for _ in 0..=cfg.retries {
            if self
                .worker
                .as_ref()
                .is_some_and(|w| w.renders >= cfg.max_renders)
            {
                // a fresh process bounds whatever the renderer leaks
                if let Some(w) = self.worker.take() {
                    w.stop().await;
                }
            }
            if self.worker.is_none() {
                match Worker::start(&shared.spec, &cfg.launcher, cfg.startup_timeout).await {
                    Ok(w) => self.worker = Some(w),
                    Err(f) => {
                        failures.push(f);
                        continue;
                    }
                }
            }
            let Some(w) = self.worker.as_mut() else {
                continue;
            };
            output::remove(&job.output);
            match w.request(&job.line, job.id, cfg.render_timeout).await {
                Ok(written) => {
                    let img = match written {
                        Written::Image => output::read(&job.output, job.width, job.height),
                        Written::Raw => output::read_raw(&job.output, job.width, job.height),
                    };
                    output::remove(&job.output);
                    match img {
                        Ok(img) => return Ok(img),
                        Err(m) => failures.push(RenderFailure {
                            message: format!("the worker answered ok but {m}"),
                            stderr: w.output().await,
                        }),
                    }
                }
                Err(RequestError::Answered(m)) => {
                    output::remove(&job.output);
                    failures.push(RenderFailure {
                        message: format!("the worker failed: {m}"),
                        stderr: w.output().await,
                    });
                }
                Err(RequestError::Dead(m)) => {
                    let stderr = match self.worker.take() {
                        Some(w) => w.stop().await,
                        None => String::new(),
                    };
                    output::remove(&job.output);
                    failures.push(RenderFailure { message: m, stderr });
                }
            }
        }
        Err(combine(failures))
    }
}
