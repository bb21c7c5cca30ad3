//! The default search on landscapes where a few pixels carry the answer,
//! and result.json's `alternatives`, through the command line on the
//! generated scenes of tests/data/basins/ (each target the scene's own
//! render, so its values are the hidden truth):
//! - a dark ball with a mirror-like highlight (shininess 20,000) of a few
//!   pixels: the default search ends with the light within 1 degree;
//! - two lights whose swap renders the same image: every run reports the
//!   swap as its one alternative (the search renders the swapped end of
//!   its descents, `optimize/swaps.rs`), not only the runs whose restarts
//!   happened to land in both basins;
//! - one light free: no run reports `alternatives` (the key is absent);
//! - the report shows an ambiguous run's alternatives side by side.
//!
//! The scenes are 48–64 px with one sample, so that every fit takes about
//! a second; scripts/bench-basins.sh measures 20 seeds against SHADE.

mod common;

use common::{json, scenefit, stderr};
use std::path::{Path, PathBuf};

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/basins")
        .join(format!("{name}.json"))
}

/// Renders `name`'s truth and fits it with the default search; returns
/// result.json and the scene file.
fn fit(dir: &Path, name: &str, seed: u64) -> (serde_json::Value, serde_json::Value) {
    let file = scene(name);
    let file = file.to_str().unwrap();
    let target = dir.join(format!("{name}.png"));
    let target = target.to_str().unwrap();
    let out = scenefit(dir, &["render", file, "-o", target]);
    assert!(out.status.success(), "{}", stderr(&out));
    let run = format!("{name}-{seed}");
    let seed = seed.to_string();
    let out = scenefit(
        dir,
        &[
            "fit", file, "--target", target, "-o", &run, "--seed", &seed, "--jobs", "1",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let scene = json(&scene(name));
    (json(&dir.join(&run).join("result.json")), scene)
}

/// The angle in degrees between two vectors given as JSON arrays.
fn angle(a: &serde_json::Value, b: &serde_json::Value) -> f64 {
    let v = |x: &serde_json::Value| -> Vec<f64> {
        x.as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_f64().unwrap())
            .collect()
    };
    let (a, b) = (v(a), v(b));
    let dot: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
    let norm = |x: &[f64]| x.iter().map(|c| c * c).sum::<f64>().sqrt();
    (dot / norm(&a) / norm(&b))
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

/// A light's value in the scene file.
fn light<'a>(scene: &'a serde_json::Value, name: &str, key: &str) -> &'a serde_json::Value {
    let lights = scene["lights"].as_array().unwrap();
    &lights.iter().find(|l| l["name"] == name).unwrap()[key]
}

#[test]
fn a_mirror_like_highlight_is_found_within_a_degree() {
    let dir = tempfile::tempdir().unwrap();
    for seed in 1..=3 {
        let (result, truth) = fit(dir.path(), "glossy_sphere", seed);
        let off = angle(
            &result["params"]["lights.sun.direction"],
            light(&truth, "sun", "direction"),
        );
        assert!(off <= 1.0, "seed {seed}: the light is {off:.2} degrees off");
    }
}

#[test]
fn swapped_lights_are_reported_as_alternatives() {
    let dir = tempfile::tempdir().unwrap();
    for seed in 1..=6 {
        let (result, truth) = fit(dir.path(), "two_lights", seed);
        let (a, b) = (
            light(&truth, "a", "direction"),
            light(&truth, "b", "direction"),
        );
        let fitted_a = &result["params"]["lights.a.direction"];
        let swapped = |x: &serde_json::Value| angle(x, b) < 2.0;
        let alternatives = result["alternatives"].as_array();
        let alternatives = alternatives.unwrap_or_else(|| panic!("seed {seed}: no alternatives"));
        // Two lengths of one swapped direction are one answer.
        assert_eq!(alternatives.len(), 1, "seed {seed}: {alternatives:?}");
        let deviation = result["deviation"]["average"].as_f64().unwrap();
        for alt in alternatives {
            let other_a = &alt["params"]["lights.a.direction"];
            // One answer has light a where the truth has it, the other
            // where the truth has light b.
            assert!(
                (angle(fitted_a, a) < 2.0 && swapped(other_a))
                    || (swapped(fitted_a) && angle(other_a, a) < 2.0),
                "seed {seed}: {fitted_a} and {other_a} are not the swap of {a} and {b}"
            );
            let alt_deviation = alt["deviation"].as_f64().unwrap();
            assert!(
                alt_deviation <= deviation + 0.01,
                "seed {seed}: {alt_deviation} does not fit alike {deviation}"
            );
        }
    }
}

#[test]
fn one_free_light_has_no_alternatives() {
    let dir = tempfile::tempdir().unwrap();
    for seed in 1..=4 {
        let (result, _) = fit(dir.path(), "one_light", seed);
        assert!(
            result.get("alternatives").is_none(),
            "seed {seed}: {}",
            result["alternatives"]
        );
    }
}

#[test]
fn the_report_shows_alternatives_side_by_side() {
    let dir = tempfile::tempdir().unwrap();
    let run = (1..=6)
        .map(|seed| (seed, fit(dir.path(), "two_lights", seed).0))
        .find(|(_, r)| r.get("alternatives").is_some())
        .map(|(seed, _)| format!("two_lights-{seed}"))
        .expect("a seed of 1..=6 reports alternatives");
    let out = scenefit(dir.path(), &["report", &run]);
    assert!(out.status.success(), "{}", stderr(&out));
    let html = std::fs::read_to_string(dir.path().join(&run).join("report.html")).unwrap();
    assert!(
        html.contains("Answers that fit alike"),
        "no alternatives section"
    );
    assert!(html.contains("Alternative 1"), "no alternative column");
}
