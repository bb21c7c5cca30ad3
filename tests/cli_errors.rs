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
