//! `fit --nuisance exposure,white_balance`: a photograph's exposure and
//! colour cast are searched with the scene, so a target taken with another
//! exposure and white balance is matched without touching the scene's
//! lights and materials; without the flag the same fit cannot match it.

mod common;

use common::{json, scenefit, scenes, stderr};

/// A sphere_floor scene at 48x36 with nothing free but the key light's
/// intensity (so the nuisance parameters are what must move).
fn scene(dir: &std::path::Path) -> std::path::PathBuf {
    let mut v = json(&scenes().join("sphere_floor.json"));
    v["image"] = serde_json::json!({"width": 48, "height": 36});
    v["free"] = serde_json::json!([
        {"param": "lights.key.intensity", "min": 5, "max": 15}
    ]);
    let p = dir.join("scene.json");
    std::fs::write(&p, v.to_string()).unwrap();
    p
}

fn fit(dir: &std::path::Path, out: &str, extra: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "fit",
        "scene.json",
        "--target",
        "target.png",
        "-o",
        out,
        "--population",
        "30",
        "--generations",
        "120",
        "--strategy",
        "shade",
        "--quiet",
    ];
    args.extend_from_slice(extra);
    let o = scenefit(dir, &args);
    assert!(o.status.success(), "{}", stderr(&o));
    json(&dir.join(out).join("result.json"))
}

#[test]
fn exposure_and_white_balance_are_recovered_as_nuisance() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    scene(dir);
    let o = scenefit(
        dir,
        &[
            "render",
            "scene.json",
            "-o",
            "target.png",
            "--set",
            "camera.exposure=1.4",
            "--set",
            "camera.white_balance=[1.1,1.0,0.8]",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));

    let plain = fit(dir, "plain", &[]);
    let with = fit(dir, "with", &["--nuisance", "exposure,white_balance"]);
    let dev = |r: &serde_json::Value| r["deviation"]["average"].as_f64().unwrap();
    assert!(
        dev(&with) < 0.1,
        "deviation with nuisance parameters {}",
        dev(&with)
    );
    assert!(
        dev(&plain) > 5.0 * dev(&with),
        "without {} with {}",
        dev(&plain),
        dev(&with)
    );
    // Exposure, white balance and intensity share one scale: compare the
    // per-channel products with the truth's (intensity 10).
    let p = &with["params"];
    let e = p["camera.exposure"].as_f64().unwrap();
    let i = p["lights.key.intensity"].as_f64().unwrap();
    for (c, truth) in [1.1, 1.0, 0.8].iter().enumerate() {
        let wb = p["camera.white_balance"][c].as_f64().unwrap();
        let got = e * wb * i / 10.0;
        let want = 1.4 * truth;
        assert!(
            (got / want - 1.0).abs() < 0.03,
            "channel {c}: exposure x balance x intensity/10 = {got}, truth {want}"
        );
    }
}

#[test]
fn unknown_nuisance_is_a_usage_error() {
    let tmp = tempfile::tempdir().unwrap();
    scene(tmp.path());
    let o = scenefit(
        tmp.path(),
        &[
            "fit",
            "scene.json",
            "--target",
            "x.png",
            "-o",
            "o",
            "--nuisance",
            "iso",
        ],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("iso"), "{}", stderr(&o));
}
