//! Sets of photographs (`fit --shots`, `diagnose` of a set): a generated
//! set of one scene under lights that move from photograph to photograph
//! is fitted jointly (the material shared, each light its own), and each
//! of the diagnosis's effects, planted in every photograph of a set, is
//! found on the set.

mod effects_data;

use scenefit::raster::io::write_image;
use scenefit::render::{from_spec, render_one};
use scenefit::scene::Scene;
use serde_json::{json, Value};
use std::path::Path;
use std::process::Command;

fn scenefit(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_scenefit"))
        .args(args)
        .output()
        .unwrap()
}

/// The light positions of a set's photographs: around the ball, above it.
fn positions(n: usize) -> Vec<[f64; 3]> {
    (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            [
                2.0 * a.cos(),
                3.0 + 0.5 * (2.0 * a).sin(),
                1.0 + 2.0 * a.sin(),
            ]
        })
        .collect()
}

/// `model` with the light's position free per photograph.
fn per_shot_light(model: &Scene) -> Scene {
    let mut m = model.clone();
    for f in &mut m.free {
        if f.param == "lights.key.position" {
            f.per_shot = true;
        }
    }
    m
}

/// Writes a set of `n` photographs of `truth` (light moved per photograph,
/// noise `sigma` levels) and the model's scene into `dir`; returns the
/// path of the shots file and the true light positions.
fn write_set(
    dir: &Path,
    truth: &Scene,
    model: &Scene,
    n: usize,
    sigma: f64,
) -> (String, Vec<[f64; 3]>) {
    let phong = from_spec("phong").unwrap();
    let pos = positions(n);
    let mut shots = Vec::new();
    for (i, p) in pos.iter().enumerate() {
        let mut s = truth.clone();
        s.lights[0].position = Some(*p);
        let mut img = render_one(phong.as_ref(), &s, 0).unwrap();
        effects_data::add_noise(&mut img, sigma, 100 + i as u64);
        let name = format!("s{i}");
        write_image(&img, &dir.join(format!("{name}.png"))).unwrap();
        shots.push(json!({"name": name, "target": format!("{name}.png")}));
    }
    let file = dir.join("shots.json");
    std::fs::write(
        &file,
        json!({"format": "scenefit-shots/1", "shots": shots}).to_string(),
    )
    .unwrap();
    std::fs::write(
        dir.join("model.json"),
        serde_json::to_string(&per_shot_light(model)).unwrap(),
    )
    .unwrap();
    (file.display().to_string(), pos)
}

fn read_json(p: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

#[test]
fn a_set_fit_recovers_the_shared_material_and_every_photographs_light() {
    let dir = tempfile::tempdir().unwrap();
    let c = effects_data::case("none", 0, 1.0, 3, 0.0);
    let (shots, pos) = write_set(dir.path(), &c.truth, &c.model, 4, 0.0);
    let model = dir.path().join("model.json").display().to_string();
    let out = dir.path().join("fit");
    let o = scenefit(&[
        "fit",
        &model,
        "--shots",
        &shots,
        "-o",
        out.to_str().unwrap(),
        "--strategy",
        "hybrid",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r = read_json(&out.join("result.json"));
    assert!(
        r["deviation"]["average"].as_f64().unwrap() < 0.2,
        "{}",
        r["deviation"]
    );
    let color = r["params"]["objects.ball.material.color"]
        .as_array()
        .unwrap();
    for (got, want) in color.iter().zip(c.truth.objects[0].material.color) {
        assert!(
            (got.as_f64().unwrap() - want).abs() < 0.03,
            "ball colour {color:?}"
        );
    }
    assert!(
        r["params"].get("lights.key.position").is_none(),
        "per-shot values are not shared"
    );
    let list = r["shots"].as_array().unwrap();
    assert_eq!(list.len(), 4);
    for (s, want) in list.iter().zip(&pos) {
        let name = s["name"].as_str().unwrap();
        let got: Vec<f64> =
            serde_json::from_value(s["params"]["lights.key.position"].clone()).unwrap();
        let err: f64 = got
            .iter()
            .zip(want)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt();
        assert!(err < 0.15, "shot {name}: light {got:?}, truth {want:?}");
        assert!(s["deviation"]["average"].as_f64().unwrap() < 0.3);
        assert!(out.join(format!("best_{name}.png")).is_file());
    }
    // The shared model, and the photographs with absolute paths for diagnose.
    let fitted = read_json(&out.join("fitted_scene.json"));
    assert_eq!(
        fitted["objects"][0]["material"]["color"],
        r["params"]["objects.ball.material.color"]
    );
    let written = read_json(&out.join("shots.json"));
    assert!(Path::new(written["shots"][0]["target"].as_str().unwrap()).is_absolute());
}

#[test]
fn the_joint_step_lowers_what_a_short_block_descent_leaves() {
    // Block descent on a tiny budget stops well short of the truth; the
    // joint Levenberg–Marquardt block after it (the last entry of
    // checkpoint.json's history) must take most of the rest, moving shared
    // and per-shot values together.
    let dir = tempfile::tempdir().unwrap();
    let c = effects_data::case("none", 1, 1.0, 3, 0.0);
    let (shots, pos) = write_set(dir.path(), &c.truth, &c.model, 4, 0.0);
    let model = dir.path().join("model.json").display().to_string();
    let out = dir.path().join("fit");
    let o = scenefit(&[
        "fit",
        &model,
        "--shots",
        &shots,
        "-o",
        out.to_str().unwrap(),
        "--generations",
        "8",
        "--rounds",
        "1",
        "--joint",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let state = read_json(&out.join("checkpoint.json"));
    // Stored bit-exact: each value's IEEE-754 bits.
    let bits: Vec<u64> = serde_json::from_value(state["history"].clone()).unwrap();
    let history: Vec<f64> = bits.into_iter().map(f64::from_bits).collect();
    eprintln!("set deviation after each block: {history:?}");
    let (before, after) = (history[history.len() - 2], history[history.len() - 1]);
    assert!(
        after < 0.5 * before,
        "the joint block took the set from {before:.3} % to {after:.3} % (history {history:?})"
    );
    let r = read_json(&out.join("result.json"));
    assert!((r["deviation"]["average"].as_f64().unwrap() - after).abs() < 1e-6);
    let worst = r["shots"]
        .as_array()
        .unwrap()
        .iter()
        .zip(&pos)
        .map(|(s, want)| {
            let got: Vec<f64> =
                serde_json::from_value(s["params"]["lights.key.position"].clone()).unwrap();
            got.iter()
                .zip(want)
                .map(|(a, b)| (a - b) * (a - b))
                .sum::<f64>()
                .sqrt()
        })
        .fold(0.0, f64::max);
    assert!(worst < 0.15, "worst light position error {worst:.3}");
}

#[test]
fn a_set_fit_gives_the_same_result_for_any_number_of_jobs() {
    let dir = tempfile::tempdir().unwrap();
    let c = effects_data::case("none", 2, 1.0, 5, 1.0);
    let (shots, _) = write_set(dir.path(), &c.truth, &c.model, 3, 1.0);
    let model = dir.path().join("model.json").display().to_string();
    let run = |jobs: &str| {
        let out = dir.path().join(format!("fit{jobs}"));
        let o = scenefit(&[
            "fit",
            &model,
            "--shots",
            &shots,
            "-o",
            out.to_str().unwrap(),
            "--generations",
            "40",
            "--rounds",
            "1",
            "--jobs",
            jobs,
            "--seed",
            "9",
            "--quiet",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let r = read_json(&out.join("result.json"));
        (r["params"].clone(), r["shots"].clone())
    };
    assert_eq!(run("1"), run("2"));
}

#[test]
fn bad_shots_files_exit_2_naming_the_file_and_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let c = effects_data::case("none", 0, 1.0, 3, 0.0);
    let (_, _) = write_set(dir.path(), &c.truth, &c.model, 2, 0.0);
    let model = dir.path().join("model.json").display().to_string();
    let cases: Vec<(Value, &str)> = vec![
        (json!({"format": "x", "shots": []}), "format"),
        (json!({"format": "scenefit-shots/1", "shots": []}), "shots"),
        (
            json!({"format": "scenefit-shots/1", "shots": [{"name": "a", "target": "nope.png"}]}),
            "nope.png",
        ),
        (
            json!({"format": "scenefit-shots/1", "shots": [{"name": "a b", "target": "s0.png"}]}),
            "shots[0].name",
        ),
        (
            json!({"format": "scenefit-shots/1", "shots": [{"name": "a", "target": "s0.png"}, {"name": "a", "target": "s1.png"}]}),
            "shots[1].name",
        ),
        (
            json!({"format": "scenefit-shots/1", "shots": [{"name": "a", "target": "s0.png", "colour": 1}]}),
            "colour",
        ),
        (
            json!({"format": "scenefit-shots/1", "shots": [{"name": "a", "target": "s0.png", "encoding": "log"}]}),
            "shots[0].encoding",
        ),
        (
            json!({"format": "scenefit-shots/1", "shots": [{"name": "a", "target": "s0.png", "set": {"objects.ball.material.color": [1, 0, 0]}}]}),
            "shared free parameter",
        ),
        (
            json!({"format": "scenefit-shots/1", "shots": [{"name": "a", "target": "s0.png", "set": {"lights.nope.position": [1, 0, 0]}}]}),
            "lights.nope.position",
        ),
    ];
    for (i, (file, expect)) in cases.into_iter().enumerate() {
        let path = dir.path().join(format!("bad{i}.json"));
        std::fs::write(&path, file.to_string()).unwrap();
        let out = dir.path().join(format!("out{i}"));
        let o = scenefit(&[
            "fit",
            &model,
            "--shots",
            path.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "case {i}: {err}");
        assert!(
            err.contains(expect),
            "case {i}: expected {expect:?} in {err}"
        );
        assert_eq!(err.trim().lines().count(), 1, "case {i}: {err}");
        assert!(!out.join("result.json").exists());
    }
}
