//! Renderer plug-ins (docs/plugins.md): the example plug-in fits a
//! parameter in both modes, and a fault-injecting plug-in
//! (tests/plugins/faulty.py) shows that a render that crashes, hangs,
//! writes no image, a non-image or an image of the wrong size costs its
//! candidate, not the run; that persistent workers are replaced when they
//! die or have served their quota; and that a generation in which every
//! render fails stops the run, which `--resume` continues.

#[path = "backends_common/mod.rs"]
mod common;

use common::*;
use scenefit::render::{from_spec, from_spec_with, RenderOptions, RenderResult};
use scenefit::scene::{parse, ParamSpace, Scene};
use std::sync::Mutex;

/// Tests that set environment variables read at session start run one at a time.
static ENV: Mutex<()> = Mutex::new(());

/// The plug-ins are Python scripts.
fn have_python() -> bool {
    have("python3", "python3")
}

fn lambert() -> String {
    root()
        .join("examples/plugins/lambert.py")
        .display()
        .to_string()
}

fn faulty() -> String {
    root().join("tests/plugins/faulty.py").display().to_string()
}

/// The diffuse scene at 64x48 (the example plug-in is pure Python).
fn small_scene() -> serde_json::Value {
    let mut s = diffuse_scene(1, 1);
    s["image"] = serde_json::json!({"width": 64, "height": 48});
    s
}

fn scene(v: &serde_json::Value) -> Scene {
    parse(&v.to_string(), "test scene", &[]).expect("test scene is valid")
}

/// Fits the light's intensity (truth 10) with `renderer`.
fn plugin_fits(renderer: &str) {
    let dir = tempdir();
    let d = dir.path();
    write_json(d, "truth.json", &small_scene());
    let mut start = small_scene();
    start["lights"][0]["intensity"] = 15.0.into();
    start["free"] = serde_json::json!([{"param": "lights.key.intensity", "min": 4, "max": 20}]);
    write_json(d, "scene.json", &start);
    let o = run(
        d,
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
    let o = run(
        d,
        &[
            "fit",
            "scene.json",
            "--target",
            "target.png",
            "-o",
            "run",
            "--renderer",
            renderer,
            "--population",
            "8",
            "--generations",
            "10",
            "-q",
        ],
        &[],
    );
    expect_code(&o, 0);
    let r = result(&d.join("run"));
    let intensity = r["params"]["lights.key.intensity"]
        .as_f64()
        .expect("fitted intensity");
    let dev = r["deviation"]["average"].as_f64().expect("deviation");
    eprintln!("{renderer}: intensity {intensity:.3} (truth 10), deviation {dev:.3} %");
    assert!((intensity - 10.0).abs() < 0.3, "intensity {intensity}");
    assert!(dev < 0.3, "deviation {dev}");
    assert_eq!(r["failed_renders"], 0);
}

#[test]
fn one_shot_plugin_fits_a_parameter() {
    if have_python() {
        plugin_fits(&format!("cmd:python3 {} {{scene}} {{output}}", lambert()));
    }
}

#[test]
fn persistent_plugin_fits_a_parameter() {
    if have_python() {
        plugin_fits(&format!("worker:python3 {} --worker", lambert()));
    }
}

/// Renders scenes whose light intensities are 1.000, 1.001, ... (the
/// faulty plug-in picks its fault from the last digits).
fn render_mix(renderer: &str, n: usize, jobs: usize) -> Vec<RenderResult> {
    render_mix_with(renderer, n, jobs, &RenderOptions::default())
}

/// As `render_mix`, with renderer options (a timeout, worker restarts)
/// given as the flags give them, not through the process environment that
/// tests running at the same time would share.
fn render_mix_with(
    renderer: &str,
    n: usize,
    jobs: usize,
    options: &RenderOptions,
) -> Vec<RenderResult> {
    let base = scene(&small_scene());
    let scenes: Vec<Scene> = (0..n)
        .map(|k| {
            let mut s = base.clone();
            s.lights[0].intensity = 1.0 + k as f64 / 1000.0;
            s
        })
        .collect();
    let r = from_spec_with(renderer, options).expect("renderer spec");
    let mut session = r
        .session(&base, &ParamSpace::default(), jobs)
        .expect("session starts");
    session.render_batch(&scenes, 1)
}

fn failure(r: &RenderResult) -> String {
    match r {
        Ok(_) => panic!("expected a failure, the render succeeded"),
        Err(f) => f.to_string(),
    }
}

#[test]
fn one_shot_faults_fail_their_render_only() {
    if !have_python() {
        return;
    }
    let _env = ENV.lock().unwrap_or_else(|p| p.into_inner());
    let opts = RenderOptions {
        render_timeout: Some(std::time::Duration::from_secs(4)),
        ..Default::default()
    };
    let started = std::time::Instant::now();
    let r = render_mix_with(
        &format!(
            "cmd:python3 {} --fault mixed {{scene}} {{output}}",
            faulty()
        ),
        8,
        8,
        &opts,
    );
    // ok, crash, ok, noimage, garbage, ok, wrongsize, hang
    for i in [0, 2, 5] {
        assert!(r[i].is_ok(), "render {i}: {}", failure(&r[i]));
    }
    let crash = failure(&r[1]);
    assert!(
        crash.contains("exited with status 3")
            && crash.contains("crashing on purpose")
            && crash.contains("2 attempts"),
        "{crash}"
    );
    assert!(
        failure(&r[3]).contains("exited 0 but no image was written"),
        "{}",
        failure(&r[3])
    );
    assert!(
        failure(&r[4]).contains("is not an image"),
        "{}",
        failure(&r[4])
    );
    assert!(
        failure(&r[6]).contains("is 8x6, expected 64x48"),
        "{}",
        failure(&r[6])
    );
    let hang = failure(&r[7]);
    assert!(
        hang.contains("timed out after 4 s") && hang.contains("hanging on purpose"),
        "{hang}"
    );
    // two attempts of 4 s for the hang, the rest in parallel (a loaded machine is slow)
    assert!(started.elapsed().as_secs_f64() < 60.0);
}

#[test]
fn worker_faults_fail_their_render_only() {
    if !have_python() {
        return;
    }
    let _env = ENV.lock().unwrap_or_else(|p| p.into_inner());
    let opts = RenderOptions {
        render_timeout: Some(std::time::Duration::from_secs(4)),
        ..Default::default()
    };
    let r = render_mix_with(
        &format!("worker:python3 {} --worker --fault mixed", faulty()),
        10,
        2,
        &opts,
    );
    // ok, crash, ok, noimage, garbage, refuse, wrongsize, noise, hang, ok
    for i in [0, 2, 7, 9] {
        assert!(r[i].is_ok(), "render {i}: {}", failure(&r[i]));
    }
    let crash = failure(&r[1]);
    assert!(
        crash.contains("the worker exited with status 3 while rendering")
            && crash.contains("crashing on purpose"),
        "{crash}"
    );
    assert!(crash.contains("2 attempts"), "{crash}");
    assert!(
        failure(&r[3]).contains("the worker answered ok but no image was written"),
        "{}",
        failure(&r[3])
    );
    assert!(failure(&r[4]).contains("is not an image"));
    let refused = failure(&r[5]);
    assert!(
        refused.contains("the worker failed: refused on purpose")
            && refused.contains("refusing on purpose"),
        "{refused}"
    );
    assert!(failure(&r[6]).contains("is 8x6, expected 64x48"));
    let hang = failure(&r[8]);
    assert!(
        hang.contains("timed out after 4 s and was killed") && hang.contains("hanging on purpose"),
        "{hang}"
    );
}

#[test]
fn worker_that_dies_is_replaced_and_its_request_retried() {
    if !have_python() {
        return;
    }
    let r = render_mix(
        &format!(
            "worker:python3 {} --worker --fault dieafter --after 2",
            faulty()
        ),
        7,
        1,
    );
    for (i, x) in r.iter().enumerate() {
        assert!(x.is_ok(), "render {i}: {}", failure(x));
    }
}

#[test]
fn worker_is_restarted_after_max_renders() {
    if !have_python() {
        return;
    }
    let _env = ENV.lock().unwrap_or_else(|p| p.into_inner());
    let spec = format!(
        "worker:python3 {} --worker --fault limit --after 3",
        faulty()
    );
    let opts = RenderOptions {
        worker_max_renders: Some(3),
        ..Default::default()
    };
    let r = render_mix_with(&spec, 8, 1, &opts);
    for (i, x) in r.iter().enumerate() {
        assert!(x.is_ok(), "render {i}: {}", failure(x));
    }
    // without the restarts the fourth render on would fail
    let r = render_mix(&spec, 5, 1);
    assert!(r[2].is_ok());
    assert!(failure(&r[3]).contains("served too many requests"));
}

#[test]
fn worker_that_cannot_start_is_a_clear_error() {
    if !have_python() {
        return;
    }
    let base = scene(&small_scene());
    let r = from_spec(&format!(
        "worker:python3 {} --worker --fault nostart",
        faulty()
    ))
    .unwrap();
    let err = match r.session(&base, &ParamSpace::default(), 2) {
        Ok(_) => panic!("the session started"),
        Err(e) => e.to_string(),
    };
    assert!(
        err.contains("no worker started")
            && err.contains("exited before it was ready (exited with status 4)")
            && err.contains("refusing to start"),
        "{err}"
    );
}

#[test]
fn fit_survives_failing_renders_and_logs_them() {
    if !have_python() {
        return;
    }
    let dir = tempdir();
    let d = dir.path();
    let mut s = small_scene();
    write_json(d, "truth.json", &s);
    s["free"] = serde_json::json!([{"param": "lights.key.intensity", "min": 4, "max": 20}]);
    write_json(d, "scene.json", &s);
    let o = run(
        d,
        &[
            "render",
            "truth.json",
            "-o",
            "target.png",
            "--renderer",
            &format!("cmd:python3 {}", lambert()),
        ],
        &[],
    );
    expect_code(&o, 0);
    let renderer = format!("worker:python3 {} --worker --fault mixed", faulty());
    let o = run(
        d,
        &[
            "fit",
            "scene.json",
            "--target",
            "target.png",
            "-o",
            "run",
            "--renderer",
            &renderer,
            "--population",
            "10",
            "--generations",
            "3",
            "-q",
        ],
        &[("SCENEFIT_RENDER_TIMEOUT", "3")],
    );
    expect_code(&o, 0);
    let r = result(&d.join("run"));
    let failed = r["failed_renders"].as_u64().expect("failed_renders");
    let log = std::fs::read_to_string(d.join("run/failures.log")).expect("failures.log");
    eprintln!("{failed} failed renders; failures.log:\n{log}");
    assert!(failed > 0 && failed < 40);
    assert!(log.contains("stderr:"), "the renderer's stderr is logged");
}

#[test]
fn generation_that_fails_entirely_stops_the_run_and_resume_continues() {
    if !have_python() {
        return;
    }
    let dir = tempdir();
    let d = dir.path();
    let mut s = small_scene();
    write_json(d, "truth.json", &s);
    s["free"] = serde_json::json!([{"param": "lights.key.intensity", "min": 4, "max": 20}]);
    write_json(d, "scene.json", &s);
    let renderer = format!("cmd:python3 {} --fault ok {{scene}} {{output}}", faulty());
    let o = run(
        d,
        &[
            "render",
            "truth.json",
            "-o",
            "target.png",
            "--renderer",
            &renderer,
        ],
        &[],
    );
    expect_code(&o, 0);
    let fit = [
        "fit",
        "scene.json",
        "--target",
        "target.png",
        "-o",
        "run",
        "--renderer",
        &renderer,
        "--population",
        "6",
        "--generations",
        "6",
        // All 6 generations run (the hybrid may end a converged run early).
        "--strategy",
        "rand1bin",
        "-q",
    ];
    // the renderer breaks: every render of the first generation fails
    let o = run(d, &fit, &[("FAULTY_MODE", "crash")]);
    expect_code(&o, 1);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("every render of generation")
            && err.contains("--resume")
            && err.contains("crashing on purpose"),
        "{err}"
    );
    assert!(d.join("run/checkpoint.json").is_file());
    // repaired, the run continues from its checkpoint
    let mut resume = fit.to_vec();
    resume.push("--resume");
    let o = run(d, &resume, &[]);
    expect_code(&o, 0);
    let r = result(&d.join("run"));
    assert_eq!(r["generations"], 6);
    let intensity = r["params"]["lights.key.intensity"]
        .as_f64()
        .expect("intensity");
    assert!((intensity - 10.0).abs() < 1.0, "{intensity}");
}

/// The commands of docs/plugins.md, as written there (output paths in a
/// temporary directory).
#[test]
fn documented_plugin_example_works() {
    if !have_python() {
        return;
    }
    let dir = tempdir();
    let d = dir.path();
    let target = d.join("ball-target.png").display().to_string();
    let out = d.join("ball-fit").display().to_string();
    let root = root();
    let o = run(
        &root,
        &[
            "render",
            "examples/plugins/ball.json",
            "-o",
            &target,
            "--renderer",
            "cmd:python3 examples/plugins/lambert.py {scene} {output}",
            "--set",
            "lights.key.intensity=10",
            "--set",
            "objects.floor.material.diffuse=0.6",
        ],
        &[],
    );
    expect_code(&o, 0);
    let o = run(
        &root,
        &[
            "fit",
            "examples/plugins/ball.json",
            "--target",
            &target,
            "-o",
            &out,
            "--renderer",
            "worker:python3 examples/plugins/lambert.py --worker",
            "--population",
            "10",
            "--generations",
            "15",
        ],
        &[],
    );
    expect_code(&o, 0);
    let r = result(std::path::Path::new(&out));
    let dev = r["deviation"]["average"].as_f64().expect("deviation");
    assert!(dev < 0.5, "deviation {dev}");
}

/// True while process `pid` exists (and is not a zombie).
fn alive(pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat"))
        .is_ok_and(|s| s.split_whitespace().nth(2).is_none_or(|st| st != "Z"))
}

#[test]
fn workers_are_killed_when_the_session_ends() {
    if !have_python() {
        return;
    }
    let _env = ENV.lock().unwrap_or_else(|p| p.into_inner());
    let pids = tempdir();
    std::env::set_var("FAULTY_PIDDIR", pids.path());
    let base = scene(&small_scene());
    let r = from_spec(&format!("worker:python3 {} --worker --fault ok", faulty())).unwrap();
    let mut session = r
        .session(&base, &ParamSpace::default(), 3)
        .expect("session starts");
    // workers past the first start with the first batch that needs them
    assert!(session
        .render_batch(&[base.clone(), base.clone()], 0)
        .iter()
        .all(|x| x.is_ok()));
    std::env::remove_var("FAULTY_PIDDIR");
    let started: Vec<u32> = std::fs::read_dir(pids.path())
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().to_str()?.parse().ok())
        .collect();
    // two renders start two of the three workers (no idle ones)
    assert_eq!(started.len(), 2);
    assert!(started.iter().all(|p| alive(*p)));
    drop(session);
    for p in &started {
        assert!(!alive(*p), "worker {p} outlived its session");
    }
}

#[test]
fn a_timeout_kills_what_the_renderer_started() {
    if !have("sh", "sh") {
        return;
    }
    let _env = ENV.lock().unwrap_or_else(|p| p.into_inner());
    let dir = tempdir();
    let pidfile = dir.path().join("child.pid");
    // a wrapper that starts a long-running child and waits for it
    let template = format!(
        "cmd:sh -c 'sleep 300 & echo $! > {}; wait' {{scene}} {{output}}",
        pidfile.display()
    );
    let opts = RenderOptions {
        render_timeout: Some(std::time::Duration::from_secs(1)),
        ..Default::default()
    };
    let r = render_mix_with(&template, 1, 1, &opts);
    assert!(failure(&r[0]).contains("timed out after 1 s"));
    let pid: u32 = std::fs::read_to_string(&pidfile)
        .expect("the wrapper wrote its child's pid")
        .trim()
        .parse()
        .expect("a pid");
    assert!(
        !alive(pid),
        "the wrapper's child {pid} survived the timeout"
    );
}
