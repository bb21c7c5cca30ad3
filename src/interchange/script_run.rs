//! One run of a shipped script for `scenefit import` / `export` (Blender's
//! or Mitsuba's): the script and the modules it imports written into a
//! private directory, the program started by the exec layer as a renderer
//! is (a process group of its own, killed with scenefit), given one time
//! limit, and what it printed last kept for the caller's error message.
//! The format modules (`blend_run`, `python_run`) say what the output means.

use crate::error::Result;
use crate::exec::process::CommandSpec;
use std::path::Path;
use std::time::Duration;

/// Longest an import or export may take: the program's start-up plus
/// reading or writing a large scene. A script that hangs costs this, not
/// the user's session.
pub const TIME_LIMIT: Duration = Duration::from_secs(900);

/// How a run ended: what it printed last (stdout and stderr, the last few
/// KB), and why it failed when it did not exit with status 0.
pub struct Ran {
    pub text: String,
    pub failure: Option<String>,
}

/// Writes `files` (name, text) into `dir`, where the script runs.
pub fn write_files(dir: &Path, files: &[(&str, &str)]) -> Result<()> {
    for (name, text) in files {
        crate::fsio::write_atomic(&dir.join(name), text.as_bytes())?;
    }
    Ok(())
}

/// Runs `spec` to its end or to `limit` (then it is killed, a failure
/// like any other); the caller reads the script's own reason from the text.
pub fn run(spec: &CommandSpec, limit: Duration) -> Result<Ran> {
    let rt = crate::exec::runtime()?;
    let launcher = crate::exec::launcher::Launcher::default();
    let out = rt.block_on(crate::exec::oneshot::run_process(spec, &launcher, limit));
    match out {
        Ok(text) => Ok(Ran {
            text,
            failure: None,
        }),
        Err(f) => Ok(Ran {
            text: f.stderr,
            failure: Some(f.message),
        }),
    }
}

/// The last `n` non-empty lines of `text`, joined for a one-line message.
pub fn last_lines(text: &str, n: usize) -> String {
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    lines[lines.len().saturating_sub(n)..].join(" | ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_script_that_hangs_is_killed_at_the_limit() {
        let spec = CommandSpec::new("sh").args(["-c", "sleep 30"]);
        let start = std::time::Instant::now();
        let ran = run(&spec, Duration::from_millis(300)).unwrap();
        assert!(start.elapsed() < Duration::from_secs(10));
        let failure = ran.failure.unwrap();
        assert!(failure.contains("timed out"), "{failure}");
    }

    #[test]
    fn a_failing_script_keeps_what_it_printed() {
        // one stream: stdout and stderr are drained side by side, so their
        // relative order is not kept (callers search every line)
        let spec = CommandSpec::new("sh").args([
            "-c",
            "echo first >&2; echo 'scenefit-error: bad' >&2; exit 3",
        ]);
        let ran = run(&spec, TIME_LIMIT).unwrap();
        assert!(ran.failure.unwrap().contains("status 3"));
        assert!(ran.text.contains("scenefit-error: bad"), "{}", ran.text);
        assert_eq!(last_lines(&ran.text, 1), "scenefit-error: bad");
    }
}
