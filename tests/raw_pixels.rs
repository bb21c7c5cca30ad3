//! The raw-pixel extension of the worker protocol (docs/plugins.md, "Raw
//! pixels"): a worker that answers `"pixels": "raw"` has its file read as
//! exactly width x height x 3 bytes; a short or long file costs that
//! candidate alone, with a message naming the expected and the actual
//! size; a worker that ignores the offer and writes a PNG still works.

#[path = "backends_common/mod.rs"]
mod common;

use common::*;
use scenefit::render::{from_spec, RenderResult};
use scenefit::scene::{parse, ParamSpace, Scene};

fn rawpix() -> String {
    root().join("tests/plugins/rawpix.py").display().to_string()
}

/// Renders scenes whose light intensities are 1.000, 1.001, ... (the
/// plug-in picks what it writes from the last digit).
fn render_modes(n: usize) -> Vec<RenderResult> {
    let mut v = diffuse_scene(1, 1);
    v["image"] = serde_json::json!({"width": 16, "height": 12});
    let base: Scene = parse(&v.to_string(), "test scene", &[]).expect("test scene is valid");
    let scenes: Vec<Scene> = (0..n)
        .map(|k| {
            let mut s = base.clone();
            s.lights[0].intensity = 1.0 + k as f64 / 1000.0;
            s
        })
        .collect();
    let r = from_spec(&format!("worker:python3 {}", rawpix())).expect("renderer spec");
    let mut session = r
        .session(&base, &ParamSpace::default(), 1)
        .expect("session starts");
    session.render_batch(&scenes, 1)
}

#[test]
fn raw_pixels_are_read_and_a_wrong_size_costs_one_candidate() {
    if !have("python3", "python3") {
        return;
    }
    let r = render_modes(4);
    for i in [0, 3] {
        let img = r[i].as_ref().unwrap_or_else(|f| panic!("render {i}: {f}"));
        assert_eq!((img.width(), img.height()), (16, 12));
        assert!(img.pixels().all(|p| p.0 == [10, 20, 30]), "render {i}");
    }
    let short = r[1].as_ref().map(|_| ()).unwrap_err().to_string();
    assert!(
        short.contains("holds 571 bytes of raw pixels, expected 576 (16x12 RGB"),
        "{short}"
    );
    let long = r[2].as_ref().map(|_| ()).unwrap_err().to_string();
    assert!(
        long.contains("holds 583 bytes of raw pixels, expected 576"),
        "{long}"
    );
}
