//! The library API (`scenefit::api`) used as a program would use it: a
//! tiny scene rendered, then fitted to that render as one photograph and
//! as a set of two, with no command line and no environment variable.

use scenefit::api::{self, FitConfig, FitTarget, Override, Photographs, RenderOptions, Shot};
use scenefit::fit::set::shots::Entry;
use scenefit::metric::deviation;
use std::path::Path;

/// sphere_floor.json at 32x24 with one sample, its light moved by `x`.
fn scene(x: f64) -> api::Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/sphere_floor.json");
    let set = [
        ("image.width", serde_json::json!(32)),
        ("image.height", serde_json::json!(24)),
        ("render.samples", serde_json::json!(1)),
        ("lights.key.position", serde_json::json!([x, 2.5, 2.5])),
    ];
    let set: Vec<Override> = set
        .into_iter()
        .map(|(path, value)| Override {
            path: path.into(),
            value,
        })
        .collect();
    api::load_scene(&path, &set).unwrap()
}

fn target(image: api::Image) -> FitTarget {
    FitTarget {
        image,
        levels: None,
        mask: None,
        path: None,
        encoding: None,
    }
}

fn config() -> FitConfig {
    let mut c = FitConfig {
        generations: 12,
        jobs: 2,
        ..FitConfig::default()
    };
    c.de.population = 12;
    c.de.seed = 3;
    c
}

#[test]
fn a_scene_rendered_and_fitted_through_the_api_moves_towards_its_photograph() {
    let renderer = api::renderer("phong", &RenderOptions::default()).unwrap();
    let truth = api::render(&scene(1.5), "truth", renderer.as_ref(), 0).unwrap();
    let start = scene(-2.0);
    let before = api::render(&start, "start", renderer.as_ref(), 0).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let request = api::FitRequest {
        scene: &start,
        scene_file: Path::new("sphere_floor.json"),
        inputs: Vec::new(),
        renderer: renderer.as_ref(),
        config: config(),
        rounds: 1,
        joint: false,
    };
    let photos = Photographs::one(&start, target(truth.clone()));
    let fitted = api::fit(request, &photos, dir.path(), &mut ()).unwrap();
    let was = deviation(&truth, &before, None).average;
    let now = fitted.result().deviation.average;
    assert!(now < was, "the fit ended at {now} %, the start was {was} %");
    assert!(fitted.worst().is_none(), "one photograph is not a set");
    // One photograph on its own keeps the single fit's run directory.
    assert!(dir.path().join("checkpoint.json").is_file());
    assert!(dir.path().join("result.json").is_file());
}

#[test]
fn a_set_of_two_photographs_goes_through_the_same_entry_point() {
    let renderer = api::renderer("phong", &RenderOptions::default()).unwrap();
    let start = scene(-2.0);
    let dir = tempfile::tempdir().unwrap();
    let shots: Vec<Shot> = [1.0, 2.0]
        .iter()
        .enumerate()
        .map(|(i, x)| {
            let image = api::render(&scene(*x), "truth", renderer.as_ref(), 0).unwrap();
            let name = format!("s{i}");
            let file = dir.path().join(format!("{name}.png"));
            scenefit::raster::io::write_image(&image, &file).unwrap();
            Shot {
                name: name.clone(),
                scene: start.clone(),
                target: std::sync::Arc::new(FitTarget {
                    path: Some(file.clone()),
                    ..target(image)
                }),
                entry: Entry {
                    name,
                    target: file,
                    mask: None,
                    encoding: None,
                    set: Default::default(),
                    hold_out: false,
                },
            }
        })
        .collect();
    let photos = Photographs { shots, file: None };
    let request = api::FitRequest {
        scene: &start,
        scene_file: Path::new("sphere_floor.json"),
        inputs: Vec::new(),
        renderer: renderer.as_ref(),
        config: config(),
        rounds: 1,
        joint: false,
    };
    let out = dir.path().join("run");
    let fitted = api::fit(request, &photos, &out, &mut ()).unwrap();
    let worst = fitted.worst().expect("a set has a worst photograph");
    assert!(worst >= fitted.result().deviation.average);
    assert_eq!(fitted.result().shots.as_ref().map(Vec::len), Some(2));
    assert!(out.join("checkpoint.json").is_file());
}
