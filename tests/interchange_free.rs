//! `scenefit free`: the fields a scene offers are listed with their
//! default bounds, and `--free GLOB` writes the scene with those fields
//! free at the documented defaults (a point: ± a quarter of its distance
//! from the camera; a fraction: [0, 1]; a positive scale: [v/2, 2v]).

use serde_json::Value;
use std::process::{Command, Output};

fn scenefit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_scenefit"))
        .args(args)
        .output()
        .unwrap()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

const SCENE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/sphere_floor.json");

#[test]
fn the_listing_names_every_field_with_its_value_and_whether_it_is_free() {
    let o = scenefit(&["free", SCENE]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    let line = |p: &str| {
        out.lines()
            .find(|l| l.split_whitespace().next() == Some(p))
            .unwrap_or_else(|| panic!("{p} not listed:\n{out}"))
            .to_string()
    };
    assert!(line("lights.key.position").trim_end().ends_with("yes"));
    assert!(!line("objects.floor.material.specular")
        .trim_end()
        .ends_with("yes"));
    let intensity = line("lights.key.intensity");
    let intensity: Vec<&str> = intensity.split_whitespace().collect();
    assert_eq!(&intensity[1..4], ["10", "5", "20"]);
    // fields the scene lacks (a light's direction, a pinhole's fx) are not offered
    assert!(!out.contains("lights.key.direction") && !out.contains("camera.fx"));
    // a pinhole's calibration is offered, its unused `up` is not
    let o = scenefit(&[
        "free",
        concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/pinhole_crate.json"),
    ]);
    let out = stdout(&o);
    assert!(
        out.contains("camera.distortion.k3") && out.contains("camera.fx"),
        "{out}"
    );
    assert!(!out.contains("camera.up"), "{out}");
}

#[test]
fn globs_free_the_fields_they_match_at_the_default_bounds() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("freed.json");
    let o = scenefit(&[
        "free",
        SCENE,
        "--free",
        "objects.*.material.specular",
        "--free",
        "lights.*.position",
        "--free",
        "objects.b*.shape.radius",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let free = s["free"].as_array().unwrap();
    let entry = |p: &str| {
        free.iter()
            .find(|f| f["param"] == p)
            .unwrap_or_else(|| panic!("{p} not free: {free:?}"))
    };
    for p in [
        "objects.ball.material.specular",
        "objects.floor.material.specular",
    ] {
        assert_eq!(
            (entry(p)["min"].as_f64(), entry(p)["max"].as_f64()),
            (Some(0.0), Some(1.0))
        );
    }
    assert_eq!(
        (
            entry("objects.ball.shape.radius")["min"].as_f64(),
            entry("objects.ball.shape.radius")["max"].as_f64()
        ),
        (Some(0.25), Some(1.0))
    );
    // already free: the scene's own entry is kept, not a second one
    assert_eq!(
        free.iter()
            .filter(|f| f["param"] == "lights.key.position")
            .count(),
        1
    );
    // the written scene renders
    let png = d.path().join("x.png");
    let o = scenefit(&[
        "render",
        out.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--width",
        "16",
        "--height",
        "12",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));

    // a glob that matches nothing, the scene as its own output, no -o
    for (args, want) in [
        (
            vec!["--free", "lights.*.nothing", "-o", out.to_str().unwrap()],
            "matches no field of",
        ),
        (vec!["--free", "ambient", "-o", SCENE], "is the scene read"),
        (vec!["--free", "ambient"], "--output"),
    ] {
        let mut all = vec!["free", SCENE];
        all.extend(args);
        let o = scenefit(&all);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert_eq!(stderr(&o).lines().count(), 1, "{}", stderr(&o));
        assert!(stderr(&o).contains(want), "{}", stderr(&o));
    }
}
