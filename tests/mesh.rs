//! Meshes through the command line and the library: the same triangles in
//! binary PLY, ASCII PLY and OBJ render the same image; a fine icosphere
//! renders as the analytic sphere it approximates; a mesh path is taken
//! relative to its scene file and stays found when a fit writes its
//! fitted scene elsewhere.

mod common;
use common::*;
use scenefit::metric::deviation;
use scenefit::render::{from_spec, render_one};
use scenefit::scene::parse;
use serde_json::json;
use std::path::Path;

/// The icosphere written to `path` as binary PLY, ASCII PLY or OBJ (by
/// `format`), with its vertex normals.
fn write_icosphere(path: &Path, level: u32, format: &str) {
    let (v, f) = icosphere::unit_icosphere(level);
    let pos = |n: &[f32; 3]| [0.5 * n[0], 0.5 + 0.5 * n[1], 0.5 * n[2]];
    let mut out = Vec::new();
    if format == "obj" {
        for n in &v {
            let p = pos(n);
            out.extend(
                format!(
                    "v {:?} {:?} {:?}\nvn {:?} {:?} {:?}\n",
                    p[0], p[1], p[2], n[0], n[1], n[2]
                )
                .bytes(),
            );
        }
        for t in &f {
            let [a, b, c] = t.map(|i| i + 1);
            out.extend(format!("f {a}//{a} {b}//{b} {c}//{c}\n").bytes());
        }
        return std::fs::write(path, out).unwrap();
    }
    out.extend(format!("ply\nformat {format} 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n", v.len(), f.len()).bytes());
    for n in &v {
        let p = pos(n);
        if format == "ascii" {
            out.extend(
                format!(
                    "{:?} {:?} {:?} {:?} {:?} {:?}\n",
                    p[0], p[1], p[2], n[0], n[1], n[2]
                )
                .bytes(),
            );
        } else {
            p.iter().chain(n).for_each(|x| out.extend(x.to_le_bytes()));
        }
    }
    for t in &f {
        if format == "ascii" {
            out.extend(format!("3 {} {} {}\n", t[0], t[1], t[2]).bytes());
        } else {
            out.push(3);
            t.iter().for_each(|i| out.extend((*i as i32).to_le_bytes()));
        }
    }
    std::fs::write(path, out).unwrap();
}

/// The ball of sphere_floor.json (direct light, 4x4 antialiasing) with
/// its sphere replaced by `shape`.
fn ball_scene(shape: serde_json::Value) -> serde_json::Value {
    let mut s = json(&scenes().join("sphere_floor.json"));
    s["objects"][0]["shape"] = shape;
    s["render"] = json!({"indirect": false, "antialias": 4});
    s.as_object_mut().unwrap().remove("free");
    s
}

fn render(v: &serde_json::Value) -> scenefit::raster::Image {
    let scene = parse(&v.to_string(), "test scene", &[]).unwrap();
    render_one(from_spec("phong").unwrap().as_ref(), &scene, 0).unwrap()
}

#[test]
fn the_same_triangles_render_alike_from_every_file_format() {
    let d = tempfile::tempdir().unwrap();
    let mut images = Vec::new();
    for (name, format) in [
        ("b.ply", "binary_little_endian"),
        ("a.ply", "ascii"),
        ("m.obj", "obj"),
    ] {
        let p = d.path().join(name);
        write_icosphere(&p, 2, format);
        images.push(render(&ball_scene(json!({"type": "mesh", "file": p}))));
    }
    assert!(images[0] == images[1], "binary and ASCII PLY differ");
    assert!(images[0] == images[2], "PLY and OBJ differ");
}

/// 81,920 triangles with vertex normals against the analytic sphere:
/// within 0.5 % over the image.
#[test]
fn a_fine_icosphere_renders_as_its_sphere() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("ico.ply");
    write_icosphere(&p, 6, "binary_little_endian");
    let mesh = render(&ball_scene(json!({"type": "mesh", "file": p})));
    let sphere = render(&ball_scene(
        json!({"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5}),
    ));
    let dev = deviation(&mesh, &sphere, None).average;
    eprintln!("81,920-triangle icosphere vs sphere: {dev:.3} %");
    assert!(dev <= 0.5, "{dev} %");
    // a coarse one's outline is visibly polygonal: the comparison can fail
    write_icosphere(&p.with_file_name("c.ply"), 1, "binary_little_endian");
    let coarse = render(&ball_scene(
        json!({"type": "mesh", "file": p.with_file_name("c.ply")}),
    ));
    let coarse = deviation(&coarse, &sphere, None).average;
    eprintln!("80-triangle icosphere vs sphere: {coarse:.3} %");
    assert!(coarse > 0.05 && coarse > 10.0 * dev, "{coarse} %");
}

/// The example scene's relative mesh path is found from any working
/// directory, and the fit's fitted scene names it absolutely.
#[test]
fn a_mesh_path_is_relative_to_its_scene_and_absolute_after_a_fit() {
    let d = tempfile::tempdir().unwrap();
    let (scene_dir, cwd) = (d.path().join("in"), d.path().join("cwd"));
    std::fs::create_dir_all(&scene_dir).unwrap();
    std::fs::create_dir_all(&cwd).unwrap();
    for f in ["mesh_blob.json", "mesh_blob.ply"] {
        std::fs::copy(scenes().join(f), scene_dir.join(f)).unwrap();
    }
    let s = scene_dir.join("mesh_blob.json");
    let s = s.to_str().unwrap();
    let o = scenefit(&cwd, &["render", s, "-o", "t.png"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let fit = [
        "fit",
        s,
        "--target",
        "t.png",
        "-o",
        "run",
        "-q",
        "--population",
        "8",
        "--generations",
        "2",
    ];
    let o = scenefit(&cwd, &fit);
    assert!(o.status.success(), "{}", stderr(&o));
    let fitted = json(&cwd.join("run/fitted_scene.json"));
    let file = fitted["objects"][0]["shape"]["file"]
        .as_str()
        .unwrap()
        .to_string();
    assert_eq!(
        Path::new(&file),
        scene_dir.join("mesh_blob.ply").canonicalize().unwrap()
    );
}
