//! `scenefit export --to mitsuba` and `scenefit import FILE.xml`
//! (docs/interchange.md): an exported scene rendered by Mitsuba itself
//! against scenefit's Mitsuba backend; a Mitsuba scene written here
//! rendered by Mitsuba itself against its import rendered by scenefit's
//! Mitsuba backend and by the built-in tracer; export of the import,
//! imported again, the same scene. Skipped without Mitsuba unless CI=true.

#[path = "backends_common/mod.rs"]
mod common;

use std::path::Path;
use std::process::Command;

fn scenefit(dir: &Path, args: &[&str]) -> String {
    let o = Command::new(common::BIN)
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "scenefit {args:?}: {err}");
    err
}

/// Renders a Mitsuba XML file with Mitsuba itself, as a user would
/// (the variant the backend's worker picks), to an 8-bit sRGB PNG.
fn mitsuba_render(xml: &Path, png: &Path) {
    let dir = xml.parent().unwrap();
    let code = format!(
        "import os, sys, glob\n\
         llvm = sorted(glob.glob('/usr/lib/x86_64-linux-gnu/libLLVM-19.so*'))\n\
         if llvm: os.environ.setdefault('DRJIT_LIBLLVM_PATH', llvm[0])\n\
         import mitsuba as mi\n\
         mi.set_variant('llvm_ad_rgb' if llvm else 'scalar_rgb')\n\
         sys.path.insert(0, {dir:?})\n\
         if os.path.exists(os.path.join({dir:?}, 'scenefit_plugins.py')): import scenefit_plugins\n\
         img = mi.render(mi.load_file({xml:?}))\n\
         mi.Bitmap(img).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, srgb_gamma=True).write({png:?})\n",
        dir = dir.to_str().unwrap(),
        xml = xml.to_str().unwrap(),
        png = png.to_str().unwrap()
    );
    let o = Command::new("python3")
        .args(["-c", &code])
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "mitsuba: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The mean absolute difference of two images, in % of full scale.
fn deviation(a: &Path, b: &Path) -> f64 {
    let a = image::open(a).unwrap().to_rgb8();
    let b = image::open(b).unwrap().to_rgb8();
    assert_eq!(a.dimensions(), b.dimensions());
    let sum: f64 = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| (*x as f64 - *y as f64).abs())
        .sum();
    100.0 * sum / (255.0 * a.as_raw().len() as f64)
}

/// A scene with every kind of thing the export writes: a sphere, a
/// textured quad, a textured box, a posed mesh, a point and a directional light.
fn scene_json() -> String {
    let root = common::root();
    let mesh = root.join("scenes/mesh_blob.ply");
    let tex = root.join("scenes/textured/checker.png");
    format!(
        r#"{{"format": "scenefit-scene/1", "image": {{"width": 96, "height": 72}},
  "camera": {{"type": "perspective", "position": [0, 1.6, 5], "look_at": [0, 0.5, 0], "fov_y_deg": 40}},
  "ambient": [0.03, 0.03, 0.03],
  "render": {{"samples": 16, "indirect": false}},
  "lights": [{{"name": "key", "type": "point", "position": [1.5, 3, 3], "intensity": 12.0, "color": [1, 0.9, 0.8]}},
             {{"name": "sun", "type": "directional", "direction": [-0.4, 1, 0.5], "intensity": 0.6}}],
  "objects": [
    {{"name": "ball", "shape": {{"type": "sphere", "center": [-1.1, 0.5, 0], "radius": 0.5}},
      "material": {{"color": [0.8, 0.3, 0.2], "specular": 0.4, "shininess": 30}}}},
    {{"name": "crate", "shape": {{"type": "box", "min": [0.6, 0, -0.4], "max": [1.4, 0.8, 0.4]}},
      "material": {{"color": [0.3, 0.5, 0.8], "color_map": {{"file": {tex:?}, "scale": [2, 1]}}}}, "transform": {{"rotate_deg": [0, -20, 0]}}}},
    {{"name": "blob", "shape": {{"type": "mesh", "file": {mesh:?}}},
      "transform": {{"scale": [1.1, 0.9, 1.0], "rotate_deg": [0, 25, 5], "translate": [0.1, 0, 0.2]}},
      "material": {{"color": [0.7, 0.7, 0.3], "specular": 0.2, "shininess": 20, "reflection": 0.1}}}},
    {{"name": "floor", "shape": {{"type": "quad", "corner": [-3, 0, 2], "edge_u": [6, 0, 0], "edge_v": [0, 0, -5]}},
      "material": {{"color": [0.8, 0.8, 0.8], "color_map": {{"file": {tex:?}, "scale": [3, 3]}}}}}}
  ]}}"#
    )
}

#[test]
fn an_exported_scene_renders_in_mitsuba_as_the_backend_draws_it() {
    if !common::have_mitsuba() {
        return;
    }
    let dir = common::tempdir();
    let d = dir.path();
    std::fs::write(d.join("scene.json"), scene_json()).unwrap();
    scenefit(
        d,
        &[
            "render",
            "scene.json",
            "--renderer",
            "mitsuba",
            "-o",
            "backend.png",
        ],
    );
    scenefit(d, &["export", "scene.json", "--to", "mitsuba", "-o", "out"]);
    for f in [
        "scene.xml",
        "scenefit_plugins.py",
        "meshes/blob.ply",
        "meshes/crate.ply",
        "textures/floor_color_map.exr",
    ] {
        assert!(d.join("out").join(f).is_file(), "out/{f} written");
    }
    mitsuba_render(&d.join("out/scene.xml"), &d.join("xml.png"));
    let dev = deviation(&d.join("backend.png"), &d.join("xml.png"));
    eprintln!("export: Mitsuba's render of the XML vs the backend's: {dev:.4} %");
    assert!(dev <= 1.0, "deviation {dev} %");
    // a second export into the same, now full, directory is refused
    let o = Command::new(common::BIN)
        .args(["export", "scene.json", "--to", "mitsuba", "-o", "out"])
        .current_dir(d)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}

/// A Mitsuba scene as a user would write it: a PLY mesh placed by its
/// to_world, a rectangle, a point and a directional emitter, a
/// roughplastic and a diffuse with a bitmap.
fn mitsuba_xml() -> String {
    let root = common::root();
    let mesh = root.join("scenes/mesh_blob.ply");
    let tex = root.join("scenes/textured/checker.png");
    format!(
        r#"<scene version="3.0.0">
  <integrator type="direct"/>
  <sensor type="perspective">
    <float name="fov" value="50"/>
    <transform name="to_world"><lookat origin="0, 1.6, 5" target="0, 0.5, 0" up="0, 1, 0"/></transform>
    <sampler type="multijitter"><integer name="sample_count" value="16"/></sampler>
    <film type="hdrfilm"><integer name="width" value="96"/><integer name="height" value="72"/>
      <rfilter type="box"/></film>
  </sensor>
  <emitter type="point" id="lamp"><point name="position" value="1.5, 3, 3"/>
    <rgb name="intensity" value="12, 11, 10"/></emitter>
  <emitter type="directional" id="sky"><vector name="direction" value="0.4, -1, -0.5"/>
    <rgb name="irradiance" value="0.5, 0.5, 0.6"/></emitter>
  <shape type="ply" id="blob">
    <string name="filename" value="{mesh}"/>
    <transform name="to_world"><scale value="0.8"/><translate value="0.3, 0.1, 0"/></transform>
    <bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.2, 0.4, 0.7"/>
      <float name="alpha" value="0.3"/></bsdf>
  </shape>
  <shape type="rectangle" id="floor">
    <transform name="to_world"><rotate x="1" angle="-90"/><scale value="3"/></transform>
    <bsdf type="twosided"><bsdf type="diffuse">
      <texture type="bitmap" name="reflectance"><string name="filename" value="{tex}"/></texture>
    </bsdf></bsdf>
  </shape>
</scene>
"#,
        mesh = mesh.display(),
        tex = tex.display()
    )
}

/// The scene's numbers and structure, file paths reduced to their names.
fn normalised(v: &serde_json::Value) -> serde_json::Value {
    use serde_json::Value;
    match v {
        Value::String(s) if s.contains('/') => Value::String(s.rsplit('/').next().unwrap().into()),
        Value::Array(a) => Value::Array(a.iter().map(normalised).collect()),
        Value::Object(o) => {
            Value::Object(o.iter().map(|(k, x)| (k.clone(), normalised(x))).collect())
        }
        x => x.clone(),
    }
}

/// Every number of `a` within `tol` (relative, or absolute near 0) of `b`'s.
fn same_up_to(a: &serde_json::Value, b: &serde_json::Value, tol: f64, at: &str) {
    use serde_json::Value;
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            assert!((x - y).abs() <= tol * x.abs().max(1.0), "{at}: {x} vs {y}");
        }
        (Value::Array(x), Value::Array(y)) => {
            assert_eq!(x.len(), y.len(), "{at}");
            for (i, (p, q)) in x.iter().zip(y).enumerate() {
                same_up_to(p, q, tol, &format!("{at}[{i}]"));
            }
        }
        (Value::Object(x), Value::Object(y)) => {
            let kx: Vec<_> = x.keys().collect();
            let ky: Vec<_> = y.keys().collect();
            assert_eq!(kx, ky, "{at}");
            for (k, p) in x {
                same_up_to(p, &y[k], tol, &format!("{at}.{k}"));
            }
        }
        (x, y) => assert_eq!(x, y, "{at}"),
    }
}

#[test]
fn an_imported_mitsuba_scene_renders_as_mitsuba_draws_it_and_round_trips() {
    if !common::have_mitsuba() {
        return;
    }
    let dir = common::tempdir();
    let d = dir.path();
    std::fs::write(d.join("user.xml"), mitsuba_xml()).unwrap();
    mitsuba_render(&d.join("user.xml"), &d.join("mitsuba.png"));
    scenefit(d, &["import", "user.xml", "-o", "imported.json"]);
    assert!(d.join("imported_assets/blob.ply").is_file());
    let scene = read_json(&d.join("imported.json"));
    assert_eq!(scene["lights"].as_array().unwrap().len(), 2);
    assert_eq!(scene["objects"].as_array().unwrap().len(), 2);
    scenefit(
        d,
        &[
            "render",
            "imported.json",
            "--renderer",
            "mitsuba",
            "-o",
            "backend.png",
        ],
    );
    scenefit(
        d,
        &[
            "render",
            "imported.json",
            "--renderer",
            "phong",
            "-o",
            "phong.png",
        ],
    );
    let dev_m = deviation(&d.join("mitsuba.png"), &d.join("backend.png"));
    let dev_p = deviation(&d.join("mitsuba.png"), &d.join("phong.png"));
    eprintln!("import: Mitsuba's render vs the imported scene by the mitsuba backend {dev_m:.4} %, by phong {dev_p:.4} %");
    assert!(dev_m <= 1.0, "mitsuba backend: {dev_m} %");
    assert!(dev_p <= 2.0, "phong: {dev_p} %");
    // export of the import, imported again: the same scene
    scenefit(
        d,
        &["export", "imported.json", "--to", "mitsuba", "-o", "again"],
    );
    scenefit(d, &["import", "again/scene.xml", "-o", "again.json"]);
    let twice = read_json(&d.join("again.json"));
    same_up_to(&normalised(&scene), &normalised(&twice), 1e-5, "scene");
}

#[test]
fn what_is_not_a_mitsuba_scene_is_refused_in_one_line() {
    let dir = common::tempdir();
    let d = dir.path();
    std::fs::write(d.join("page.xml"), "<html><body>hi</body></html>").unwrap();
    let o = Command::new(common::BIN)
        .args(["import", "page.xml", "-o", "s.json"])
        .current_dir(d)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("page.xml: no <scene> element"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!d.join("s.json").exists() && !d.join("s_assets").exists());
}
