//! Renderer processes as Slurm tasks: each process the exec layer starts
//! becomes `srun --job-name=NAME --ntasks=1 --cpus-per-task=1 --unbuffered
//! [the user's --slurm-args] /bin/sh -c 'exec "$@" 2>FILE' - PROGRAM ARGS`,
//! its stdin and stdout passed through by srun (so the JSON-lines protocol
//! is unchanged; its stderr goes to a file of the session, see `wrap`). Inside an
//! allocation (`SLURM_JOB_ID` set, under salloc or sbatch) srun makes each a
//! job step of it; outside one each is a job of its own.
//!
//! Every task of a session is named `<prefix><n>` with one prefix per
//! session, `scenefit-<pid>-<time>-`. The prefix is what is cancelled: the
//! session's end cancels whatever still runs under it (killing the local
//! srun client alone leaves the remote task running for a few seconds, or
//! a pending job queued); the watchdog does the same if scenefit is killed
//! outright; and the prefix is recorded in the run directory's
//! `rundir::SLURM_JOBS` so that the next run there (a resume, an
//! overwrite) cancels what a killed run left and says which job ids those
//! were.

use super::discover;
use super::process::CommandSpec;
pub use super::slurm_cancel::{cancel_prefixes, find};
use crate::error::Result;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

/// The start of every task name scenefit gives.
pub const NAME_PREFIX: &str = "scenefit-";

/// Sessions started by this process, for unique prefixes.
static SESSIONS: AtomicU64 = AtomicU64::new(0);

/// The Slurm side of one session.
#[derive(Debug)]
pub struct Slurm {
    srun: PathBuf,
    /// The user's srun options (`--slurm-args`), after ours.
    args: Vec<String>,
    /// This session's task-name prefix.
    prefix: String,
    next: AtomicU64,
    /// Where the prefix is recorded, once the first task starts.
    ledger: Option<PathBuf>,
    recorded: Mutex<bool>,
    /// The session's directory, where the tasks' stderr files go.
    dir: Mutex<Option<PathBuf>>,
}

/// One task started through srun, named so that it can be cancelled.
#[derive(Debug, Clone)]
pub struct Task {
    pub name: String,
    /// Where the task's stderr goes (in the session's directory).
    pub stderr: Option<PathBuf>,
}

impl Task {
    /// The end of what the task printed on stderr, for messages.
    pub fn stderr_tail(&self) -> String {
        let Some(path) = &self.stderr else {
            return String::new();
        };
        // bounded: only the tail is read, whatever the task wrote
        let Ok(keep) = crate::input::read_tail(path, super::tail::TAIL_BYTES as u64) else {
            return String::new();
        };
        String::from_utf8_lossy(&keep).into_owned()
    }
}

impl Slurm {
    /// A session on Slurm with the user's srun options; `ledger` is the
    /// file of the run directory that records it. Fails (a user error)
    /// when srun is not installed.
    pub fn new(args: Vec<String>, ledger: Option<PathBuf>) -> Result<Slurm> {
        let srun = discover::find(
            "srun",
            "install Slurm's client (`apt-get install slurm-client`) or run where Slurm is, or use --executor local",
        )?;
        let time = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_secs())
            .unwrap_or(0);
        let prefix = format!(
            "{NAME_PREFIX}{}-{time}-{}-",
            std::process::id(),
            SESSIONS.fetch_add(1, Ordering::SeqCst)
        );
        super::watchdog::watch_slurm(&prefix);
        Ok(Slurm {
            srun,
            args,
            prefix,
            next: AtomicU64::new(1),
            ledger,
            recorded: Mutex::new(false),
            dir: Mutex::new(None),
        })
    }

    /// `spec` as a Slurm task: srun runs it, in the same directory, with
    /// the same environment (srun passes ours on).
    pub fn wrap(&self, spec: &CommandSpec) -> (CommandSpec, Task) {
        self.record();
        let name = format!(
            "{}{}",
            self.prefix,
            self.next.fetch_add(1, Ordering::SeqCst)
        );
        let stderr = self
            .dir
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .as_ref()
            .map(|d| d.join(format!("{name}.stderr")));
        let redirect = match &stderr {
            Some(f) => format!("exec \"$@\" 2>{}", shell_words::quote(&f.to_string_lossy())),
            None => "exec \"$@\" 2>/dev/null".to_string(),
        };
        let mut s = CommandSpec::new(&self.srun)
            .arg(format!("--job-name={name}"))
            .args([
                "--ntasks=1",
                "--nodes=1",
                "--cpus-per-task=1",
                "--unbuffered",
            ])
            // the user's options come after ours: srun takes the last
            .args(self.args.iter())
            // The task's stderr goes to a file, not back through srun:
            // output printed during a render (Blender prints at every one)
            // held the answer line back ~40 ms in srun's I/O forwarding
            // (measured: 50 ms a render instead of 12). The file is read
            // back for messages (`Task::stderr_tail`).
            .args(["/bin/sh", "-c", &redirect, "scenefit-task"])
            .arg(&spec.program)
            .args(spec.args.iter());
        s.cwd = spec.cwd.clone();
        s.env = spec.env.clone();
        (s, Task { name, stderr })
    }

    /// Puts the tasks' stderr files into `dir` (the session's directory,
    /// which the tasks must see: a shared file system on a cluster).
    pub fn use_dir(&self, dir: &Path) {
        *self.dir.lock().unwrap_or_else(|p| p.into_inner()) = Some(dir.to_path_buf());
    }

    /// Writes the prefix into the run directory's ledger (once).
    fn record(&self) {
        let mut done = self.recorded.lock().unwrap_or_else(|p| p.into_inner());
        if *done {
            return;
        }
        *done = true;
        let Some(path) = &self.ledger else { return };
        let written = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .and_then(|mut f| {
                writeln!(f, "{}", self.prefix)?;
                f.sync_all()
            });
        if let Err(e) = written {
            eprintln!(
                "scenefit: cannot record the Slurm jobs in {}: {e}",
                path.display()
            );
        }
    }

    /// Cancels one task that was killed here (a worker replaced, a render
    /// timed out), without waiting for scancel.
    pub fn cancel_task(&self, task: &Task) {
        let _ = Command::new("scancel")
            .args(["--quiet", &format!("--name={}", task.name)])
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .map(|mut c| std::thread::spawn(move || c.wait()));
    }
}

impl Drop for Slurm {
    fn drop(&mut self) {
        // the srun clients are gone by now; their remote tasks may not be
        // (ending them is the normal end of a session: nothing to say)
        cancel_prefixes(std::slice::from_ref(&self.prefix));
        if let Some(path) = &self.ledger {
            forget(path, &self.prefix);
        }
        super::watchdog::forget_slurm(&self.prefix);
    }
}

/// Removes `prefix` from the ledger; removes the ledger when it is empty.
fn forget(path: &Path, prefix: &str) {
    let Ok(text) = crate::input::read_text_capped(path, crate::input::MAX_TEXT_BYTES) else {
        return;
    };
    let rest: Vec<&str> = text
        .lines()
        .filter(|l| !l.trim().is_empty() && l.trim() != prefix)
        .collect();
    let _ = if rest.is_empty() {
        std::fs::remove_file(path).is_ok()
    } else {
        crate::fsio::write_atomic(path, format!("{}\n", rest.join("\n")).as_bytes()).is_ok()
    };
}

/// Whether the scenefit that used `prefix` (`scenefit-<pid>-...`) still
/// runs on this host: its tasks are then its own business.
fn alive(prefix: &str) -> bool {
    let pid = prefix
        .strip_prefix(NAME_PREFIX)
        .and_then(|r| r.split('-').next())
        .and_then(|p| p.parse::<i32>().ok())
        .filter(|p| *p > 1);
    match pid {
        Some(p) if p as u32 == std::process::id() => true,
        // SAFETY: kill(2) with signal 0 only checks that the process exists.
        Some(p) => unsafe { libc::kill(p, 0) == 0 },
        None => false,
    }
}

/// Cancels what an earlier, killed run left on Slurm, as recorded in the
/// run directory's ledger `path`, and says which job ids those were. The
/// ledger is then removed (the prefixes of a run still alive are kept).
pub fn clean_ledger(path: &Path) {
    // bounded: the ledger is read on every run, whatever stands in its place
    let text = match crate::input::read_text_capped(path, crate::input::MAX_TEXT_BYTES) {
        Ok(t) => t,
        // No ledger, or no directory to hold one (the run itself refuses
        // an output that is not a directory, in its own words).
        Err(crate::error::Error::Io { source, .. })
            if matches!(
                source.kind(),
                std::io::ErrorKind::NotFound | std::io::ErrorKind::NotADirectory
            ) =>
        {
            return
        }
        Err(e) => {
            eprintln!("scenefit: warning: {e}; no Slurm jobs of an earlier run are cancelled");
            return;
        }
    };
    if which::which("squeue").is_err() {
        // kept for a run where Slurm can be asked
        eprintln!(
            "scenefit: {} lists Slurm jobs of an earlier run, but squeue is not here to cancel them",
            path.display()
        );
        return;
    }
    let mut prefixes = Vec::new();
    for (n, line) in text.lines().enumerate() {
        match session_prefix(line) {
            Some(p) => prefixes.push(p.to_string()),
            None if line.trim().is_empty() => {}
            // never a wider name: "scenefit-" alone would cancel every
            // scenefit task of the user
            None => eprintln!(
                "scenefit: {}: line {}: ignored; expected a session's task-name prefix {NAME_PREFIX}PID-TIME-N-",
                path.display(),
                n + 1
            ),
        }
    }
    let (live, dead): (Vec<String>, Vec<String>) = prefixes.into_iter().partition(|p| alive(p));
    let ids = cancel_prefixes(&dead);
    if !ids.is_empty() {
        eprintln!(
            "scenefit: cancelled Slurm job(s) left by an earlier run in this directory: {}",
            ids.join(", ")
        );
    }
    let _ = if live.is_empty() {
        std::fs::remove_file(path).is_ok()
    } else {
        crate::fsio::write_atomic(path, format!("{}\n", live.join("\n")).as_bytes()).is_ok()
    };
}

/// The line of a ledger as a session's prefix, exactly as `Slurm::new`
/// writes it (`scenefit-<pid>-<time>-<n>-`); None for anything else.
fn session_prefix(line: &str) -> Option<&str> {
    let p = line.trim();
    let numbers = p.strip_prefix(NAME_PREFIX)?.strip_suffix('-')?;
    let parts: Vec<&str> = numbers.split('-').collect();
    let digits = |s: &&str| !s.is_empty() && s.len() <= 20 && s.bytes().all(|b| b.is_ascii_digit());
    (parts.len() == 3 && parts.iter().all(digits)).then_some(p)
}

/// The words of `--slurm-args`, split like a shell would.
pub fn split_args(text: &str) -> std::result::Result<Vec<String>, String> {
    shell_words::split(text).map_err(|e| format!("cannot split into words: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wraps_in_srun_keeping_directory_and_environment() {
        let Ok(s) = Slurm::new(vec!["--partition=gpu".into()], None) else {
            return; // no srun here: nothing to wrap with
        };
        let spec = CommandSpec::new("/bin/worker")
            .arg("--threads")
            .arg("1")
            .cwd("/tmp")
            .env("K", "V");
        let (w, task) = s.wrap(&spec);
        let args: Vec<String> = w
            .args
            .iter()
            .map(|a| a.to_string_lossy().into_owned())
            .collect();
        assert!(task.name.starts_with(NAME_PREFIX));
        assert_eq!(args[0], format!("--job-name={}", task.name));
        let user = args.iter().position(|a| a == "--partition=gpu").unwrap();
        let prog = args.iter().position(|a| a == "/bin/worker").unwrap();
        assert!(user < prog, "{args:?}");
        assert_eq!(args[prog - 3], "-c");
        assert!(args[prog - 2].ends_with("2>/dev/null"), "{args:?}");
        s.use_dir(Path::new("/shared/run"));
        let (w, task) = s.wrap(&spec);
        let script = w.args[w.args.len() - 5].to_string_lossy().into_owned();
        let file = format!("/shared/run/{}.stderr", task.name);
        assert!(script.ends_with(&format!("2>{file}")), "{script}");
        assert_eq!(task.stderr.as_deref(), Some(Path::new(&file)));
        assert_eq!(&args[prog + 1..], ["--threads", "1"]);
        assert_eq!(w.cwd.as_deref(), Some(Path::new("/tmp")));
        assert_eq!(w.env, spec.env);
        let (_, second) = s.wrap(&spec);
        assert_ne!(task.name, second.name);
    }

    #[test]
    fn only_a_whole_session_prefix_is_read_from_a_ledger() {
        assert_eq!(
            session_prefix(" scenefit-12-1700000000-0- "),
            Some("scenefit-12-1700000000-0-")
        );
        for bad in [
            "scenefit-",
            "scenefit-12-",
            "scenefit-12-1700000000-",
            "scenefit-12-1700000000-0",
            "scenefit-12-1700000000-0-5",
            "scenefit-a-1-2-",
            "scenefit-1--2-",
            "other-1-2-3-",
            "",
        ] {
            assert_eq!(session_prefix(bad), None, "{bad:?}");
        }
    }

    #[test]
    fn a_dead_runs_prefix_is_not_alive() {
        assert!(alive(&format!("{NAME_PREFIX}{}-1-0-", std::process::id())));
        assert!(!alive(&format!("{NAME_PREFIX}999999999-1-0-")));
        assert!(!alive("scenefit-x-"));
    }

    #[test]
    fn slurm_args_are_split_like_a_shell() {
        assert_eq!(
            split_args("-p gpu --constraint='a100|h100'").unwrap(),
            ["-p", "gpu", "--constraint=a100|h100"]
        );
        assert!(split_args("'open").is_err());
    }
}
