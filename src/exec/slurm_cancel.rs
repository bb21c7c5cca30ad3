//! A run's Slurm jobs and job steps found by their task-name prefix and
//! cancelled: what a session does at its end, the watchdog when scenefit
//! is killed, and a later run for what a killed one left.

use std::process::{Command, Stdio};

/// Jobs and job steps of the current user whose names start with one of
/// `prefixes`, as Slurm ids (`123`, or `123.4` for a step in a job that is
/// not one of them). Empty when squeue cannot be asked.
pub fn find(prefixes: &[String]) -> Vec<String> {
    let ours = |name: &str| prefixes.iter().any(|p| name.starts_with(p.as_str()));
    let query = |steps: bool| -> Vec<(String, String)> {
        let mut c = Command::new("squeue");
        c.args(["--me", "--noheader", "--format=%i %j"]);
        if steps {
            c.arg("--steps");
        }
        let Ok(out) = c.stdin(Stdio::null()).stderr(Stdio::null()).output() else {
            return Vec::new();
        };
        String::from_utf8_lossy(&out.stdout)
            .lines()
            .filter_map(|l| {
                let (id, name) = l.trim().split_once(' ')?;
                Some((id.trim().to_string(), name.trim().to_string()))
            })
            .collect()
    };
    let jobs: Vec<String> = query(false)
        .into_iter()
        .filter(|(_, n)| ours(n))
        .map(|(i, _)| i)
        .collect();
    let mut ids = jobs.clone();
    for (id, name) in query(true) {
        let job = id.split('.').next().unwrap_or("");
        if ours(&name) && !jobs.iter().any(|j| j == job) {
            ids.push(id);
        }
    }
    ids
}

/// Cancels the jobs and steps named by `prefixes`; returns their ids.
pub fn cancel_prefixes(prefixes: &[String]) -> Vec<String> {
    if prefixes.is_empty() {
        return Vec::new();
    }
    let ids = find(prefixes);
    if !ids.is_empty() {
        let _ = Command::new("scancel")
            .arg("--quiet")
            .args(&ids)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status();
    }
    ids
}
