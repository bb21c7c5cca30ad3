//! Bad input gets one clear line naming the file, key or option and what was
//! expected, and exit code 2; never a panic.

mod common;
use common::*;
use std::path::Path;

fn write(dir: &Path, name: &str, text: &str) -> String {
    std::fs::write(dir.join(name), text).unwrap();
    name.to_string()
}

/// The example scene with one edit made to its JSON.
fn edited(edit: impl FnOnce(&mut serde_json::Value)) -> String {
    let mut v = json(&scenes().join("sphere_floor.json"));
    edit(&mut v);
    v.to_string()
}

/// Asserts a user error: exit code 2, one line, mentioning every `needles`.
fn assert_user_error(out: &std::process::Output, needles: &[&str]) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(2), "exit code; stderr: {err}");
    assert!(
        !err.contains("panicked") && !err.contains("RUST_BACKTRACE"),
        "no panic: {err}"
    );
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "one line: {err}");
    for n in needles {
        assert!(err.contains(n), "stderr should mention {n:?}: {err}");
    }
}

fn render(dir: &Path, scene: &str) -> std::process::Output {
    scenefit(dir, &["render", scene, "-o", "out.png"])
}

#[test]
fn malformed_json_names_file_and_line() {
    let d = tempfile::tempdir().unwrap();
    let f = write(
        d.path(),
        "bad.json",
        "{\"format\": \"scenefit-scene/1\",\n  \"image\": {\"width\": 128,, }",
    );
    assert_user_error(
        &render(d.path(), &f),
        &["bad.json", "line 2", "not valid JSON"],
    );
}

#[test]
fn unknown_key_is_named_with_its_path() {
    let d = tempfile::tempdir().unwrap();
    let f = write(
        d.path(),
        "s.json",
        &edited(|v| v["objects"][0]["material"]["colour"] = serde_json::json!([1, 0, 0])),
    );
    assert_user_error(
        &render(d.path(), &f),
        &["s.json", "objects[0].material", "unknown field `colour`"],
    );
}

#[test]
fn min_above_max_is_rejected() {
    let d = tempfile::tempdir().unwrap();
    let f = write(
        d.path(),
        "s.json",
        &edited(|v| {
            v["free"][1] = serde_json::json!({"param": "lights.key.intensity", "min": 50, "max": 1})
        }),
    );
    assert_user_error(
        &render(d.path(), &f),
        &["s.json", "free[1].max", "max >= min"],
    );
}

#[test]
fn free_parameter_naming_a_missing_object() {
    let d = tempfile::tempdir().unwrap();
    let f = write(
        d.path(),
        "s.json",
        &edited(|v| v["free"][2]["param"] = serde_json::json!("objects.teapot.material.color")),
    );
    assert_user_error(
        &render(d.path(), &f),
        &["s.json", "free[2].param", "no object named \"teapot\""],
    );
}

#[test]
fn negative_radius() {
    let d = tempfile::tempdir().unwrap();
    let f = write(
        d.path(),
        "s.json",
        &edited(|v| v["objects"][0]["shape"]["radius"] = serde_json::json!(-0.5)),
    );
    assert_user_error(
        &render(d.path(), &f),
        &["s.json", "objects[0].shape.radius", "positive"],
    );
}

#[test]
fn degenerate_camera_up_parallel_to_view() {
    let d = tempfile::tempdir().unwrap();
    let f = write(
        d.path(),
        "s.json",
        &edited(|v| {
            v["camera"]["position"] = serde_json::json!([0, 5, 0]);
            v["camera"]["look_at"] = serde_json::json!([0, 0, 0]);
            v["camera"]["up"] = serde_json::json!([0, 1, 0]);
        }),
    );
    assert_user_error(&render(d.path(), &f), &["s.json", "camera.up", "parallel"]);
}

#[test]
fn wrong_type_names_key_and_expectation() {
    let d = tempfile::tempdir().unwrap();
    let f = write(
        d.path(),
        "s.json",
        &edited(|v| v["lights"][0]["intensity"] = serde_json::json!("bright")),
    );
    assert_user_error(
        &render(d.path(), &f),
        &["s.json", "lights[0].intensity", "expected f64"],
    );
}

#[test]
fn missing_scene_file() {
    let d = tempfile::tempdir().unwrap();
    assert_user_error(
        &render(d.path(), "nope.json"),
        &["nope.json", "No such file"],
    );
}

fn fit_args<'a>(scene: &'a str, target: &'a str) -> Vec<&'a str> {
    vec![
        "fit",
        scene,
        "--target",
        target,
        "-o",
        "run",
        "--generations",
        "2",
        "--population",
        "8",
        "-q",
    ]
}

#[test]
fn missing_target() {
    let d = tempfile::tempdir().unwrap();
    let scene = scenes().join("sphere_floor.json");
    let out = scenefit(d.path(), &fit_args(scene.to_str().unwrap(), "missing.png"));
    assert_user_error(&out, &["missing.png", "No such file"]);
}

#[test]
fn truncated_target() {
    let d = tempfile::tempdir().unwrap();
    let scene = scenes().join("sphere_floor.json");
    assert!(scenefit(
        d.path(),
        &["render", scene.to_str().unwrap(), "-o", "t.png"]
    )
    .status
    .success());
    let bytes = std::fs::read(d.path().join("t.png")).unwrap();
    std::fs::write(d.path().join("cut.png"), &bytes[..bytes.len() / 2]).unwrap();
    let out = scenefit(d.path(), &fit_args(scene.to_str().unwrap(), "cut.png"));
    assert_user_error(&out, &["cut.png", "--target", "could not decode"]);
    assert!(
        !d.path().join("run/result.json").exists(),
        "no result from a failed start"
    );
}

#[test]
fn target_of_the_wrong_size() {
    let d = tempfile::tempdir().unwrap();
    let scene = scenes().join("sphere_floor.json");
    let s = scene.to_str().unwrap();
    assert!(scenefit(
        d.path(),
        &[
            "render",
            s,
            "-o",
            "small.png",
            "--width",
            "64",
            "--height",
            "48"
        ]
    )
    .status
    .success());
    let out = scenefit(d.path(), &fit_args(s, "small.png"));
    assert_user_error(&out, &["small.png", "expected 128x96", "got 64x48"]);
}

#[test]
fn bad_option_values() {
    let d = tempfile::tempdir().unwrap();
    let scene = scenes().join("sphere_floor.json");
    let s = scene.to_str().unwrap();
    assert!(scenefit(d.path(), &["render", s, "-o", "t.png"])
        .status
        .success());
    let cases: &[(&[&str], &[&str])] = &[
        (&["--strategy", "simplex"], &["simplex", "rand1bin"]),
        (&["--population", "2"], &["population"]),
        (&["--cr", "1.5"], &["cr"]),
        (&["--generations", "many"], &["--generations", "many"]),
        (&["--jobs", "0"], &["--jobs"]),
    ];
    for (extra, needles) in cases {
        let mut args = vec!["fit", s, "--target", "t.png", "-o", "run", "-q"];
        args.extend_from_slice(extra);
        assert_user_error(&scenefit(d.path(), &args), needles);
    }
    let out = scenefit(
        d.path(),
        &["render", s, "-o", "x.png", "--renderer", "raytracer9000"],
    );
    assert_user_error(&out, &["--renderer raytracer9000", "expected phong"]);
    let out = scenefit(
        d.path(),
        &[
            "render",
            s,
            "-o",
            "x.png",
            "--set",
            "lights.nope.position=[1,2,3]",
        ],
    );
    assert_user_error(&out, &["lights.nope.position", "no entry named \"nope\""]);
}

#[test]
fn set_overrides_a_field() {
    let d = tempfile::tempdir().unwrap();
    let scene = scenes().join("sphere_floor.json");
    let s = scene.to_str().unwrap();
    assert!(scenefit(d.path(), &["render", s, "-o", "a.png"])
        .status
        .success());
    assert!(scenefit(
        d.path(),
        &[
            "render",
            s,
            "-o",
            "b.png",
            "--set",
            "objects.ball.material.color=[0.1,0.2,0.9]"
        ]
    )
    .status
    .success());
    let a = image::open(d.path().join("a.png")).unwrap().to_rgb8();
    let b = image::open(d.path().join("b.png")).unwrap().to_rgb8();
    assert_ne!(a, b, "--set should change the ball's colour");
}

#[test]
fn non_positive_exposure_and_white_balance() {
    let d = tempfile::tempdir().unwrap();
    let f = write(
        d.path(),
        "e.json",
        &edited(|v| v["camera"]["exposure"] = serde_json::json!(0)),
    );
    assert_user_error(
        &render(d.path(), &f),
        &["e.json", "camera.exposure", "positive"],
    );
    let f = write(
        d.path(),
        "w.json",
        &edited(|v| v["camera"]["white_balance"] = serde_json::json!([1, -1, 1])),
    );
    assert_user_error(
        &render(d.path(), &f),
        &["w.json", "camera.white_balance", "positive"],
    );
}

/// Every numeric option of every command, given a negative number, says
/// which option and what it expects (clap used to say only "unexpected
/// argument '-1'").
#[test]
fn negative_numbers_name_their_option() {
    let d = tempfile::tempdir().unwrap();
    let scene = scenes().join("sphere_floor.json");
    let scene = scene.to_str().unwrap();
    let fit = ["fit", scene, "--target", "t.png", "-o", "out"];
    let cases: Vec<(Vec<&str>, &str)> = [
        (vec!["render", scene, "-o", "x.png"], "--seed"),
        (vec!["render", scene, "-o", "x.png"], "--width"),
        (fit.to_vec(), "--rounds"),
        (fit.to_vec(), "--render-timeout"),
        (fit.to_vec(), "--worker-max-renders"),
        (fit.to_vec(), "--workers"),
        (fit.to_vec(), "--population"),
        (fit.to_vec(), "--generations"),
        (fit.to_vec(), "--jobs"),
        (fit.to_vec(), "--stagnation"),
        (fit.to_vec(), "--seed"),
        (fit.to_vec(), "--phase-generations"),
        (vec!["diagnose", "fitdir", "-o", "out"], "--population"),
        (vec!["diagnose", "fitdir", "-o", "out"], "--generations"),
        (
            vec!["diagnose", "fitdir", "-o", "out"],
            "--restart-generations",
        ),
        (vec!["diagnose", "fitdir", "-o", "out"], "--max-effects"),
        (vec!["diagnose", "fitdir", "-o", "out"], "--min-gain"),
        (vec!["diagnose", "fitdir", "-o", "out"], "--seed"),
        (vec!["diagnose", "fitdir", "-o", "out"], "--jobs"),
        (vec!["demo", "-o", "out"], "--population"),
        (vec!["demo", "-o", "out"], "--seed"),
        (
            vec!["pipeline", scene, "--target", "t.png", "-o", "out"],
            "--stage2-fine-renders",
        ),
        (
            vec!["pipeline", scene, "--target", "t.png", "-o", "out"],
            "--stage1-population",
        ),
    ]
    .into_iter()
    .collect();
    for (mut args, flag) in cases {
        args.extend([flag, "-1"]);
        let out = scenefit(d.path(), &args);
        assert_user_error(&out, &[&format!("'-1' for '{flag}"), "expected"]);
    }
    assert!(!d.path().join("out").exists() && !d.path().join("x.png").exists());
}

/// `diagnose --effects` with a name no effect has: one line naming the
/// option, the name and the names there are, before anything is read or
/// written.
#[test]
fn an_unknown_effect_name_is_refused_naming_the_known_ones() {
    let d = tempfile::tempdir().unwrap();
    let args = ["diagnose", "fitdir", "-o", "out", "--effects"];
    for (names, bad) in [("albedo_map,shine", "\"shine\""), ("", "\"\"")] {
        let out = scenefit(d.path(), &[&args[..], &[names]].concat());
        assert_user_error(&out, &["--effects", bad, "albedo_map", "camera_response"]);
    }
    assert!(!d.path().join("out").exists());
}

#[test]
fn a_huge_worker_count_is_refused_by_its_option() {
    let d = tempfile::tempdir().unwrap();
    let scene = scenes().join("sphere_floor.json");
    let out = scenefit(
        d.path(),
        &[
            "fit",
            scene.to_str().unwrap(),
            "--target",
            "t.png",
            "-o",
            "out",
        ]
        .into_iter()
        .chain(["--renderer", "worker:true", "--workers", "1000000000"])
        .collect::<Vec<_>>(),
    );
    assert_user_error(&out, &["--workers", "65536"]);
}

/// A fit directory with the example scene as its fitted scene, and the
/// scene's rendered image as `t.png`.
fn fit_dir_and_target(d: &Path) {
    let scene = scenes().join("sphere_floor.json");
    std::fs::create_dir(d.join("fitdir")).unwrap();
    std::fs::copy(&scene, d.join("fitdir/fitted_scene.json")).unwrap();
    let out = scenefit(d, &["render", scene.to_str().unwrap(), "-o", "t.png"]);
    assert!(out.status.success(), "{}", stderr(&out));
}

/// The memory estimate is checked by every command that renders, before
/// it allocates, and the message names what to lower.
#[test]
fn every_command_checks_memory_first_naming_the_cause() {
    let d = tempfile::tempdir().unwrap();
    fit_dir_and_target(d.path());
    let scene = scenes().join("sphere_floor.json");
    let scene = scene.to_str().unwrap();
    let huge = "100000000000";
    let fit = ["fit", scene, "--target", "t.png", "-o", "out"];
    let cases: [(Vec<&str>, Vec<&str>); 5] = [
        (
            [&fit[..], &["--jobs", huge]].concat(),
            vec!["--jobs", "GiB"],
        ),
        (
            [&fit[..], &["--population", huge]].concat(),
            vec!["--population", "GiB"],
        ),
        (
            vec!["demo", "-o", "out", "--population", huge],
            vec!["--population", "GiB"],
        ),
        (
            vec!["diagnose", "fitdir", "-o", "out", "--population", huge],
            vec!["--population", "GiB"],
        ),
        (
            vec!["diagnose", "fitdir", "-o", "out", "--jobs", huge],
            vec!["--jobs", "GiB"],
        ),
    ];
    for (args, needles) in cases {
        let out = scenefit(d.path(), &args);
        assert_user_error(&out, &needles);
        assert!(!needles[0].is_empty() && !stderr(&out).contains("image.width"));
    }
    assert!(!d.path().join("out").exists());
}

/// `render` at the largest image size needs about 55 GiB: refused, naming
/// the scene key, where the machine has less (else it is a valid render).
#[test]
fn a_render_too_large_for_memory_names_the_image_size() {
    let meminfo = std::fs::read_to_string("/proc/meminfo").unwrap_or_default();
    let avail_kib: f64 = meminfo
        .lines()
        .find(|l| l.starts_with("MemAvailable:"))
        .and_then(|l| l.split_whitespace().nth(1)?.parse().ok())
        .unwrap_or(f64::INFINITY);
    if avail_kib > 50.0 * 1024.0 * 1024.0 {
        eprintln!("skipped: this machine could render 16384x16384");
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let scene = scenes().join("sphere_floor.json");
    let out = scenefit(
        d.path(),
        &[
            "render",
            scene.to_str().unwrap(),
            "-o",
            "x.png",
            "--width",
            "16384",
            "--height",
            "16384",
        ],
    );
    assert_user_error(
        &out,
        &["sphere_floor.json", "image.width", "16384x16384", "GiB"],
    );
    assert!(!d.path().join("x.png").exists());
}

/// A checkpoint whose scene declares another (huge) image is refused on
/// resume before anything of that size is allocated.
#[test]
fn a_resumed_checkpoint_declaring_a_huge_image_is_refused() {
    let d = tempfile::tempdir().unwrap();
    fit_dir_and_target(d.path());
    let scene = scenes().join("sphere_floor.json");
    let fit = |extra: &[&str]| {
        let mut args = vec![
            "fit",
            scene.to_str().unwrap(),
            "--target",
            "t.png",
            "-o",
            "run",
            "-q",
            "--population",
            "8",
        ];
        args.extend(extra);
        scenefit(d.path(), &args)
    };
    let out = fit(&["--generations", "2"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let path = d.path().join("run/checkpoint.json");
    let mut c = json(&path);
    c["base"]["image"] = serde_json::json!({"width": 16384, "height": 16384});
    std::fs::write(&path, c.to_string()).unwrap();
    let out = fit(&["--resume", "--generations", "4"]);
    assert_user_error(&out, &["checkpoint.json", "base.image", "16384x16384"]);
}

/// A shots file that is an array, and a bad value in a shot's `set`: the
/// message names the file, the shot and the key.
#[test]
fn shots_file_errors_name_the_shot_and_key() {
    let d = tempfile::tempdir().unwrap();
    let ball = scenes().join("diligent_ball");
    let scene = ball.join("scene.json");
    let shots = ball.join("shots24.json");
    let mut v = json(&shots);
    for s in v["shots"].as_array_mut().unwrap() {
        for k in ["target", "mask"] {
            let p = ball.join(s[k].as_str().unwrap());
            s[k] = serde_json::json!(p.to_str().unwrap());
        }
    }
    v["shots"][3]["set"] = serde_json::json!({"lights.led.intensity": "bright"});
    write(d.path(), "bad.json", &v.to_string());
    write(d.path(), "array.json", "[1, 2]");
    let fit = |f: &str| {
        let args = ["fit", scene.to_str().unwrap(), "--shots", f, "-o", "out"];
        scenefit(d.path(), &args)
    };
    assert_user_error(
        &fit("bad.json"),
        &["bad.json", "shots[3].set.lights.led.intensity", "string"],
    );
    assert_user_error(
        &fit("array.json"),
        &["array.json", "(top level)", "expected a JSON object"],
    );
}

/// A line of a run directory's slurm-jobs.txt that is not a whole session
/// prefix (`scenefit-` alone matched every scenefit task of the user) is
/// ignored with a warning; a dead session's prefix is still cancelled.
#[test]
fn a_slurm_ledger_line_cancels_only_its_own_session() {
    use std::os::unix::fs::PermissionsExt;
    let d = tempfile::tempdir().unwrap();
    fit_dir_and_target(d.path());
    let bin = d.path().join("bin");
    std::fs::create_dir(&bin).unwrap();
    let log = d.path().join("scancel.log");
    let scripts = [
        (
            "squeue",
            "#!/bin/sh\ncase \"$*\" in *--steps*) exit 0;; esac\necho '101 scenefit-999999999-1-0-1'\necho '202 scenefit-777-5-0-1'\n".to_string(),
        ),
        ("scancel", format!("#!/bin/sh\necho \"$*\" >> {}\n", log.display())),
    ];
    for (name, text) in scripts {
        let p = bin.join(name);
        std::fs::write(&p, text).unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    std::fs::create_dir(d.path().join("run")).unwrap();
    write(
        &d.path().join("run"),
        "slurm-jobs.txt",
        "scenefit-\nscenefit-999999999-1-0-\n",
    );
    let scene = scenes().join("sphere_floor.json");
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_scenefit"))
        .args([
            "fit",
            scene.to_str().unwrap(),
            "--target",
            "t.png",
            "-o",
            "run",
        ])
        .args([
            "--overwrite",
            "-q",
            "--population",
            "4",
            "--generations",
            "1",
        ])
        .current_dir(d.path())
        .env("PATH", path)
        .output()
        .unwrap();
    let err = stderr(&out);
    assert!(err.contains("slurm-jobs.txt: line 1: ignored"), "{err}");
    let cancelled = std::fs::read_to_string(&log).unwrap_or_default();
    assert!(cancelled.contains("101"), "{cancelled} / {err}");
    assert!(!cancelled.contains("202"), "{cancelled}");
}
