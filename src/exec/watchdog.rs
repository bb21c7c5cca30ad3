//! Cleans up after a scenefit that was killed outright (SIGKILL), when no
//! destructor runs: a small process (scenefit re-executed with the hidden
//! first argument `WATCHDOG_ARG`) holds a pipe from scenefit, on which
//! scenefit records the process group of every renderer it starts (and
//! forgets it when it is killed), every run directory, and the task-name
//! prefix of every Slurm session. When the pipe closes, however scenefit
//! ended, the watchdog kills the groups still recorded, cancels the Slurm
//! tasks still running under the prefixes, and removes the directories,
//! then exits.
//!
//! It is off unless `enable()` is called (the command line does), so that
//! programs using the library are not re-executed, and it starts only
//! when the first renderer process or run directory does.

use std::collections::BTreeSet;
use std::io::{BufRead, Write};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{ChildStdin, Command, Stdio};
use std::sync::Mutex;

/// The first argument that makes scenefit run as the watchdog.
pub const WATCHDOG_ARG: &str = "__exec-watchdog";

/// The pipe to the watchdog, started on first use once enabled.
enum State {
    Off,
    Enabled,
    Running(ChildStdin),
    /// It could not start or went away: nothing more to tell it.
    Gone,
}

static STATE: Mutex<State> = Mutex::new(State::Off);

/// Lets the exec layer start the watchdog when it first starts a renderer
/// or makes a run directory. Without it, renderers still die with their
/// sessions and with the thread that started them (PR_SET_PDEATHSIG), but
/// a SIGKILLed scenefit may leave their children and its run directories.
pub fn enable() {
    let mut st = STATE.lock().unwrap_or_else(|p| p.into_inner());
    if matches!(*st, State::Off) {
        *st = State::Enabled;
    }
}

fn start() -> Option<ChildStdin> {
    let exe = std::env::current_exe().ok()?;
    let mut child = Command::new(exe)
        .arg(WATCHDOG_ARG)
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        // out of the terminal's process group: Ctrl-C must not end it first
        .process_group(0)
        .spawn()
        .ok()?;
    let pipe = child.stdin.take();
    // it exits on its own when the pipe closes; reap it then
    std::thread::spawn(move || {
        let _ = child.wait();
    });
    pipe
}

fn send(line: &str) {
    let mut st = STATE.lock().unwrap_or_else(|p| p.into_inner());
    if matches!(*st, State::Enabled) {
        *st = match start() {
            Some(p) => State::Running(p),
            None => State::Gone,
        };
    }
    if let State::Running(p) = &mut *st {
        if writeln!(p, "{line}").and_then(|_| p.flush()).is_err() {
            *st = State::Gone;
        }
    }
}

/// Records a renderer's process group.
pub fn watch_group(pgid: i32) {
    send(&format!("+g{pgid}"));
}

/// Forgets a process group that was killed.
pub fn forget_group(pgid: i32) {
    send(&format!("-g{pgid}"));
}

/// Records a run directory to remove if scenefit is killed.
pub fn watch_dir(dir: &Path) {
    if let Some(s) = dir.to_str().filter(|s| !s.contains('\n')) {
        send(&format!("+d{s}"));
    }
}

/// Forgets a run directory that was removed.
pub fn forget_dir(dir: &Path) {
    if let Some(s) = dir.to_str().filter(|s| !s.contains('\n')) {
        send(&format!("-d{s}"));
    }
}

/// Records the task-name prefix of a Slurm session (`super::slurm`).
pub fn watch_slurm(prefix: &str) {
    if !prefix.contains('\n') {
        send(&format!("+s{prefix}"));
    }
}

/// Forgets a Slurm session whose tasks were cancelled.
pub fn forget_slurm(prefix: &str) {
    if !prefix.contains('\n') {
        send(&format!("-s{prefix}"));
    }
}

/// The watchdog's main: reads records from stdin to its end, then cleans up.
pub fn serve() -> i32 {
    // SAFETY: setting signal dispositions to SIG_IGN touches no memory of ours.
    unsafe {
        for s in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
            libc::signal(s, libc::SIG_IGN);
        }
    }
    let mut groups = BTreeSet::new();
    let mut dirs = BTreeSet::new();
    let mut slurm = BTreeSet::new();
    for line in std::io::stdin().lock().lines() {
        let Ok(line) = line else { break };
        let (op, rest) = line.split_at(line.len().min(2));
        match op {
            "+g" => {
                if let Ok(g) = rest.parse::<i32>() {
                    groups.insert(g);
                }
            }
            "-g" => {
                if let Ok(g) = rest.parse::<i32>() {
                    groups.remove(&g);
                }
            }
            "+s" => {
                slurm.insert(rest.to_string());
            }
            "-s" => {
                slurm.remove(rest);
            }
            "+d" => {
                dirs.insert(PathBuf::from(rest));
            }
            "-d" => {
                dirs.remove(Path::new(rest));
            }
            _ => {}
        }
    }
    for g in groups {
        if g > 1 {
            // SAFETY: kill(2) on a process group; no memory is involved.
            unsafe {
                libc::kill(-g, libc::SIGKILL);
            }
        }
    }
    // the srun clients are dead now; their remote tasks may not be
    let prefixes: Vec<String> = slurm.into_iter().collect();
    super::slurm_cancel::cancel_prefixes(&prefixes);
    for d in dirs {
        let _ = std::fs::remove_dir_all(d);
    }
    0
}
