//! `diagnose` holds the shared free parameters that move geometry where the
//! fit put them, lists them in diagnosis.json, and frees them again in
//! improved_scene.json; `--refit-geometry` refits them with the rest.

mod common;

use common::{json, scenefit, scenes, stderr};
use std::path::Path;

const CENTRE: &str = "objects.ball.shape.center";

/// Runs `scenefit` with the words of `line` as its arguments, and checks
/// it succeeded.
fn run(dir: &Path, line: &str) {
    let args: Vec<&str> = line.split_whitespace().collect();
    let o = scenefit(dir, &args);
    assert!(o.status.success(), "{line}: {}", stderr(&o));
}

/// A fit of sphere_floor (small) whose ball's centre is free, to a target
/// with the ball moved.
fn fit_with_free_centre(dir: &Path) {
    let mut s = json(&scenes().join("sphere_floor.json"));
    s["image"] = serde_json::json!({"width": 48, "height": 36});
    s["free"].as_array_mut().unwrap().push(serde_json::json!(
        {"param": CENTRE, "min": [-0.2, 0.3, -0.2], "max": [0.2, 0.7, 0.2]}
    ));
    std::fs::write(dir.join("scene.json"), s.to_string()).unwrap();
    run(
        dir,
        "render scene.json -o target.png --set objects.ball.shape.center=[0.05,0.5,0]",
    );
    run(
        dir,
        "fit scene.json --target target.png -o fit --generations 20 -q",
    );
}

/// A short diagnosis of the fit into `out`; its diagnosis.json.
fn diagnose(dir: &Path, out: &str, extra: &str) -> serde_json::Value {
    run(
        dir,
        &format!(
            "diagnose fit -o {out} --generations 2 --population 8 \
             --restart-generations 0 --max-effects 1 {extra}"
        ),
    );
    json(&dir.join(out).join("diagnosis.json"))
}

#[test]
fn diagnose_holds_fitted_geometry_and_frees_it_again_in_the_improved_scene() {
    let d = tempfile::tempdir().unwrap();
    fit_with_free_centre(d.path());
    let fitted = json(&d.path().join("fit/fitted_scene.json"));
    let centre = fitted["objects"][0]["shape"]["center"].clone();

    let held = diagnose(d.path(), "diag", "");
    assert_eq!(held["held"], serde_json::json!([CENTRE]), "{held}");
    assert_eq!(
        held["params_after"][CENTRE], centre,
        "held at the fit's value"
    );
    let improved = json(&d.path().join("diag/improved_scene.json"));
    assert_eq!(improved["objects"][0]["shape"]["center"], centre);
    let free: Vec<&str> = improved["free"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["param"].as_str().unwrap())
        .collect();
    assert!(free.contains(&CENTRE), "free again: {free:?}");
    let report = std::fs::read_to_string(d.path().join("diag/report.html")).unwrap();
    assert!(report.contains(CENTRE), "the report says what was held");

    let refit = diagnose(d.path(), "diag2", "--refit-geometry");
    assert!(refit.get("held").is_none(), "{refit}");
    assert!(refit["params_after"][CENTRE].is_array());
}
