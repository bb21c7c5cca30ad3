//! Hostile cases for the run directory (issue: nothing lost): a new run
//! never destroys an earlier one, two runs never share a directory, inputs
//! the run would overwrite are refused, a resume with other inputs is
//! refused naming what changed, empty work is no result, files follow the
//! umask, and a failed write leaves the previous file intact. Each case
//! asserts the exit code, the one line, and that nothing was lost.

mod common;

use common::{json, scenefit, stderr};
use std::os::unix::fs::PermissionsExt;
use std::path::Path;
use std::process::Command;

/// A small scene: one free light intensity, 32x24 pixels.
const SCENE: &str = r#"{
  "format": "scenefit-scene/1",
  "image": {"width": 32, "height": 24},
  "camera": {"type": "perspective", "position": [0, 1.5, 5], "look_at": [0, 0.5, 0],
             "up": [0, 1, 0], "fov_y_deg": 40},
  "lights": [{"name": "key", "type": "point", "position": [1, 3, 2], "color": [1, 1, 1],
              "intensity": 10.0}],
  "objects": [
    {"name": "ball", "shape": {"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5},
     "material": {"color": [0.8, 0.5, 0.2], "diffuse": 1.0, "specular": 0.3, "shininess": 40}},
    {"name": "floor", "shape": {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
     "material": {"color": [0.6, 0.6, 0.6], "diffuse": 1.0}}
  ],
  "free": [{"param": "lights.key.intensity", "min": 1, "max": 30}]
}"#;

/// A directory with scene.json and target.png (intensity 14).
fn setup() -> tempfile::TempDir {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("scene.json"), SCENE).unwrap();
    let out = scenefit(
        d.path(),
        &[
            "render",
            "scene.json",
            "-o",
            "target.png",
            "--set",
            "lights.key.intensity=14",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    d
}

/// `fit` with small defaults; an option in `extra` replaces its default.
fn fit(d: &Path, out: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "fit",
        "scene.json",
        "--target",
        "target.png",
        "-o",
        out,
        "-q",
    ];
    // The paper's strategy: these tests are about run directories, and
    // they count its generations and read its population in checkpoints
    // (the default hybrid may end a converged run early).
    for (flag, value) in [
        ("--generations", "6"),
        ("--population", "10"),
        ("--seed", "2"),
        ("--strategy", "rand1bin"),
    ] {
        if !extra.contains(&flag) {
            args.extend([flag, value]);
        }
    }
    args.extend_from_slice(extra);
    scenefit(d, &args)
}

/// Exit code 2 and a single line that contains every one of `words`.
fn refused(out: &std::process::Output, words: &[&str]) {
    let e = stderr(out);
    assert_eq!(out.status.code(), Some(2), "{e}");
    assert_eq!(e.trim_end().lines().count(), 1, "one line: {e}");
    for w in words {
        assert!(e.contains(w), "{w:?} in: {e}");
    }
}

#[test]
fn a_new_run_refuses_an_earlier_runs_results() {
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    let before = std::fs::read(d.path().join("run/result.json")).unwrap();
    refused(
        &fit(d.path(), "run", &["--seed", "9"]),
        &["--resume", "--overwrite"],
    );
    assert_eq!(
        std::fs::read(d.path().join("run/result.json")).unwrap(),
        before
    );
}

#[test]
fn a_new_run_refuses_an_interrupted_checkpoint() {
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    std::fs::remove_file(d.path().join("run/result.json")).unwrap();
    let checkpoint = std::fs::read(d.path().join("run/checkpoint.json")).unwrap();
    refused(&fit(d.path(), "run", &[]), &["checkpoint", "--resume"]);
    assert_eq!(
        std::fs::read(d.path().join("run/checkpoint.json")).unwrap(),
        checkpoint
    );
}

#[test]
fn overwrite_replaces_the_earlier_run() {
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    std::fs::write(d.path().join("run/notes.txt"), "mine").unwrap();
    let out = fit(d.path(), "run", &["--overwrite", "--seed", "4"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(json(&d.path().join("run/result.json"))["seed"], 4);
    assert_eq!(
        std::fs::read_to_string(d.path().join("run/notes.txt")).unwrap(),
        "mine"
    );
}

#[test]
fn overwrite_keeps_the_earlier_run_when_the_renderer_cannot_start() {
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    let before = std::fs::read(d.path().join("run/result.json")).unwrap();
    let out = fit(
        d.path(),
        "run",
        &["--overwrite", "--renderer", "worker:/nonexistent/renderer"],
    );
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert_eq!(
        std::fs::read(d.path().join("run/result.json")).unwrap(),
        before
    );
    assert!(d.path().join("run/best.png").is_file());
}

#[test]
fn a_target_the_run_would_overwrite_is_refused() {
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    let best = std::fs::read(d.path().join("run/best.png")).unwrap();
    let out = scenefit(
        d.path(),
        &[
            "fit",
            "scene.json",
            "--target",
            "run/best.png",
            "-o",
            "run",
            "--overwrite",
            "--generations",
            "3",
            "--population",
            "10",
            "-q",
        ],
    );
    refused(&out, &["best.png", "overwrite"]);
    assert_eq!(std::fs::read(d.path().join("run/best.png")).unwrap(), best);
}

#[test]
fn a_mask_the_run_would_overwrite_is_refused() {
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    let best = std::fs::read(d.path().join("run/best.png")).unwrap();
    refused(
        &fit(d.path(), "run", &["--overwrite", "--mask", "run/best.png"]),
        &["--mask", "best.png"],
    );
    assert_eq!(std::fs::read(d.path().join("run/best.png")).unwrap(), best);
}

#[test]
fn two_runs_never_share_a_directory() {
    let d = setup();
    let bin = env!("CARGO_BIN_EXE_scenefit");
    let args = [
        "fit",
        "scene.json",
        "--target",
        "target.png",
        "-o",
        "run",
        "--overwrite",
        "--generations",
        "400",
        "--population",
        "20",
        // All 400 generations run (the hybrid may end a converged run early).
        "--strategy",
        "rand1bin",
        "-q",
    ];
    let mut first = Command::new(bin)
        .args(args)
        .current_dir(d.path())
        .spawn()
        .unwrap();
    // Wait until the first run holds the directory.
    let started = std::time::Instant::now();
    while !d.path().join("run/checkpoint.json").exists() && started.elapsed().as_secs() < 30 {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let second = scenefit(d.path(), &args);
    let status = first.wait().unwrap();
    assert!(status.success());
    refused(&second, &["in use"]);
    assert_eq!(json(&d.path().join("run/result.json"))["generations"], 400);
}

#[test]
fn an_output_that_is_a_file_is_refused() {
    let d = setup();
    std::fs::write(d.path().join("out"), "x").unwrap();
    refused(&fit(d.path(), "out", &[]), &["out", "directory"]);
    assert_eq!(std::fs::read_to_string(d.path().join("out")).unwrap(), "x");
}

#[test]
fn resume_with_nothing_to_resume_is_refused() {
    let d = setup();
    refused(&fit(d.path(), "run", &["--resume"]), &["nothing to resume"]);
}

/// A finished run, then a resume with one input changed: refused, naming it.
fn resume_changed(extra: &[&str], words: &[&str], change_target: bool) {
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    let before = std::fs::read(d.path().join("run/result.json")).unwrap();
    if change_target {
        let out = scenefit(
            d.path(),
            &[
                "render",
                "scene.json",
                "-o",
                "target.png",
                "--set",
                "lights.key.intensity=20",
            ],
        );
        assert!(out.status.success());
    }
    let mut args = vec!["--resume"];
    args.extend_from_slice(extra);
    refused(&fit(d.path(), "run", &args), words);
    assert_eq!(
        std::fs::read(d.path().join("run/result.json")).unwrap(),
        before
    );
}

#[test]
fn resume_refuses_another_f() {
    resume_changed(&["--f", "0.9"], &["--f"], false);
}

#[test]
fn resume_refuses_another_cr() {
    resume_changed(&["--cr", "0.2"], &["--cr"], false);
}

#[test]
fn resume_refuses_another_strategy() {
    resume_changed(&["--strategy", "jde"], &["--strategy"], false);
}

#[test]
fn resume_refuses_another_seed() {
    resume_changed(&["--seed", "7"], &["--seed"], false);
}

#[test]
fn resume_refuses_another_target() {
    resume_changed(&[], &["target"], true);
}

#[test]
fn resume_refuses_another_scene() {
    resume_changed(&["--set", "lights.key.position=[1,3,3]"], &["scene"], false);
}

#[test]
fn resume_refuses_another_stagnation_rule() {
    resume_changed(&["--stagnation", "3"], &["--stagnation"], false);
}

#[test]
fn a_larger_budget_continues_a_finished_run() {
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    let first = json(&d.path().join("run/result.json"));
    let out = fit(d.path(), "run", &["--resume", "--generations", "12"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let more = json(&d.path().join("run/result.json"));
    assert_eq!(first["generations"], 6);
    assert_eq!(more["generations"], 12);
    assert!(more["evaluations"].as_u64() > first["evaluations"].as_u64());
}

#[test]
fn a_checkpoint_saved_by_an_earlier_build_resumes_as_todays() {
    // One photograph's checkpoint as builds before the one fit path saved
    // it (format 2) continues to the result today's checkpoint gives.
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    let c = json(&d.path().join("run/checkpoint.json"));
    let old = serde_json::json!({
        "format": "scenefit-checkpoint/2",
        "identity": c["identities"][0],
        "phase_index": c["blocks_done"],
        "base": c["base"],
        "search": c["within"]["search"],
        "generation_offset": c["generations"],
        "evaluations_before": c["evaluations"],
        "elapsed_before": c["seconds"],
    });
    copy_dir(&d.path().join("run"), &d.path().join("old"));
    std::fs::write(d.path().join("old/checkpoint.json"), old.to_string()).unwrap();
    for run in ["run", "old"] {
        let out = fit(d.path(), run, &["--resume", "--generations", "12"]);
        assert!(out.status.success(), "{run}: {}", stderr(&out));
    }
    let (now, was) = (
        json(&d.path().join("run/result.json")),
        json(&d.path().join("old/result.json")),
    );
    assert_eq!(was["generations"], 12);
    assert_eq!(now["params"], was["params"]);
    assert_eq!(now["evaluations"], was["evaluations"]);
    // Saved again in today's format.
    let again = json(&d.path().join("old/checkpoint.json"));
    assert_eq!(again["format"], "scenefit-checkpoint/3");
}

/// Copies the files of run directory `from` into a new directory `to`.
fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        if e.path().is_file() && e.file_name() != ".scenefit.lock" {
            std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
        }
    }
}

#[test]
fn a_resumed_finished_run_is_the_same_result() {
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    let first = json(&d.path().join("run/result.json"));
    let out = fit(d.path(), "run", &["--resume"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let again = json(&d.path().join("run/result.json"));
    assert_eq!(first["params"], again["params"]);
    assert_eq!(first["evaluations"], again["evaluations"]);
}

#[test]
fn a_tampered_checkpoint_is_refused_naming_it() {
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    let p = d.path().join("run/checkpoint.json");
    let mut c = json(&p);
    c["base"]["image"]["width"] = serde_json::json!(0);
    std::fs::write(&p, c.to_string()).unwrap();
    refused(
        &fit(d.path(), "run", &["--resume"]),
        &["checkpoint.json", "image"],
    );
}

#[test]
fn a_checkpoint_of_another_phase_layout_is_refused() {
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    let p = d.path().join("run/checkpoint.json");
    let mut c = json(&p);
    c["blocks_done"] = serde_json::json!(7);
    std::fs::write(&p, c.to_string()).unwrap();
    refused(
        &fit(d.path(), "run", &["--resume"]),
        &["checkpoint.json", "blocks_done"],
    );
}

#[test]
fn a_garbage_checkpoint_is_refused() {
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    std::fs::write(d.path().join("run/checkpoint.json"), "{\"format\": tru").unwrap();
    refused(&fit(d.path(), "run", &["--resume"]), &["checkpoint.json"]);
}

#[test]
fn an_old_format_checkpoint_is_refused() {
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    let p = d.path().join("run/checkpoint.json");
    let mut c = json(&p);
    c["format"] = serde_json::json!("scenefit-checkpoint/1");
    std::fs::write(&p, c.to_string()).unwrap();
    refused(
        &fit(d.path(), "run", &["--resume"]),
        &["checkpoint.json", "format"],
    );
}

#[test]
fn zero_generations_is_no_result() {
    let d = setup();
    refused(
        &fit(d.path(), "run", &["--generations", "0"]),
        &["--generations"],
    );
    assert!(!d.path().join("run/result.json").exists());
}

#[test]
fn a_phase_of_zero_generations_is_no_result() {
    let d = setup();
    refused(
        &fit(d.path(), "run", &["--phase-generations", "0"]),
        &["--phase-generations"],
    );
    assert!(!d.path().join("run/result.json").exists());
}

/// Runs `scenefit ARGS` in `dir` through `sh` with a shell prefix (umask,
/// ulimit).
fn scenefit_sh(dir: &Path, prefix: &str, args: &str) -> std::process::Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!(
            "{prefix}; exec '{}' {args}",
            env!("CARGO_BIN_EXE_scenefit")
        ))
        .current_dir(dir)
        .output()
        .unwrap()
}

#[test]
fn outputs_follow_the_umask() {
    let d = setup();
    let out = scenefit_sh(
        d.path(),
        "umask 022",
        "fit scene.json --target target.png -o run --generations 10 --population 10 -q",
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let out = scenefit_sh(d.path(), "umask 022", "render scene.json -o r.png");
    assert!(out.status.success(), "{}", stderr(&out));
    // Every file the run left (a run that converges early snapshots only
    // the generations it reached), and the rendered image.
    let mut files: Vec<String> = std::fs::read_dir(d.path().join("run"))
        .unwrap()
        .flatten()
        .map(|e| format!("run/{}", e.file_name().to_string_lossy()))
        .collect();
    files.sort();
    for f in [
        "run/result.json",
        "run/best.png",
        "run/fitted_scene.json",
        "run/checkpoint.json",
        "run/best_g0000.bmp",
    ] {
        assert!(files.iter().any(|x| x == f), "{f} missing: {files:?}");
    }
    files.push("r.png".into());
    for f in &files {
        let mode = std::fs::metadata(d.path().join(f))
            .unwrap()
            .permissions()
            .mode()
            & 0o777;
        assert_eq!(mode, 0o644, "{f}: {mode:o}");
    }
}

#[test]
fn a_failed_image_write_keeps_the_previous_file() {
    let d = setup();
    let before = std::fs::read(d.path().join("target.png")).unwrap();
    // A file-size limit of 1 KiB: the PNG cannot be written whole (EFBIG).
    let out = scenefit_sh(
        d.path(),
        "trap '' XFSZ; ulimit -f 2",
        "render scene.json -o target.png --width 200 --height 150 --set lights.key.intensity=3",
    );
    assert_ne!(out.status.code(), Some(0), "{}", stderr(&out));
    assert_eq!(
        stderr(&out).trim_end().lines().count(),
        1,
        "{}",
        stderr(&out)
    );
    assert_eq!(std::fs::read(d.path().join("target.png")).unwrap(), before);
    let left: Vec<String> = std::fs::read_dir(d.path())
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n.contains(".tmp"))
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
}

#[test]
fn a_failed_result_write_leaves_no_result() {
    let d = setup();
    // Snapshots and the checkpoint fit in 2 KiB blocks; best.png at this
    // size does not.
    let out = scenefit_sh(
        d.path(),
        "trap '' XFSZ; ulimit -f 8",
        "fit scene.json --target target.png -o run --generations 3 --population 10 -q",
    );
    if out.status.success() {
        // Everything fitted under the limit; then every file is whole.
        assert!(json(&d.path().join("run/result.json"))["params"].is_object());
    } else {
        assert!(
            !d.path().join("run/result.json").exists(),
            "no result after a failed write"
        );
    }
}

#[test]
fn pipeline_refuses_an_earlier_pipeline_without_resume() {
    let d = setup();
    std::fs::create_dir_all(d.path().join("pipe")).unwrap();
    std::fs::write(d.path().join("pipe/comparison.json"), "{}").unwrap();
    let out = scenefit(
        d.path(),
        &[
            "pipeline",
            "scene.json",
            "--target",
            "target.png",
            "-o",
            "pipe",
            "--stage2",
            "povray",
        ],
    );
    refused(&out, &["--resume", "--overwrite"]);
    assert_eq!(
        std::fs::read_to_string(d.path().join("pipe/comparison.json")).unwrap(),
        "{}"
    );
}

#[test]
fn a_finished_fit_keeps_its_population_for_the_report() {
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    let c = json(&d.path().join("run/checkpoint.json"));
    let pop = &c["within"]["search"]["de"]["population"];
    assert_eq!(pop.as_array().map(|p| p.len()), Some(10), "{c}");
}

/// A set of two photographs of the scene (target.png and a copy) in
/// shots.json, for the set fit's run-directory cases.
fn setup_set() -> tempfile::TempDir {
    let d = setup();
    std::fs::copy(d.path().join("target.png"), d.path().join("other.png")).unwrap();
    let shots = r#"{"format": "scenefit-shots/1", "shots": [
        {"name": "a", "target": "target.png"}, {"name": "b", "target": "other.png"}]}"#;
    std::fs::write(d.path().join("shots.json"), shots).unwrap();
    d
}

/// `fit --shots` into `out`, small.
fn fit_set(d: &Path, shots: &str, out: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "fit",
        "scene.json",
        "--shots",
        shots,
        "-o",
        out,
        "--generations",
        "4",
        "--population",
        "10",
        "-q",
    ];
    args.extend_from_slice(extra);
    scenefit(d, &args)
}

#[test]
fn a_set_fit_refuses_an_earlier_set_run_and_resumes_a_finished_one() {
    let d = setup_set();
    assert!(fit_set(d.path(), "shots.json", "run", &[]).status.success());
    let result = std::fs::read(d.path().join("run/result.json")).unwrap();
    refused(
        &fit_set(d.path(), "shots.json", "run", &[]),
        &["checkpoint", "--resume", "--overwrite"],
    );
    let out = fit_set(d.path(), "shots.json", "run", &["--resume"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let again = std::fs::read(d.path().join("run/result.json")).unwrap();
    let params =
        |b: &[u8]| serde_json::from_slice::<serde_json::Value>(b).unwrap()["params"].clone();
    assert_eq!(params(&again), params(&result));
}

#[test]
fn a_set_photograph_the_run_would_overwrite_is_refused() {
    let d = setup_set();
    assert!(fit_set(d.path(), "shots.json", "run", &[]).status.success());
    // The photograph of shot "a" stored in the run directory as the name
    // of a shot's best render.
    std::fs::copy(d.path().join("target.png"), d.path().join("run/best_a.png")).unwrap();
    let kept = std::fs::read(d.path().join("run/best_a.png")).unwrap();
    let shots = r#"{"format": "scenefit-shots/1", "shots": [
        {"name": "a", "target": "run/best_a.png"}, {"name": "b", "target": "other.png"}]}"#;
    std::fs::write(d.path().join("inside.json"), shots).unwrap();
    refused(
        &fit_set(d.path(), "inside.json", "run", &["--overwrite"]),
        &["shot a", "best_a.png", "overwrite"],
    );
    assert_eq!(
        std::fs::read(d.path().join("run/best_a.png")).unwrap(),
        kept
    );
    // The shots file itself inside the run directory, under a run's name
    // (its photographs named from there).
    let shots = r#"{"format": "scenefit-shots/1", "shots": [
        {"name": "a", "target": "../target.png"}, {"name": "b", "target": "../other.png"}]}"#;
    std::fs::write(d.path().join("run/shots.json"), shots).unwrap();
    refused(
        &fit_set(d.path(), "run/shots.json", "run", &["--overwrite"]),
        &["--shots", "shots.json"],
    );
}

#[test]
fn a_planted_lock_symlink_is_refused_and_not_followed() {
    let d = setup();
    std::fs::create_dir(d.path().join("run")).unwrap();
    std::fs::write(d.path().join("victim.txt"), "precious").unwrap();
    std::os::unix::fs::symlink(
        d.path().join("victim.txt"),
        d.path().join("run/.scenefit.lock"),
    )
    .unwrap();
    refused(
        &fit(d.path(), "run", &[]),
        &[".scenefit.lock", "symbolic link"],
    );
    assert_eq!(
        std::fs::read_to_string(d.path().join("victim.txt")).unwrap(),
        "precious"
    );
}

/// `diagnose run -o OUT`, small.
fn diagnose(d: &Path, out: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "diagnose",
        "run",
        "-o",
        out,
        "--population",
        "4",
        "--generations",
        "2",
        "--restart-generations",
        "0",
        "--max-effects",
        "1",
    ];
    args.extend_from_slice(extra);
    scenefit(d, &args)
}

#[test]
fn a_diagnosis_follows_the_run_directory_rule() {
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    let out = diagnose(d.path(), "diag", &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let first = std::fs::read(d.path().join("diag/diagnosis.json")).unwrap();
    // An earlier diagnosis is not silently replaced.
    refused(&diagnose(d.path(), "diag", &[]), &["diag", "--overwrite"]);
    assert_eq!(
        std::fs::read(d.path().join("diag/diagnosis.json")).unwrap(),
        first
    );
    refused(
        &diagnose(d.path(), "diag", &["--resume"]),
        &["--resume", "cannot be resumed"],
    );
    refused(&diagnose(d.path(), "run", &[]), &["fit directory"]);
    // An input under a name the diagnosis writes is not overwritten.
    std::fs::copy(
        d.path().join("target.png"),
        d.path().join("diag/render_after.png"),
    )
    .unwrap();
    let kept = std::fs::read(d.path().join("diag/render_after.png")).unwrap();
    refused(
        &diagnose(
            d.path(),
            "diag",
            &["--overwrite", "--target", "diag/render_after.png"],
        ),
        &["--target", "render_after.png"],
    );
    assert_eq!(
        std::fs::read(d.path().join("diag/render_after.png")).unwrap(),
        kept
    );
    std::fs::remove_file(d.path().join("diag/render_after.png")).unwrap();
    std::fs::write(d.path().join("diag/notes.txt"), "mine").unwrap();
    let out = diagnose(d.path(), "diag", &["--overwrite"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        std::fs::read_to_string(d.path().join("diag/notes.txt")).unwrap(),
        "mine"
    );
}

#[test]
fn two_diagnoses_never_share_a_directory() {
    let d = setup();
    assert!(fit(d.path(), "run", &[]).status.success());
    let bin = env!("CARGO_BIN_EXE_scenefit");
    // A diagnosis long enough for the second to start while it runs.
    let mut first = Command::new(bin)
        .args(["diagnose", "run", "-o", "diag", "--max-effects", "1"])
        .current_dir(d.path())
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    while !d.path().join("diag/.scenefit.lock").exists() && started.elapsed().as_secs() < 30 {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let second = diagnose(d.path(), "diag", &["--overwrite"]);
    assert!(first.wait().unwrap().success());
    refused(&second, &["in use"]);
}

#[test]
fn report_on_a_set_fit_says_what_to_run() {
    let d = setup_set();
    assert!(fit_set(d.path(), "shots.json", "run", &[]).status.success());
    let out = scenefit(d.path(), &["report", "run"]);
    refused(&out, &["set of photographs", "scenefit diagnose"]);
    assert!(!d.path().join("run/report.html").exists());
}
