//! `scenefit fit` end to end on the built-in tracer: recovery of hidden
//! truth on the paper's scene (Table II setting), the output files,
//! determinism across --jobs, and resuming a killed run.

mod common;
use common::*;
use scenefit::fit::{self, FitConfig, FitTarget};
use scenefit::optimize::{DeConfig, Strategy};
use scenefit::render::{from_spec, render_one};
use scenefit::scene::{load, parse, Override, ParamSpace, Scene, Value};
use std::path::Path;

/// Values the targets are rendered with; the fit starts from the bounds.
const HIDDEN: [(&str, &str); 7] = [
    ("lights.led_left.position", "[-0.042, 0.132, 0.05]"),
    ("lights.led_left.intensity", "0.014"),
    ("lights.led_right.position", "[0.038, 0.136, 0.02]"),
    ("lights.led_right.intensity", "0.012"),
    ("objects.floor.material.color", "[0.45, 0.5, 0.55]"),
    ("objects.sphere.material.specular", "0.25"),
    ("objects.sphere.material.shininess", "50"),
];

fn truth(base: &Scene, colour: [f64; 3]) -> Scene {
    let mut sets: Vec<Override> = HIDDEN
        .iter()
        .map(|(k, v)| format!("{k}={v}").parse().unwrap())
        .collect();
    sets.push(
        format!(
            "objects.sphere.material.color={}",
            serde_json::json!(colour)
        )
        .parse()
        .unwrap(),
    );
    let text = serde_json::to_string(base).unwrap();
    parse(&text, "truth", &sets).unwrap()
}

/// The paper's Table II setting: targets rendered by the same model, the
/// paper's six colours, the paper's budget (80 x 500); SHADE.
#[test]
fn recovers_hidden_truth_for_the_papers_six_colours() {
    let base = load(&scenes().join("paper_box.json")).unwrap();
    let space = ParamSpace::from_scene(&base);
    let phong = from_spec("phong").unwrap();
    let colours = [
        ("red", [0.70, 0.06, 0.05]),
        ("green", [0.08, 0.55, 0.10]),
        ("blue", [0.06, 0.12, 0.65]),
        ("yellow", [0.80, 0.62, 0.05]),
        ("brown", [0.30, 0.14, 0.05]),
        ("pink", [0.85, 0.35, 0.45]),
    ];
    let sphere = [0.0, 0.085, -0.03];
    for (name, rgb) in colours {
        let t = truth(&base, rgb);
        let image = render_one(phong.as_ref(), &t, 0).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let config = FitConfig {
            de: DeConfig {
                strategy: Strategy::Shade,
                seed: 11,
                ..DeConfig::default()
            },
            generations: 500,
            ..FitConfig::default()
        };
        let target = FitTarget {
            image,
            levels: None,
            mask: None,
            path: None,
            encoding: None,
        };
        let r = fit::run(&base, &target, phong.as_ref(), &config, dir.path(), &mut ())
            .unwrap()
            .result;
        assert!(
            r.deviation.average <= 0.1,
            "{name}: average deviation {:.4} % > 0.1 %",
            r.deviation.average
        );
        assert!(
            r.evaluations <= 80 * 501,
            "{name}: within the paper's budget"
        );
        let fitted = load(&dir.path().join("fitted_scene.json")).unwrap();
        for s in &space.specs {
            match (s.field.get(&t).unwrap(), s.field.get(&fitted).unwrap()) {
                (Value::Vector(a), Value::Vector(b)) if s.name.ends_with("position") => {
                    let err =
                        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2))
                            .sqrt();
                    let dist = ((a[0] - sphere[0]).powi(2)
                        + (a[1] - sphere[1]).powi(2)
                        + (a[2] - sphere[2]).powi(2))
                    .sqrt();
                    assert!(
                        err <= 0.02 * dist,
                        "{name}: {} off by {:.2} mm, over 2 % of {:.1} mm",
                        s.name,
                        err * 1e3,
                        dist * 1e3
                    );
                }
                (Value::Vector(a), Value::Vector(b)) => {
                    let err = (0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f64::max);
                    assert!(err <= 0.01, "{name}: {} off by {err:.4}", s.name);
                }
                _ => {}
            }
        }
    }
}

fn write_target(dir: &Path, scene: &Path, sets: &[&str]) {
    let mut args = vec!["render", scene.to_str().unwrap(), "-o", "target.png"];
    for s in sets {
        args.push("--set");
        args.push(s);
    }
    let out = scenefit(dir, &args);
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn fit_writes_every_output_and_recovers_the_example() {
    let d = tempfile::tempdir().unwrap();
    let scene = scenes().join("sphere_floor.json");
    write_target(
        d.path(),
        &scene,
        &[
            "lights.key.position=[1.5,2.5,2.5]",
            "lights.key.intensity=14",
            "objects.ball.material.color=[0.2,0.5,0.8]",
        ],
    );
    let out = scenefit(
        d.path(),
        &[
            "fit",
            scene.to_str().unwrap(),
            "--target",
            "target.png",
            "-o",
            "run",
            "--generations",
            "150",
            "--strategy",
            "shade",
            "-q",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let run = d.path().join("run");
    let r = json(&run.join("result.json"));
    for key in [
        "renderer",
        "strategy",
        "seed",
        "params",
        "deviation",
        "evaluations",
        "generations",
        "wall_seconds",
    ] {
        assert!(r.get(key).is_some(), "result.json lacks {key}");
    }
    assert_eq!(r["renderer"], "phong");
    assert_eq!(r["generations"], 150);
    assert!(
        r["deviation"]["average"].as_f64().unwrap() < 0.2,
        "{}",
        r["deviation"]
    );
    let pos: Vec<f64> = serde_json::from_value(r["params"]["lights.key.position"].clone()).unwrap();
    let err =
        ((pos[0] - 1.5f64).powi(2) + (pos[1] - 2.5f64).powi(2) + (pos[2] - 2.5f64).powi(2)).sqrt();
    assert!(err < 0.05, "light off by {err} m: {pos:?}");
    // Colours are reported as linear RGB whatever space they were searched in.
    let c: Vec<f64> =
        serde_json::from_value(r["params"]["objects.ball.material.color"].clone()).unwrap();
    assert!(
        (c[0] - 0.2).abs() < 0.02 && (c[2] - 0.8).abs() < 0.02,
        "{c:?}"
    );
    assert!(
        load(&run.join("fitted_scene.json")).is_ok(),
        "fitted_scene.json is a valid scene"
    );
    assert_eq!(
        image::open(run.join("best.png"))
            .unwrap()
            .to_rgb8()
            .dimensions(),
        (128, 96)
    );
    for g in (10..=150).step_by(10) {
        assert!(
            run.join(format!("best_g{g:04}.bmp")).exists(),
            "best_g{g:04}.bmp"
        );
    }
    let progress = std::fs::read_to_string(run.join("progress.txt")).unwrap();
    // Generation 0 (the initial population) and every tenth after it.
    assert_eq!(
        progress.lines().filter(|l| !l.starts_with('#')).count(),
        16,
        "{progress}"
    );
}

#[test]
fn same_seed_same_params_whatever_the_jobs() {
    let d = tempfile::tempdir().unwrap();
    let scene = scenes().join("paper_box.json");
    write_target(
        d.path(),
        &scene,
        &["objects.sphere.material.color=[0.2,0.6,0.3]"],
    );
    let mut results = Vec::new();
    for jobs in ["1", "2"] {
        let out_dir = format!("run{jobs}");
        let out = scenefit(
            d.path(),
            &[
                "fit",
                scene.to_str().unwrap(),
                "--target",
                "target.png",
                "-o",
                &out_dir,
                "--generations",
                "25",
                "--population",
                "30",
                "--seed",
                "5",
                "--jobs",
                jobs,
                "-q",
            ],
        );
        assert!(out.status.success(), "{}", stderr(&out));
        results.push(json(&d.path().join(&out_dir).join("result.json")));
    }
    assert_eq!(results[0]["params"], results[1]["params"]);
    assert_eq!(results[0]["deviation"], results[1]["deviation"]);
    let out = scenefit(
        d.path(),
        &[
            "fit",
            scene.to_str().unwrap(),
            "--target",
            "target.png",
            "-o",
            "run_other",
            "--generations",
            "25",
            "--population",
            "30",
            "--seed",
            "6",
            "-q",
        ],
    );
    assert!(out.status.success());
    assert_ne!(
        json(&d.path().join("run_other/result.json"))["params"],
        results[0]["params"],
        "another seed, another search"
    );
}

#[test]
fn a_killed_run_resumes_to_the_same_result() {
    let d = tempfile::tempdir().unwrap();
    let scene = scenes().join("paper_box.json");
    write_target(
        d.path(),
        &scene,
        &["objects.sphere.material.color=[0.6,0.3,0.2]"],
    );
    let s = scene.to_str().unwrap();
    let args = |dir: &'static str| {
        vec![
            "fit",
            s,
            "--target",
            "target.png",
            "-o",
            dir,
            "--generations",
            "300",
            "--seed",
            "3",
            "--jobs",
            "1",
            "-q",
        ]
    };
    let out = scenefit(d.path(), &args("straight"));
    assert!(out.status.success(), "{}", stderr(&out));

    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_scenefit"))
        .args(args("killed"))
        .current_dir(d.path())
        .spawn()
        .unwrap();
    let progress = d.path().join("killed/progress.txt");
    let started = std::time::Instant::now();
    loop {
        let lines = std::fs::read_to_string(&progress)
            .map(|t| t.lines().count())
            .unwrap_or(0);
        if lines > 5 || started.elapsed().as_secs() > 60 {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        !d.path().join("killed/result.json").exists(),
        "killed before the end (raise --generations if this machine is faster)"
    );
    let mut resume = args("killed");
    resume.push("--resume");
    let out = scenefit(d.path(), &resume);
    assert!(out.status.success(), "{}", stderr(&out));
    let (a, b) = (
        json(&d.path().join("straight/result.json")),
        json(&d.path().join("killed/result.json")),
    );
    assert_eq!(a["params"], b["params"]);
    assert_eq!(a["evaluations"], b["evaluations"]);

    // A resume that does not match the checkpoint says so.
    let mut wrong = args("killed");
    wrong.extend(["--resume", "--population", "40"]);
    let out = scenefit(d.path(), &wrong);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("--population"), "{}", stderr(&out));
}
