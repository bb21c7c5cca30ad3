//! Runs one of the Blender scripts of `scenefit import` / `export` once,
//! headless (the backend's persistent worker serves renders; these run one
//! job): the script and the modules it imports (the worker itself, whose
//! scene build the export reuses, and scene_common / jsonlines) written
//! into a private temporary directory, Blender started as the backend
//! starts it plus `--disable-autoexec` (a .blend's own Python never runs),
//! its output kept for the error message, killed after a time limit.

use crate::error::{Error, Result};
use std::ffi::OsString;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The scripts and the modules they import, as shipped.
const FILES: &[(&str, &str)] = &[
    ("worker.py", include_str!("../../blender_scripts/worker.py")),
    (
        "export_blend.py",
        include_str!("../../blender_scripts/export_blend.py"),
    ),
    (
        "import_blend.py",
        include_str!("../../blender_scripts/import_blend.py"),
    ),
    ("jsonlines.py", include_str!("../../workers/jsonlines.py")),
    (
        "scene_common.py",
        include_str!("../../workers/scene_common.py"),
    ),
];

/// Longest a job may take: Blender's start-up plus reading or writing a
/// large scene.
const TIME_LIMIT: Duration = Duration::from_secs(900);

/// The line a script prints before a user's error (a file it cannot map),
/// to be shown as scenefit's one-line error.
const USER_ERROR: &str = "scenefit-error: ";

/// Runs `blender -b [blend] ... -P script -- args` in the temporary
/// directory `dir` (which receives the scripts). Err(Usage) carries a
/// script's own user error; Err(Run) the end of Blender's output.
pub fn run(dir: &Path, blend: Option<&Path>, script: &str, args: &[OsString]) -> Result<()> {
    let program =
        crate::exec::discover::find("blender", &crate::exec::discover::apt_hint("blender"))?;
    for (name, text) in FILES {
        crate::fsio::write_atomic(&dir.join(name), text.as_bytes())?;
    }
    let log = dir.join("blender.log");
    let out = std::fs::File::create(&log).map_err(|e| Error::io(&log, e))?;
    let err = out.try_clone().map_err(|e| Error::io(&log, e))?;
    let mut cmd = Command::new(program);
    cmd.arg("-b");
    if let Some(b) = blend {
        cmd.arg(b);
    }
    cmd.args(["--factory-startup", "--disable-autoexec", "-noaudio"])
        .args(["--python-exit-code", "1", "-P"])
        .arg(dir.join(script))
        .arg("--")
        .args(args)
        .current_dir(dir)
        .env("TMPDIR", dir)
        .stdin(Stdio::null())
        .stdout(out)
        .stderr(err);
    let ok = wait(cmd)?;
    let text = crate::input::read_tail(&log, 64 << 10)
        .map(|b| String::from_utf8_lossy(&b).into_owned())
        .unwrap_or_default();
    if let Some(line) = text.lines().rev().find_map(|l| l.strip_prefix(USER_ERROR)) {
        return Err(Error::Usage(line.trim().to_string()));
    }
    if let (Some(b), Some(why)) = (blend, unreadable(&text)) {
        return Err(Error::Usage(format!(
            "{}: Blender cannot read it ({why}); expected a .blend file saved by Blender",
            b.display()
        )));
    }
    if ok {
        return Ok(());
    }
    let tail: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    let last = tail[tail.len().saturating_sub(3)..].join(" | ");
    Err(Error::Run(format!(
        "Blender failed running {script}: {last}"
    )))
}

/// Blender's reason for not loading the file it was given, from its log
/// ("Error: Failed to read blend file 'F': Missing DNA block").
fn unreadable(log: &str) -> Option<String> {
    let line = log
        .lines()
        .find(|l| l.contains("Failed to read blend file") || l.contains("Cannot read file"))?;
    let why = line.rsplit(": ").next().unwrap_or(line).trim();
    Some(why.to_string())
}

/// Starts `cmd` in a process group of its own and waits at most
/// TIME_LIMIT; true when it exited with status 0.
fn wait(mut cmd: Command) -> Result<bool> {
    use std::os::unix::process::CommandExt;
    cmd.process_group(0);
    let mut child = cmd
        .spawn()
        .map_err(|e| Error::Run(format!("cannot start blender: {e}")))?;
    let start = Instant::now();
    loop {
        match child.try_wait() {
            Ok(Some(status)) => return Ok(status.success()),
            Ok(None) if start.elapsed() < TIME_LIMIT => {
                std::thread::sleep(Duration::from_millis(50))
            }
            _ => {
                // SAFETY: kill(2) on the group this function started.
                unsafe { libc::kill(-(child.id() as i32), libc::SIGKILL) };
                let _ = child.wait();
                return Err(Error::Run(format!(
                    "Blender took over {} s; killed",
                    TIME_LIMIT.as_secs()
                )));
            }
        }
    }
}
