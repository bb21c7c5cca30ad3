//! Photographs held out of a set's fit (`"hold_out": true`, `--hold-out`):
//! a generated set of one scene, the light moving from photograph to
//! photograph, one photograph held out. It takes no part in the fit (the
//! fit is the same when it is replaced by noise), it is predicted from the
//! fitted model within 1.2x the noise floor, and a wrong name or holding
//! out every photograph is one line, exit 2.

mod effects_data;

use scenefit::metric::deviation;
use scenefit::raster::io::write_image;
use scenefit::render::{from_spec, render_one};
use scenefit::scene::Scene;
use serde_json::{json, Value};
use std::path::Path;
use std::process::{Command, Output};

/// Photographs in the set; the last is the one held out.
const SHOTS: usize = 5;
/// Noise of the photographs, 8-bit levels (one standard deviation).
const SIGMA: f64 = 2.0;

fn scenefit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_scenefit"))
        .args(args)
        .output()
        .unwrap()
}

fn read_json(p: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

/// The light positions: around the ball, above it.
fn positions() -> Vec<[f64; 3]> {
    (0..SHOTS)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / SHOTS as f64;
            [
                2.0 * a.cos(),
                3.0 + 0.5 * (2.0 * a).sin(),
                1.0 + 2.0 * a.sin(),
            ]
        })
        .collect()
}

/// Writes the set's photographs (noisy renders of `truth`, the light moved
/// per photograph), the model with the light free per photograph, and a
/// shots file; returns the noise floor of each photograph (the deviation
/// of the truth's render from it).
fn write_set(dir: &Path, truth: &Scene, model: &Scene) -> Vec<f64> {
    let phong = from_spec("phong").unwrap();
    let mut shots = Vec::new();
    let mut floors = Vec::new();
    for (i, p) in positions().iter().enumerate() {
        let mut s = truth.clone();
        s.lights[0].position = Some(*p);
        let clean = render_one(phong.as_ref(), &s, 0).unwrap();
        let mut img = clean.clone();
        effects_data::add_noise(&mut img, SIGMA, 200 + i as u64);
        floors.push(deviation(&img, &clean, None).average);
        write_image(&img, &dir.join(format!("s{i}.png"))).unwrap();
        shots.push(json!({"name": format!("s{i}"), "target": format!("s{i}.png")}));
    }
    shots[SHOTS - 1]["hold_out"] = json!(true);
    let file = json!({"format": "scenefit-shots/1", "shots": shots});
    std::fs::write(dir.join("shots.json"), file.to_string()).unwrap();
    let mut m = model.clone();
    for f in &mut m.free {
        f.per_shot = f.param == "lights.key.position";
    }
    std::fs::write(dir.join("model.json"), serde_json::to_string(&m).unwrap()).unwrap();
    floors
}

/// Fits the set in `dir` into `dir/out`; result.json.
fn fit(dir: &Path, out: &str, extra: &[&str]) -> Value {
    let (model, shots) = (dir.join("model.json"), dir.join("shots.json"));
    let out = dir.join(out);
    let mut args = vec![
        "fit",
        model.to_str().unwrap(),
        "--shots",
        shots.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--generations",
        "150",
        "--rounds",
        "2",
        "--quiet",
    ];
    args.extend(extra);
    let o = scenefit(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    read_json(&out.join("result.json"))
}

#[test]
fn a_held_out_photograph_is_not_fitted_and_is_predicted_within_the_noise() {
    let dir = tempfile::tempdir().unwrap();
    let c = effects_data::case("none", 0, 1.0, 3, 0.0);
    let floors = write_set(dir.path(), &c.truth, &c.model);
    let r = fit(dir.path(), "fit", &[]);
    let fitted: Vec<&str> = r["shots"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        fitted,
        ["s0", "s1", "s2", "s3"],
        "the held-out one is not fitted"
    );
    let held = r["held_out"].as_array().unwrap();
    assert_eq!(held.len(), 1);
    assert_eq!(held[0]["name"], "s4");
    let predicted = held[0]["deviation_fit"]["average"].as_f64().unwrap();
    let floor = floors[SHOTS - 1];
    eprintln!("held out s4: predicted at {predicted:.4} %, noise floor {floor:.4} %");
    assert!(
        predicted <= 1.2 * floor,
        "s4 predicted at {predicted:.4} %, noise floor {floor:.4} %"
    );
    assert!(held[0]["params"]["lights.key.position"].is_array());
    let out = dir.path().join("fit");
    assert!(out.join("best_s4.png").is_file(), "the prediction's render");
    let written = read_json(&out.join("shots.json"));
    assert_eq!(written["shots"][4]["name"], "s4");
    assert_eq!(written["shots"][4]["hold_out"], true);

    // The held-out photograph replaced by noise: the fit is the same.
    let mut garbage = scenefit::raster::Image::new(64, 48);
    effects_data::add_noise(&mut garbage, 80.0, 7);
    write_image(&garbage, &dir.path().join("s4.png")).unwrap();
    let g = fit(dir.path(), "fit_garbage", &[]);
    assert_eq!(g["params"], r["params"], "the shared model");
    assert_eq!(g["shots"], r["shots"], "every fitted photograph");
    let worse = g["held_out"][0]["deviation_fit"]["average"]
        .as_f64()
        .unwrap();
    assert!(
        worse > 5.0 * predicted,
        "noise is not predicted: {worse:.3} %"
    );
}

#[test]
fn hold_out_names_that_are_wrong_or_every_shot_exit_2_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let c = effects_data::case("none", 0, 1.0, 3, 0.0);
    write_set(dir.path(), &c.truth, &c.model);
    let (model, shots) = (dir.path().join("model.json"), dir.path().join("shots.json"));
    let out = dir.path().join("out");
    let base = [
        "fit",
        model.to_str().unwrap(),
        "--shots",
        shots.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--quiet",
    ];
    let target = dir.path().join("s0.png");
    let alone = [
        "fit",
        model.to_str().unwrap(),
        "--target",
        target.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--hold-out",
        "s0",
    ];
    for (extra, says) in [
        (&["--hold-out", "s1,nope"][..], "nope"),
        (&["--hold-out", "s0,s1,s2,s3"][..], "every photograph"),
        (&[][..], ""),
    ] {
        let o = if says.is_empty() {
            scenefit(&alone)
        } else {
            scenefit(&[&base[..], extra].concat())
        };
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{extra:?}: {err}");
        assert!(
            err.contains("--hold-out") || says == "every photograph",
            "{err}"
        );
        assert!(err.contains(says), "{extra:?}: {err}");
        assert!(!out.join("result.json").exists());
    }
}

#[test]
fn a_set_diagnosis_predicts_the_held_out_photographs_before_and_after() {
    let dir = tempfile::tempdir().unwrap();
    let c = effects_data::case("none", 0, 1.0, 3, 0.0);
    write_set(dir.path(), &c.truth, &c.model);
    fit(dir.path(), "fit", &[]);
    let fit_dir = dir.path().join("fit");
    let diagnose = |out: &str, extra: &[&str]| {
        let out = dir.path().join(out);
        let mut args = vec![
            "diagnose",
            fit_dir.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--population",
            "4",
            "--generations",
            "4",
            "--restart-generations",
            "0",
            "--max-effects",
            "1",
        ];
        args.extend(extra);
        (scenefit(&args), out)
    };
    let (o, out) = diagnose("diag", &["--hold-out", "s0"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let d = read_json(&out.join("diagnosis.json"));
    let after: Vec<&str> = d["shots_after"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(after, ["s1", "s2", "s3"], "held out of every refit");
    let held: Vec<&str> = d["held_out"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(held, ["s0", "s4"], "the diagnosis's and the fit's");
    // The fit's prediction of the shot it held out is its own figure, not
    // a second prediction by the diagnosis's search.
    let fitted = read_json(&fit_dir.join("result.json"));
    assert_eq!(fitted["held_out"][0]["name"], "s4");
    assert_eq!(
        d["held_out"][1]["deviation_fit"], fitted["held_out"][0]["deviation_fit"],
        "result.json's deviation_fit"
    );
    for h in d["held_out"].as_array().unwrap() {
        for key in ["deviation_fit", "deviation_after"] {
            let v = h[key]["average"].as_f64().unwrap();
            assert!(v > 0.0 && v < 2.0, "{key} {v}");
        }
    }
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(page.contains("s4 (held out)"), "the report marks it");
    assert!(out.join("render_after_s4.png").is_file());
    assert!(out.join("residual_after_s4.png").is_file());

    let (o, _) = diagnose("diag2", &["--hold-out", "nope"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("--hold-out") && err.contains("nope"), "{err}");
}

#[test]
fn a_resume_holding_out_other_photographs_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let c = effects_data::case("none", 0, 1.0, 3, 0.0);
    write_set(dir.path(), &c.truth, &c.model);
    let r = fit(dir.path(), "fit", &[]);
    // The same inputs resume (a finished run writes its result again).
    let again = fit(dir.path(), "fit", &["--resume"]);
    assert_eq!(again["held_out"], r["held_out"]);
    let (model, shots) = (dir.path().join("model.json"), dir.path().join("shots.json"));
    let out = dir.path().join("fit");
    let o = scenefit(&[
        "fit",
        model.to_str().unwrap(),
        "--shots",
        shots.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--resume",
        "--hold-out",
        "s3",
        "--quiet",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("held out were [s4], now [s3, s4]"), "{err}");
}
