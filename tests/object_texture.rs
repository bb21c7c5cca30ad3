//! `albedo_map` in the object's frame: three photographs of a sphere
//! printed with a known colour texture, each with its own camera (known)
//! and its own light, fitted with a flat colour. The diagnosis accepts
//! the map, writes it as a 16-bit linear PNG beside improved_scene.json,
//! which names it by a relative path and renders the diagnosis's render
//! again; the map matches the true texture on the texels it solved, and
//! the texels no photograph sees keep 1 (the scalar colour).

mod common;

use scenefit::render::{from_spec, render_one};
use scenefit::scene::texture::{self, Encoding, TextureRef};
use scenefit::scene::Scene;
use serde_json::{json, Value};
use std::path::Path;
use std::process::Command;

const SHOTS: usize = 3;

/// The true texture's linear value at (u, v): 4 x 2 blocks of three
/// colours (none grey, so the channels differ).
fn truth_at(u: f64, v: f64) -> [f64; 3] {
    const COLOURS: [[f64; 3]; 3] = [[0.9, 0.8, 0.3], [0.3, 0.5, 0.9], [0.7, 0.3, 0.3]];
    let (i, j) = (
        (u.rem_euclid(1.0) * 8.0) as usize,
        (v.rem_euclid(1.0) * 4.0) as usize,
    );
    COLOURS[(i + 2 * j) % 3]
}

/// Writes the true texture, 64 x 32 texels, 16-bit linear.
fn write_truth(path: &Path) {
    let (w, h) = (64u32, 32u32);
    let img = image::ImageBuffer::from_fn(w, h, |x, y| {
        let u = (x as f64 + 0.5) / w as f64;
        let v = 1.0 - (y as f64 + 0.5) / h as f64;
        image::Rgb(truth_at(u, v).map(|c| (c * 65535.0).round() as u16))
    });
    img.save(path).unwrap();
}

fn base_scene() -> Value {
    json!({
        "format": "scenefit-scene/1",
        "image": {"width": 128, "height": 128},
        "camera": {"type": "perspective", "position": [0, 0.6, 4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 35},
        "ambient": [0.03, 0.03, 0.03],
        "lights": [{"name": "key", "type": "directional", "direction": [0.3, 0.5, 1], "intensity": 3}],
        "objects": [{"name": "ball", "shape": {"type": "sphere", "center": [0, 0, 0], "radius": 1},
            "material": {"color": [0.5, 0.5, 0.5], "specular": 0.1, "shininess": 40}}],
        "free": [{"param": "objects.ball.material.color", "min": [0, 0, 0], "max": [1, 1, 1]}]
    })
}

/// Shot i's camera position and light direction.
fn shot(i: usize) -> ([f64; 3], [f64; 3]) {
    let a = (35.0 * (i as f64 - 1.0)).to_radians();
    let b = (50.0 * (i as f64 - 1.0)).to_radians();
    ([4.0 * a.sin(), 0.6, 4.0 * a.cos()], [b.sin(), 0.5, b.cos()])
}

fn run_ok(dir: &Path, args: &[&str]) {
    let o = Command::new(env!("CARGO_BIN_EXE_scenefit"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Renders the photographs and writes the model and the shots file.
fn make_set(dir: &Path) {
    write_truth(&dir.join("truth.png"));
    let mut truth = base_scene();
    truth["objects"][0]["material"]["color"] = json!([1.0, 1.0, 1.0]);
    truth["objects"][0]["material"]["color_map"] =
        json!({"file": dir.join("truth.png"), "encoding": "linear"});
    let truth: Scene = scenefit::scene::parse(&truth.to_string(), "truth.json", &[]).unwrap();
    let phong = from_spec("phong").unwrap();
    let mut list = Vec::new();
    for i in 0..SHOTS {
        let (cam, light) = shot(i);
        let mut s = truth.clone();
        s.lights[0].direction = Some(light);
        s.camera.position = Some(cam);
        let img = render_one(phong.as_ref(), &s, 0).unwrap();
        scenefit::raster::io::write_image(&img, &dir.join(format!("s{i}.png"))).unwrap();
        list.push(
            json!({"name": format!("s{i}"), "target": format!("s{i}.png"),
            "set": {"camera.position": cam, "lights.key.direction": light}}),
        );
    }
    std::fs::write(dir.join("model.json"), base_scene().to_string()).unwrap();
    let shots = json!({"format": "scenefit-shots/1", "shots": list});
    std::fs::write(dir.join("shots.json"), shots.to_string()).unwrap();
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn a_texture_seen_by_three_cameras_is_solved_in_the_objects_frame() {
    let dir = tempfile::tempdir().unwrap();
    // OBJECT_TEXTURE_KEEP=DIR keeps the files in DIR (to look at).
    let kept = std::env::var("OBJECT_TEXTURE_KEEP").map(std::path::PathBuf::from);
    let d = kept.as_deref().unwrap_or(dir.path());
    std::fs::create_dir_all(d).unwrap();
    make_set(d);
    run_ok(
        d,
        &[
            "fit",
            "model.json",
            "--shots",
            "shots.json",
            "-o",
            "fit",
            "--quiet",
        ],
    );
    let mut args = vec!["diagnose", "fit", "-o", "diag", "--max-effects", "1"];
    args.extend(common::QUICK_DIAGNOSE);
    run_ok(d, &args);
    let diagnosis = read_json(&d.join("diag/diagnosis.json"));
    assert_eq!(diagnosis["accepted"][0], "albedo_map", "{diagnosis:#}");

    // The map is named beside the scene, by a relative path.
    let improved = read_json(&d.join("diag/improved_scene.json"));
    let map = &improved["objects"][0]["material"]["color_map"];
    let file = map["file"].as_str().unwrap();
    assert!(
        !Path::new(file).is_absolute() && file.ends_with(".png"),
        "{map}"
    );
    assert_eq!(map["encoding"], "linear");

    // Loaded, it holds the texture times the fitted colour on the texels
    // it solved, and 1 on those no photograph sees (the back, u near 1/4).
    let scene = scenefit::scene::load(&d.join("diag/improved_scene.json")).unwrap();
    let color = scene.objects[0].material.color;
    let t: TextureRef = scene.objects[0].material.color_map.clone().unwrap();
    let hi = t.range()[1] as f32;
    let texels = texture::get(Path::new(t.file()), Encoding::Linear).unwrap();
    let side = texels.width as usize;
    let (mut err, mut solved, mut back) = (0.0, 0, 0);
    for j in 0..side {
        for i in 0..side {
            let v: Vec<f64> = (0..3)
                .map(|c| (texels.values[3 * (j * side + i) + c] * hi) as f64)
                .collect();
            let (u, w) = (
                (i as f64 + 0.5) / side as f64,
                1.0 - (j as f64 + 0.5) / side as f64,
            );
            if (0.15..0.35).contains(&u) {
                back += 1;
                assert!(
                    v.iter().all(|x| (x - 1.0).abs() < 1e-3),
                    "unseen ({i}, {j}): {v:?}"
                );
            }
            if v.iter().any(|x| (x - 1.0).abs() > 1e-3) {
                let truth = truth_at(u, w);
                err += (0..3)
                    .map(|c| (v[c] * color[c] - truth[c]).abs())
                    .sum::<f64>()
                    / 3.0;
                solved += 1;
            }
        }
    }
    let mean = err / solved.max(1) as f64;
    println!("map {side}x{side}: {solved} texels solved, mean absolute error {mean:.4}; {back} unseen kept at 1");
    assert!(
        solved > side * side / 8,
        "{solved} texels solved of {}",
        side * side
    );
    assert!(back > 0);
    assert!(mean < 0.05, "mean absolute error {mean}");

    // improved_scene.json renders the diagnosis's render of each
    // photograph from that photograph's own camera (a set whose cameras
    // differ was once drawn all from the first shot's camera).
    for i in 0..2 {
        let (cam, light) = shot(i);
        let set = |k: &str, v: [f64; 3]| format!("{k}={}", json!(v));
        let c = set("camera.position", cam);
        let l = set("lights.key.direction", light);
        let args = [
            "render",
            "diag/improved_scene.json",
            "-o",
            "again.png",
            "--set",
            &c,
            "--set",
            &l,
        ];
        run_ok(d, &args);
        let a = image::open(d.join("again.png")).unwrap().to_rgb8();
        let b = image::open(d.join(format!("diag/render_after_s{i}.png")))
            .unwrap()
            .to_rgb8();
        let worst = a
            .as_raw()
            .iter()
            .zip(b.as_raw())
            .map(|(x, y)| x.abs_diff(*y))
            .max();
        assert!(
            worst.unwrap() <= 1,
            "shot {i}: improved scene vs render after: {worst:?}"
        );
    }
}
