//! Renderer workers on a real Slurm (`--executor slurm`): the single-node
//! cluster of scripts/slurm-local.sh, which scripts/test.sh starts before
//! the tests and stops after them. A fit on Slurm gives the same
//! parameters as the same fit run locally, with a `worker:` plug-in and
//! with Blender, even when one worker's task is cancelled (`scancel`)
//! mid-run; a worker that cannot start fails with one line naming srun and
//! Slurm's message; Ctrl-C leaves no job behind; and a run directory whose
//! run was killed with jobs still queued has them cancelled (and named) by
//! the next run there.
//!
//! Without a cluster the tests skip, saying why, unless CI is "true".

#[path = "backends_common/mod.rs"]
mod common;

use common::*;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// True when srun answers; otherwise skips (or fails with CI=true).
fn have_slurm() -> bool {
    let ok = Command::new("srun")
        .args(["-n1", "--job-name=scenefit-test-probe", "true"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    if !ok {
        let msg = "skipping: no Slurm cluster answers `srun -n1 true` (start one with `scripts/slurm-local.sh start`, as scripts/test.sh does)";
        if std::env::var("CI").as_deref() == Ok("true") {
            panic!("{msg}; CI=true requires it");
        }
        eprintln!("{msg}");
    }
    ok
}

fn lambert_worker() -> String {
    format!(
        "worker:python3 {} --worker",
        root().join("examples/plugins/lambert.py").display()
    )
}

/// Jobs and steps of this user: id -> (name, state).
fn squeue() -> BTreeMap<String, (String, String)> {
    let mut all = BTreeMap::new();
    for steps in [false, true] {
        let mut c = Command::new("squeue");
        c.args(["--me", "--noheader", "--format=%i %j %T"]);
        if steps {
            // steps have no state column: they run
            c.args(["--steps", "--format=%i %j"]);
        }
        let out = c.output().expect("squeue runs");
        for l in String::from_utf8_lossy(&out.stdout).lines() {
            let w: Vec<&str> = l.split_whitespace().collect();
            if w.len() >= 2 {
                let state = w.get(2).copied().unwrap_or("RUNNING");
                all.insert(w[0].to_string(), (w[1].to_string(), state.to_string()));
            }
        }
    }
    all
}

/// The jobs of the scenefit with process id `pid` (not completing).
fn jobs_of(pid: u32) -> Vec<(String, String, String)> {
    let prefix = format!("scenefit-{pid}-");
    squeue()
        .into_iter()
        .filter(|(_, (n, s))| n.starts_with(&prefix) && s != "COMPLETING")
        .map(|(i, (n, s))| (i, n, s))
        .collect()
}

/// The task number at the end of a task name (`scenefit-PID-T-S-N`).
fn task_number(name: &str) -> u64 {
    name.rsplit('-')
        .next()
        .and_then(|n| n.parse().ok())
        .unwrap_or(0)
}

/// The scene of these tests at `w`x`h`, the light's intensity and the
/// floor's diffuse free.
fn setup(dir: &Path, w: u32, h: u32, renderer: &str) {
    let mut truth = diffuse_scene(1, 1);
    truth["image"] = serde_json::json!({"width": w, "height": h});
    write_json(dir, "truth.json", &truth);
    let o = run(
        dir,
        &[
            "render",
            "truth.json",
            "-o",
            "target.png",
            "--renderer",
            renderer,
        ],
        &[],
    );
    expect_code(&o, 0);
    let mut start = with_free(truth);
    start["lights"][0]["intensity"] = 15.0.into();
    write_json(dir, "scene.json", &start);
}

fn fit_args<'a>(out: &'a str, renderer: &'a str, generations: &'a str) -> Vec<&'a str> {
    vec![
        "fit",
        "scene.json",
        "--target",
        "target.png",
        "-o",
        out,
        "--renderer",
        renderer,
        "--seed",
        "5",
        "--population",
        "8",
        "--generations",
        generations,
        // The whole budget, whatever the start: the hybrid may converge
        // within a second, before a worker can be cancelled mid-run.
        "--strategy",
        "shade",
        "--jobs",
        "2",
        "-q",
    ]
}

/// Runs the fit on Slurm, cancels the task of its first worker once it has
/// run a while, and returns how many tasks the run started in all.
fn fit_on_slurm_with_scancel(dir: &Path, args: &[&str]) -> u64 {
    let mut all: Vec<&str> = args.to_vec();
    all.extend(["--executor", "slurm"]);
    let mut child = Command::new(BIN)
        .args(&all)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(dir.join("slurm.stderr")).unwrap())
        .spawn()
        .expect("scenefit starts");
    let pid = child.id();
    let mut cancelled: Option<String> = None;
    let mut first_seen: Option<Instant> = None;
    let mut most = 0;
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        let jobs = jobs_of(pid);
        for (_, name, _) in &jobs {
            most = most.max(task_number(name));
        }
        let running: Vec<_> = jobs.iter().filter(|j| j.2 == "RUNNING").collect();
        if cancelled.is_none() && !running.is_empty() {
            let since = *first_seen.get_or_insert_with(Instant::now);
            // the worker has served some renders by now
            if since.elapsed() > Duration::from_millis(1500) {
                let victim = running.iter().min_by_key(|j| task_number(&j.1)).unwrap();
                let s = Command::new("scancel")
                    .arg(&victim.0)
                    .stderr(Stdio::null())
                    .status()
                    .unwrap();
                // A task listed as running may have ended before scancel
                // reached it ("Invalid job id"): look again and pick another.
                if s.success() {
                    cancelled = Some(victim.1.clone());
                }
            }
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let stderr = std::fs::read_to_string(dir.join("slurm.stderr")).unwrap_or_default();
    assert!(status.success(), "the Slurm fit failed: {stderr}");
    assert!(
        cancelled.is_some(),
        "the fit ended before a worker could be cancelled; stderr: {stderr}"
    );
    // no task of the run is left once it has ended
    let deadline = Instant::now() + Duration::from_secs(20);
    while !jobs_of(pid).is_empty() && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(200));
    }
    assert!(jobs_of(pid).is_empty(), "jobs left: {:?}", jobs_of(pid));
    assert!(
        !dir.join("sl").join(scenefit::rundir::SLURM_JOBS).exists(),
        "a finished run leaves no job record"
    );
    most
}

fn params(dir: &Path) -> serde_json::Value {
    result(dir)["params"].clone()
}

fn same_fit_on_slurm(renderer: &str, w: u32, h: u32, generations: &str) {
    let tmp = tempdir();
    let d = tmp.path();
    setup(d, w, h, renderer);
    let o = run(d, &fit_args("local", renderer, generations), &[]);
    expect_code(&o, 0);
    let tasks = fit_on_slurm_with_scancel(d, &fit_args("sl", renderer, generations));
    // two workers, and the replacement of the one cancelled
    assert!(
        tasks >= 3,
        "the cancelled worker was not replaced ({tasks} tasks)"
    );
    assert_eq!(params(&d.join("sl")), params(&d.join("local")));
}

#[test]
fn plugin_fit_on_slurm_matches_local_despite_a_cancelled_worker() {
    if !have_slurm() || !have("python3", "python3") {
        return;
    }
    // 40 generations: about 5 s on Slurm here (12 took 1.5 s, as long as
    // the test waits before it cancels a worker).
    same_fit_on_slurm(&lambert_worker(), 64, 48, "40");
}

#[test]
fn blender_fit_on_slurm_matches_local_despite_a_cancelled_worker() {
    if !have_slurm() || !have("blender", "Blender") {
        return;
    }
    same_fit_on_slurm("blender", 48, 36, "6");
}

#[test]
fn a_worker_that_cannot_start_names_srun_and_slurms_message() {
    if !have_slurm() || !have("python3", "python3") {
        return;
    }
    let tmp = tempdir();
    let d = tmp.path();
    setup(d, 16, 12, "phong");
    let r = lambert_worker();
    let mut args = fit_args("out", &r, "2");
    args.extend([
        "--executor",
        "slurm",
        "--slurm-args",
        "--partition=no-such-partition",
    ]);
    let o = run(d, &args, &[]);
    expect_code(&o, 1);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("srun"), "{e}");
    assert!(e.contains("--partition=no-such-partition"), "{e}");
    assert!(e.to_lowercase().contains("invalid partition"), "{e}");
    assert!(!e.contains("panicked"), "{e}");
}

#[test]
fn ctrl_c_cancels_every_task_of_the_run() {
    if !have_slurm() || !have("python3", "python3") {
        return;
    }
    let tmp = tempdir();
    let d = tmp.path();
    setup(d, 16, 12, "phong");
    let sleepy = format!(
        "worker:python3 {} --sleep 0.5",
        root().join("tests/plugins/sleepy.py").display()
    );
    let mut args = fit_args("out", &sleepy, "50");
    args.extend(["--executor", "slurm", "--workers", "4"]);
    let mut child = Command::new(BIN)
        .args(&args)
        .current_dir(d)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let pid = child.id();
    let deadline = Instant::now() + Duration::from_secs(60);
    while jobs_of(pid).iter().filter(|j| j.2 == "RUNNING").count() < 4 {
        assert!(Instant::now() < deadline, "the workers did not start");
        std::thread::sleep(Duration::from_millis(100));
    }
    // SAFETY: kill(2) on the child we started.
    unsafe {
        libc::kill(pid as i32, libc::SIGINT);
    }
    let _ = child.wait();
    let deadline = Instant::now() + Duration::from_secs(20);
    while !jobs_of(pid).is_empty() && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(200));
    }
    assert!(jobs_of(pid).is_empty(), "jobs left: {:?}", jobs_of(pid));
}

#[test]
fn the_next_run_cancels_what_a_killed_run_left_and_names_the_jobs() {
    if !have_slurm() || !have("python3", "python3") {
        return;
    }
    let tmp = tempdir();
    let d = tmp.path();
    setup(d, 16, 12, "phong");
    // a killed run's record, with a job of it still there (pid 999999999
    // is no process)
    let prefix = "scenefit-999999999-1-0-";
    let out = d.join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(
        out.join(scenefit::rundir::SLURM_JOBS),
        format!("{prefix}\n"),
    )
    .unwrap();
    let sb = Command::new("sbatch")
        .args([
            "--parsable",
            &format!("--job-name={prefix}1"),
            "--output=/dev/null",
            "--wrap",
            "sleep 300",
        ])
        .current_dir(d)
        .output()
        .unwrap();
    assert!(
        sb.status.success(),
        "{}",
        String::from_utf8_lossy(&sb.stderr)
    );
    let id = String::from_utf8_lossy(&sb.stdout)
        .trim()
        .split(';')
        .next()
        .unwrap()
        .to_string();
    assert!(squeue().contains_key(&id));
    let o = run(d, &fit_args("out", "phong", "2"), &[]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("left by an earlier run") && e.contains(&id),
        "{e}"
    );
    let deadline = Instant::now() + Duration::from_secs(20);
    while squeue().get(&id).is_some_and(|(_, s)| s != "COMPLETING") && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(200));
    }
    assert!(
        squeue().get(&id).is_none_or(|(_, s)| s == "COMPLETING"),
        "job {id} still there"
    );
}

/// The figures of docs/scale-out.md (run by hand, on a quiet machine:
/// `cargo test --release --test slurm -- --ignored --nocapture figures`):
/// renders per second of the latency-bound fake worker
/// (tests/plugins/sleepy.py, 50 ms per render, 32x24) with 1 to 64
/// workers, local and on Slurm; scenefit's own CPU time per render
/// (getrusage of this process, apart from its children); a worker's
/// start-up; and the same with Blender at 2 workers.
#[test]
#[ignore]
fn figures() {
    use scenefit::exec::Executor;
    use scenefit::render::{from_spec_with, RenderOptions};
    use scenefit::scene::{parse, ParamSpace};
    if !have_slurm() {
        return;
    }
    fn cpu_self() -> f64 {
        let mut u: libc::rusage = unsafe { std::mem::zeroed() };
        // SAFETY: getrusage fills the struct we own.
        unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
        let t = |v: libc::timeval| v.tv_sec as f64 + v.tv_usec as f64 * 1e-6;
        t(u.ru_utime) + t(u.ru_stime)
    }
    fn uptime() -> String {
        std::fs::read_to_string("/proc/loadavg")
            .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
            .unwrap_or_default()
    }
    let sizes: Vec<usize> = std::env::var("FIGURE_WORKERS")
        .unwrap_or_else(|_| "1,8,32,64".into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let per_worker: usize = std::env::var("FIGURE_RENDERS_PER_WORKER")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(40);
    let mut scene = diffuse_scene(1, 1);
    scene["image"] = serde_json::json!({"width": 32, "height": 24});
    let sleepy = format!(
        "worker:python3 {} --sleep 0.05",
        root().join("tests/plugins/sleepy.py").display()
    );
    let mut cases: Vec<(String, usize, String)> = Vec::new();
    for &n in &sizes {
        cases.push((sleepy.clone(), n, "32x24".into()));
    }
    if std::env::var("FIGURE_BLENDER").is_ok() {
        cases.push(("blender".into(), 2, "64x48".into()));
    }
    println!("renderer | workers | executor | start-up s | renders | renders/s | scenefit CPU ms/render | load");
    for (spec, n, size) in cases {
        let (w, h) = size.split_once('x').unwrap();
        scene["image"] = serde_json::json!({"width": w.parse::<u32>().unwrap(), "height": h.parse::<u32>().unwrap()});
        let s = parse(&scene.to_string(), "figure scene", &[]).unwrap();
        let renders = if spec == "blender" {
            80
        } else {
            n * per_worker
        };
        for executor in [Executor::Local, Executor::Slurm { args: vec![] }] {
            let label = if executor == Executor::Local {
                "local"
            } else {
                "slurm"
            };
            let opts = RenderOptions {
                workers: Some(n),
                executor,
                ..Default::default()
            };
            let r = from_spec_with(&spec, &opts).unwrap();
            let t0 = Instant::now();
            let mut session = r.session(&s, &ParamSpace::default(), n).unwrap();
            let startup = t0.elapsed().as_secs_f64();
            // every worker started and warm
            let warm = vec![s.clone(); n * 2];
            assert!(session.render_batch(&warm, 1).iter().all(|r| r.is_ok()));
            let batch = vec![s.clone(); renders];
            let (c0, t0) = (cpu_self(), Instant::now());
            let out = session.render_batch(&batch, 1);
            let wall = t0.elapsed().as_secs_f64();
            let cpu = cpu_self() - c0;
            assert!(out.iter().all(|r| r.is_ok()));
            drop(session);
            let name = if spec == "blender" {
                "blender"
            } else {
                "sleepy 50 ms"
            };
            println!(
                "{name} | {n} | {label} | {startup:.2} | {renders} | {:.0} | {:.3} | {}",
                renders as f64 / wall,
                cpu * 1e3 / renders as f64,
                uptime()
            );
        }
    }
}
