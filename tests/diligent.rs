//! The measured DiLiGenT ball (tests/data/diligent_ball): a photograph
//! reduced to 128x96 with its saturated pixels masked out, fitted with
//! scenes/diligent_ball.json, recovers the calibrated light direction; and
//! the diagnosis of a fit with the scene as given (which lacks the
//! photographs' linear response) finds an effect that brings the direction
//! closer.

use scenefit::diagnose::photo;
use scenefit::fit::{self, FitConfig, FitTarget};
use scenefit::metric::Mask;
use scenefit::optimize::DeConfig;
use scenefit::raster::io as image_io;
use scenefit::render::from_spec;
use scenefit::scene::{load, Field, Response, Value};
use std::path::Path;

/// The repository's reduced copy of the data (examples/diligent_data.rs).
fn data() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/diligent_ball")
}

/// Photograph `name` (e.g. "028") at the scene's size and its mask: the
/// ball without the saturated pixels.
fn shot(data: &Path, name: &str) -> (scenefit::raster::Image, Mask) {
    let target = image_io::read_image(&data.join(format!("{name}.png")), "photo").unwrap();
    let mask = Mask::load(
        &data.join(format!("{name}_mask.png")),
        target.width(),
        target.height(),
    )
    .unwrap();
    (target, mask)
}

/// Degrees between the fitted `lights.led.direction` of `scene` and `truth`.
fn angle(scene: &scenefit::scene::Scene, truth: [f64; 3]) -> f64 {
    let Some(Value::Vector(d)) = Field::resolve(scene, "lights.led.direction")
        .unwrap()
        .get(scene)
    else {
        panic!("no direction")
    };
    photo::angle_deg(d, truth)
}

#[test]
fn diagnosis_of_a_photograph_brings_the_light_closer() {
    let data = data();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    // Image 28 of 96: line 28 of light_directions.txt.
    let line = std::fs::read_to_string(data.join("light_directions.txt"))
        .unwrap()
        .lines()
        .nth(27)
        .unwrap()
        .to_string();
    let v: Vec<f64> = line
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect();
    let truth = [v[0], v[1], v[2]];
    let (target, mask) = shot(&data, "028");
    let scene = load(&root.join("scenes/diligent_ball.json")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let config = FitConfig {
        de: DeConfig {
            population: 40,
            seed: 28,
            strategy: scenefit::optimize::Strategy::Shade,
            ..DeConfig::default()
        },
        generations: 150,
        snapshot_every: 1000,
        ..FitConfig::default()
    };
    let t = FitTarget {
        image: target.clone(),
        levels: None,
        mask: Some(mask.clone()),
        path: None,
        encoding: None,
    };
    let phong = from_spec("phong").unwrap();
    let r = fit::run(&scene, &t, phong.as_ref(), &config, dir.path(), &mut ())
        .unwrap()
        .result;
    let fitted = load(&dir.path().join("fitted_scene.json")).unwrap();
    let before = angle(&fitted, truth);
    let inputs = scenefit::diagnose::SetInputs::one(&scenefit::diagnose::Inputs {
        scene: fitted,
        target,
        mask: Some(mask),
    });
    let d = scenefit::diagnose::run(
        &inputs,
        &dir.path().join("diagnose"),
        &scenefit::diagnose::DiagnoseConfig {
            max_rounds: 1,
            seed: 28,
            ..Default::default()
        },
    )
    .unwrap()
    .diagnosis;
    let improved = load(&dir.path().join("diagnose/improved_scene.json")).unwrap();
    let after = angle(&improved, truth);
    let summary = format!(
        "direction {before:.2} -> {after:.2} deg, deviation {:.3} -> {:.3} %, accepted {:?}",
        r.deviation.average, d.deviation_after.average, d.accepted
    );
    eprintln!("{summary}");
    assert!(d.accepted.iter().any(|a| a != "unexplained"), "{summary}");
    assert!(after < 0.75 * before, "{summary}");
    assert!(
        d.deviation_after.average < 0.9 * r.deviation.average,
        "{summary}"
    );
}

#[test]
fn light_direction_of_a_photograph_within_four_degrees() {
    let data = data();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let (target, mask) = shot(&data, "001");
    let ball = Mask::load(&data.join("mask.png"), target.width(), target.height()).unwrap();
    let on_ball = ball.pixels().len();
    assert!(
        mask.pixels().len() < on_ball,
        "saturated pixels stay in the mask"
    );
    assert!(mask.pixels().len() > on_ball / 2);

    let mut scene = load(&root.join("scenes/diligent_ball.json")).unwrap();
    // The photographs store linear values: v^2.2 before sRGB encoding.
    scene.camera.response = Some(Response {
        gamma: 2.2,
        ..Default::default()
    });
    let dir = tempfile::tempdir().unwrap();
    let config = FitConfig {
        de: DeConfig {
            population: 40,
            ..DeConfig::default()
        },
        generations: 150,
        snapshot_every: 1000,
        ..FitConfig::default()
    };
    let t = FitTarget {
        image: target,
        levels: None,
        mask: Some(mask),
        path: None,
        encoding: None,
    };
    let r = fit::run(
        &scene,
        &t,
        from_spec("phong").unwrap().as_ref(),
        &config,
        dir.path(),
        &mut (),
    )
    .unwrap()
    .result;
    let fitted = load(&dir.path().join("fitted_scene.json")).unwrap();
    let err = angle(&fitted, [-0.0635, -0.4317, 0.8998]);
    assert!(
        err < 4.0,
        "angular error {err:.2} deg (deviation {:.3} %)",
        r.deviation.average
    );
    assert!(
        r.deviation.average < 1.0,
        "deviation {:.3} %",
        r.deviation.average
    );
}

#[test]
fn shots_file_names_each_photograph_its_mask_and_its_light_direction() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shots_path = root.join("scenes/diligent_ball/shots_calibrated.json");
    let shots: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&shots_path).unwrap()).unwrap();
    assert_eq!(shots["format"], "scenefit-shots/1");
    let list = shots["shots"].as_array().unwrap();
    let directions = std::fs::read_to_string(data().join("light_directions.txt")).unwrap();
    let directions: Vec<&str> = directions.lines().collect();
    assert_eq!(list.len(), directions.len());
    let base = shots_path.parent().unwrap();
    let scene = load(&root.join("scenes/diligent_ball.json")).unwrap();
    let size = (scene.image.width, scene.image.height);
    for (shot, line) in list.iter().zip(directions) {
        // Paths are relative to the shots file, the images the scene's size.
        let target =
            image_io::read_image(&base.join(shot["target"].as_str().unwrap()), "target").unwrap();
        assert_eq!(target.dimensions(), size, "{}", shot["name"]);
        Mask::load(&base.join(shot["mask"].as_str().unwrap()), size.0, size.1).unwrap();
        let want: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        let got: Vec<f64> = shot["set"]["lights.led.direction"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(got, want, "{}", shot["name"]);
        assert_eq!(shot["encoding"], "srgb");
    }
}
