//! `scenefit import-cameras`: a COLMAP text model written here from known
//! cameras (three lens models, COLMAP's half-pixel centre) comes back as a
//! shots file whose cameras are the known ones; a set fit over that file
//! finds the light as the same fit over hand-written cameras does; an
//! OpenCV calibration YAML is read; bad inputs are refused in one line.

use scenefit::raster::io::write_image;
use scenefit::render::{from_spec, render_one};
use scenefit::scene::pinhole::rodrigues;
use scenefit::scene::Scene;
use serde_json::{json, Value};
use std::path::Path;
use std::process::{Command, Output};

fn scenefit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_scenefit"))
        .args(args)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn read_json(p: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

/// A known camera: fx, fy, cx, cy (OpenCV), rvec, tvec, [k1, k2, p1, p2].
struct Known {
    f: [f64; 4],
    rvec: [f64; 3],
    tvec: [f64; 3],
    k: [f64; 4],
}

/// Three views of the origin from about 5 units, from the left, the
/// front and the right, slightly from above.
fn cameras() -> Vec<Known> {
    vec![
        Known {
            f: [60.0, 60.0, 23.5, 17.5],
            rvec: [3.3, 0.4, -0.1],
            tvec: [0.05, 0.5, 5.3],
            k: [0.0; 4],
        },
        Known {
            f: [58.0, 58.0, 24.2, 17.1],
            rvec: [3.35, 0.1, -0.05],
            tvec: [-0.06, 0.49, 5.32],
            k: [-0.08, 0.0, 0.0, 0.0],
        },
        Known {
            f: [61.0, 59.5, 23.0, 18.0],
            rvec: [3.3, -0.35, 0.12],
            tvec: [0.1, 0.45, 5.25],
            k: [-0.05, 0.01, 0.001, -0.002],
        },
    ]
}

/// The model: a ball on a floor under one point light whose position is
/// free, seen by a pinhole camera that the shots' `set` values replace.
fn model() -> Value {
    json!({
        "format": "scenefit-scene/1",
        "image": {"width": 48, "height": 36},
        "camera": {"type": "pinhole", "fx": 60.0, "fy": 60.0, "cx": 23.5, "cy": 17.5,
                   "rotation": [3.3, 0.0, 0.0], "translation": [0.0, 0.5, 5.3],
                   "distortion": [0.0, 0.0, 0.0, 0.0, 0.0]},
        "ambient": [0.03, 0.03, 0.03],
        "lights": [{"name": "key", "type": "point", "position": [0.0, 2.0, 0.0],
                    "color": [1, 1, 1], "intensity": 12.0}],
        "objects": [
            {"name": "ball", "shape": {"type": "sphere", "center": [0, 0.6, 0], "radius": 0.6},
             "material": {"color": [0.8, 0.5, 0.3], "specular": 0.3, "shininess": 30}},
            {"name": "floor", "shape": {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
             "material": {"color": [0.9, 0.9, 0.9], "diffuse": 0.7}}
        ],
        "free": [{"param": "lights.key.position", "min": [-3, 1, -3], "max": [3, 5, 3]}]
    })
}

const LIGHT: [f64; 3] = [1.2, 3.1, 1.6];

fn set_of(c: &Known) -> serde_json::Map<String, Value> {
    let mut m = serde_json::Map::new();
    for (k, v) in ["fx", "fy", "cx", "cy"].iter().zip(c.f) {
        m.insert(format!("camera.{k}"), json!(v));
    }
    m.insert("camera.rotation".into(), json!(c.rvec));
    m.insert("camera.translation".into(), json!(c.tvec));
    if c.k != [0.0; 4] {
        for (k, v) in ["k1", "k2", "p1", "p2", "k3"]
            .iter()
            .zip([c.k[0], c.k[1], c.k[2], c.k[3], 0.0])
        {
            m.insert(format!("camera.distortion.{k}"), json!(v));
        }
    }
    m
}

/// The photographs (truth: the light at LIGHT), model.json and the
/// hand-written shots file.
fn write_photos(dir: &Path) {
    let phong = from_spec("phong").unwrap();
    let mut truth = model();
    truth["lights"][0]["position"] = json!(LIGHT);
    let mut hand = Vec::new();
    for (i, c) in cameras().iter().enumerate() {
        let mut s = truth.clone();
        for (k, v) in set_of(c) {
            let path: Vec<&str> = k.split('.').collect();
            match path.as_slice() {
                ["camera", "distortion", _] => {
                    s["camera"]["distortion"] = json!([c.k[0], c.k[1], c.k[2], c.k[3], 0.0])
                }
                ["camera", f] => s["camera"][*f] = v,
                _ => unreachable!(),
            }
        }
        let scene: Scene = scenefit::scene::load::from_value(s, "truth").unwrap();
        let img = render_one(phong.as_ref(), &scene, 0).unwrap();
        write_image(&img, &dir.join(format!("images/view_{i}.png"))).unwrap();
        hand.push(json!({"name": format!("view_{i}"), "target": format!("images/view_{i}.png"), "set": set_of(c)}));
    }
    std::fs::write(dir.join("model.json"), model().to_string()).unwrap();
    let shots = json!({"format": "scenefit-shots/1", "shots": hand});
    std::fs::write(dir.join("hand.json"), shots.to_string()).unwrap();
}

/// The COLMAP model of the known cameras: PINHOLE, SIMPLE_RADIAL and
/// OPENCV, principal points in COLMAP's convention (+0.5), the images
/// named as JPEGs (found as the PNGs beside them), empty point lines.
fn write_colmap(dir: &Path) {
    let cs = cameras();
    let c = &cs;
    let cameras_txt = format!(
        "# Camera list with one line of data per camera:\n#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n\
         1 PINHOLE 48 36 {} {} {} {}\n2 SIMPLE_RADIAL 48 36 {} {} {} {}\n3 OPENCV 48 36 {} {} {} {} {} {} {} {}\n",
        c[0].f[0], c[0].f[1], c[0].f[2] + 0.5, c[0].f[3] + 0.5,
        c[1].f[0], c[1].f[2] + 0.5, c[1].f[3] + 0.5, c[1].k[0],
        c[2].f[0], c[2].f[1], c[2].f[2] + 0.5, c[2].f[3] + 0.5, c[2].k[0], c[2].k[1], c[2].k[2], c[2].k[3],
    );
    let mut images_txt = String::from("# Image list with two lines of data per image:\n");
    for (i, k) in c.iter().enumerate() {
        let theta = (k.rvec.iter().map(|a| a * a).sum::<f64>()).sqrt();
        let (s, w) = (theta / 2.0).sin_cos();
        let q = k.rvec.map(|a| a / theta * s);
        images_txt += &format!(
            "{} {w} {} {} {} {} {} {} {} view_{i}.jpg\n{}\n",
            i + 1,
            q[0],
            q[1],
            q[2],
            k.tvec[0],
            k.tvec[1],
            k.tvec[2],
            i + 1,
            if i == 1 { "" } else { "12.5 3.25 -1" }
        );
    }
    std::fs::create_dir_all(dir.join("sparse")).unwrap();
    std::fs::write(dir.join("sparse/cameras.txt"), cameras_txt).unwrap();
    std::fs::write(dir.join("sparse/images.txt"), images_txt).unwrap();
}

fn fit(dir: &Path, shots: &str, out: &str) -> Value {
    let o = scenefit(&[
        "fit",
        dir.join("model.json").to_str().unwrap(),
        "--shots",
        dir.join(shots).to_str().unwrap(),
        "-o",
        dir.join(out).to_str().unwrap(),
        "--strategy",
        "hybrid",
        "--generations",
        "40",
        "--seed",
        "3",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    read_json(&dir.join(out).join("result.json"))
}

fn light_error(r: &Value) -> f64 {
    let got: Vec<f64> = serde_json::from_value(r["params"]["lights.key.position"].clone()).unwrap();
    got.iter()
        .zip(LIGHT)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
        .sqrt()
}

#[test]
fn a_colmap_model_gives_the_known_cameras_and_fits_as_hand_written_ones() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    std::fs::create_dir_all(dir.join("images")).unwrap();
    write_photos(dir);
    write_colmap(dir);
    let out = dir.join("imported.json");
    let o = scenefit(&[
        "import-cameras",
        "--colmap",
        dir.join("sparse").to_str().unwrap(),
        "--images",
        dir.join("images").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--scene",
        dir.join("model.json").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let shots = read_json(&out);
    let hand = read_json(&dir.join("hand.json"));
    for (got, want) in shots["shots"]
        .as_array()
        .unwrap()
        .iter()
        .zip(hand["shots"].as_array().unwrap())
    {
        assert_eq!(got["name"], want["name"]);
        assert_eq!(
            got["target"], want["target"],
            "found as the PNG, relative to the shots file"
        );
        let (g, w) = (
            got["set"].as_object().unwrap(),
            want["set"].as_object().unwrap(),
        );
        assert_eq!(g.keys().collect::<Vec<_>>(), w.keys().collect::<Vec<_>>());
        for (k, wv) in w {
            if k == "camera.rotation" {
                // one rotation has two Rodrigues vectors when |r| > pi
                let m = |v: &Value| rodrigues(serde_json::from_value(v.clone()).unwrap());
                let (a, b) = (m(&g[k]), m(wv));
                for i in 0..3 {
                    assert!(
                        (a[i] - b[i]).length() < 1e-6,
                        "{}: rotation {a:?} against {b:?}",
                        want["name"]
                    );
                }
                continue;
            }
            let flat = |v: &Value| -> Vec<f64> {
                serde_json::from_value(v.clone())
                    .or_else(|_| serde_json::from_value(json!([v])))
                    .unwrap()
            };
            for (a, b) in flat(&g[k]).iter().zip(flat(wv)) {
                assert!(
                    (a - b).abs() < 1e-6,
                    "{}: {k}: {a} against {b}",
                    want["name"]
                );
            }
        }
    }
    let imported = light_error(&fit(dir, "imported.json", "fit_imported"));
    let by_hand = light_error(&fit(dir, "hand.json", "fit_hand"));
    assert!(
        by_hand < 0.1,
        "hand-written cameras: light off by {by_hand}"
    );
    assert!(
        imported < by_hand + 0.02,
        "imported cameras: light off by {imported}, by hand {by_hand}"
    );
    eprintln!("light error: imported {imported:.5}, by hand {by_hand:.5}");
}

#[test]
fn an_opencv_calibration_is_read_and_bad_inputs_are_refused_in_one_line() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    std::fs::create_dir_all(dir.join("images")).unwrap();
    write_photos(dir);
    let yml = dir.join("view_0.yml");
    std::fs::write(&yml, "%YAML:1.0\n---\nimage_width: 48\nimage_height: 36\ncamera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 60., 0., 23.5, 0.,\n       60., 17.5, 0., 0., 1. ]\ndistortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n   data: [ -0.1, 0.02, 0., 0., 0. ]\nrvec: [ 3.3, 0.4, -0.1 ]\ntvec: [ 0.05, 0.5, 5.3 ]\n").unwrap();
    let out = dir.join("cv.json");
    let images = dir.join("images");
    let o = scenefit(&[
        "import-cameras",
        "--opencv",
        yml.to_str().unwrap(),
        "--images",
        images.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = read_json(&out)["shots"][0].clone();
    assert_eq!(s["name"], "view_0");
    assert_eq!(s["set"]["camera.cy"], json!(17.5));
    assert_eq!(s["set"]["camera.distortion.k1"], json!(-0.1));
    assert_eq!(s["set"]["camera.rotation"], json!([3.3, 0.4, -0.1]));

    // a listed photograph missing, a fisheye model, a binary file, a FIFO
    let sparse = dir.join("sparse");
    std::fs::create_dir_all(&sparse).unwrap();
    std::fs::write(sparse.join("cameras.txt"), "1 PINHOLE 48 36 60 60 24 18\n").unwrap();
    std::fs::write(
        sparse.join("images.txt"),
        "1 1 0 0 0 0 0 5 1 nowhere.jpg\n\n",
    )
    .unwrap();
    let run = |args: &[&str]| {
        let mut all = vec!["import-cameras"];
        all.extend_from_slice(args);
        all.extend_from_slice(&[
            "--images",
            images.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        let o = scenefit(&all);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert_eq!(stderr(&o).lines().count(), 1, "{}", stderr(&o));
        stderr(&o)
    };
    let colmap = sparse.to_str().unwrap();
    assert!(run(&["--colmap", colmap]).contains("photograph \"nowhere.jpg\" is not in"));
    std::fs::write(
        sparse.join("cameras.txt"),
        "1 OPENCV_FISHEYE 48 36 60 60 24 18 0 0 0 0\n",
    )
    .unwrap();
    assert!(run(&["--colmap", colmap])
        .contains("cameras.txt: line 1: lens model \"OPENCV_FISHEYE\" is not read"));
    std::fs::write(&yml, [0u8, 159, 146, 150]).unwrap();
    assert!(run(&["--opencv", yml.to_str().unwrap()]).contains("not UTF-8 text"));
    assert!(run(&["--opencv", "/dev/zero"]).contains("a device; expected a regular file"));
    // the output is never one of the inputs
    std::fs::write(sparse.join("cameras.txt"), "1 PINHOLE 48 36 60 60 24 18\n").unwrap();
    let o = scenefit(&[
        "import-cameras",
        "--colmap",
        colmap,
        "--images",
        images.to_str().unwrap(),
        "-o",
        sparse.join("images.txt").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("is an input"), "{}", stderr(&o));
}
