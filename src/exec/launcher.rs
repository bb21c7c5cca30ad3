//! The executor: where renderer processes run. The backends build their
//! commands as always; `Launcher::launch` turns each into what is really
//! started: the command itself (`local`), or the command as a Slurm task
//! (`slurm`, see `super::slurm`). Nothing above the exec layer knows which.

use super::process::CommandSpec;
use super::slurm::{Slurm, Task};
use crate::error::Result;
use std::path::PathBuf;
use std::sync::Arc;

/// Where renderer processes run, as the user chose.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Executor {
    /// Child processes of scenefit.
    #[default]
    Local,
    /// Slurm tasks started with srun; the words are passed to srun as given.
    Slurm { args: Vec<String> },
}

impl Executor {
    /// The executor named `name` (`local` or `slurm`) with srun's options.
    pub fn from_name(name: &str, slurm_args: Vec<String>) -> Option<Executor> {
        match name {
            "local" => Some(Executor::Local),
            "slurm" => Some(Executor::Slurm { args: slurm_args }),
            _ => None,
        }
    }
}

/// A session's executor, shared by its workers and renders.
#[derive(Clone, Debug, Default)]
pub struct Launcher {
    slurm: Option<Arc<Slurm>>,
}

/// A process as started: what to spawn, and its Slurm task if it is one.
pub struct Launched {
    pub spec: CommandSpec,
    pub task: Option<Task>,
}

impl Launcher {
    /// The launcher for `executor`; `ledger` is the run directory's record
    /// of its Slurm jobs (None: not recorded).
    pub fn new(executor: &Executor, ledger: Option<PathBuf>) -> Result<Launcher> {
        Ok(Launcher {
            slurm: match executor {
                Executor::Local => None,
                Executor::Slurm { args } => Some(Arc::new(Slurm::new(args.clone(), ledger)?)),
            },
        })
    }

    /// Whether processes run as Slurm tasks.
    pub fn is_slurm(&self) -> bool {
        self.slurm.is_some()
    }

    /// What to start for `spec`.
    pub fn launch(&self, spec: &CommandSpec) -> Launched {
        match &self.slurm {
            None => Launched {
                spec: spec.clone(),
                task: None,
            },
            Some(s) => {
                let (spec, task) = s.wrap(spec);
                Launched {
                    spec,
                    task: Some(task),
                }
            }
        }
    }

    /// Where Slurm tasks write their stderr: the session's directory.
    pub fn use_dir(&self, dir: &std::path::Path) {
        if let Some(s) = &self.slurm {
            s.use_dir(dir);
        }
    }

    /// Cancels a task whose local srun was killed (its remote side may
    /// still run, or its job still be queued).
    pub fn cancel(&self, task: Option<&Task>) {
        if let (Some(s), Some(t)) = (&self.slurm, task) {
            s.cancel_task(t);
        }
    }
}
