//! Textures in the object's frame (`material.color_map`, `specular_map`,
//! `shininess_map`; docs/scene-format.md "Textures"), drawn by the
//! built-in tracer: a map of ones draws as the untextured scene on a
//! plane, a sphere, a box and a mesh; the colour map lands where the
//! documented texture coordinates put it (a quad, and a mesh with the
//! same coordinates, alike); the specular map scales the highlight and
//! the shininess map sets its exponent; bad map files are refused in one
//! line naming the key and the file, exit 2. Cheap: 64x48 renders. The
//! agreement of Blender, Mitsuba and POV-Ray with the built-in tracer
//! (96x72) is measured on a scene of every map, the normal map too.

use scenefit::api::{self, Image, RenderOptions};
use serde_json::{json, Value};
use std::path::Path;
use std::process::Command;

/// A scene of one object (`shape`, `material`) in `dir`, lit by a point
/// light and a little ambient, seen from +z; written to scene.json.
fn scene(dir: &Path, shape: Value, material: Value, ortho: bool) -> std::path::PathBuf {
    let camera = if ortho {
        json!({"type": "orthographic", "position": [0, 0, 5], "look_at": [0, 0, 0], "height": 2.0})
    } else {
        json!({"type": "perspective", "position": [0.3, 1.4, 4], "look_at": [0, 0.3, 0], "fov_y_deg": 45})
    };
    let s = json!({
        "format": "scenefit-scene/1",
        "image": {"width": 64, "height": 48},
        "camera": camera,
        "ambient": [0.1, 0.1, 0.1],
        "lights": [{"name": "key", "type": "point", "position": [1.0, 2.5, 3.0], "intensity": 8.0}],
        "objects": [{"name": "thing", "shape": shape, "material": material}]
    });
    let p = dir.join("scene.json");
    std::fs::write(&p, serde_json::to_string_pretty(&s).unwrap()).unwrap();
    p
}

fn render(path: &Path) -> Image {
    let scene = api::load_scene(path, &[]).unwrap();
    let phong = api::renderer("phong", &RenderOptions::default()).unwrap();
    api::render(&scene, "test", phong.as_ref(), 0).unwrap()
}

/// A PNG of `w` x `h` with texel (i, j) = f(i, j), 8-bit RGB.
fn png(path: &Path, w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 3]) {
    image::RgbImage::from_fn(w, h, |i, j| image::Rgb(f(i, j)))
        .save(path)
        .unwrap();
}

/// The largest difference of one channel, and the mean, in 8-bit codes.
fn diff(a: &Image, b: &Image) -> (u8, f64) {
    let d: Vec<u8> = a
        .iter()
        .zip(b.iter())
        .map(|(x, y)| x.abs_diff(*y))
        .collect();
    let mean = d.iter().map(|&x| x as f64).sum::<f64>() / d.len() as f64;
    (*d.iter().max().unwrap(), mean)
}

/// A quad of 2 x 2 m facing +z as an OBJ with texture coordinates: the
/// quad shape's own parametrisation (corner (-1,-1,0), u along +x, v +y).
fn quad_obj(dir: &Path) -> String {
    let p = dir.join("quad.obj");
    std::fs::write(
        &p,
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    )
    .unwrap();
    p.display().to_string()
}

fn shapes(dir: &Path) -> Vec<(&'static str, Value)> {
    let file = quad_obj(dir);
    vec![
        (
            "plane",
            json!({"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]}),
        ),
        (
            "sphere",
            json!({"type": "sphere", "center": [0, 0.5, 0], "radius": 0.6}),
        ),
        (
            "box",
            json!({"type": "box", "min": [-0.5, 0, -0.5], "max": [0.5, 0.8, 0.5]}),
        ),
        ("mesh", json!({"type": "mesh", "file": file})),
    ]
}

#[test]
fn a_map_of_ones_draws_as_the_untextured_scene() {
    let d = tempfile::tempdir().unwrap();
    png(&d.path().join("ones.png"), 4, 4, |_, _| [255, 255, 255]);
    for (name, shape) in shapes(d.path()) {
        let plain = json!({"color": [0.7, 0.5, 0.3], "specular": 0.4, "shininess": 30});
        let a = render(&scene(d.path(), shape.clone(), plain, false));
        let mapped = json!({"color": [0.7, 0.5, 0.3], "specular": 0.4, "shininess": 30,
            "color_map": "ones.png", "specular_map": "ones.png",
            "shininess_map": {"file": "ones.png", "range": [0, 30]}});
        let b = render(&scene(d.path(), shape, mapped, false));
        let (max, mean) = diff(&a, &b);
        // the specular terms are summed apart with maps: rounding only
        assert!(max <= 1 && mean < 0.05, "{name}: max {max}, mean {mean}");
        let lit = a.pixels().filter(|p| p.0.iter().any(|&c| c > 40)).count();
        assert!(lit > 200, "{name}: {lit} lit pixels");
    }
}

/// Texel quadrants: top left red, top right green, bottom left blue,
/// bottom right white (8x8, linear), on a quad and on a mesh with the
/// same coordinates, lit by ambient only (the image is the texture).
#[test]
fn the_colour_map_lands_where_the_documented_coordinates_put_it() {
    let d = tempfile::tempdir().unwrap();
    png(&d.path().join("q.png"), 8, 8, |i, j| match (i < 4, j < 4) {
        (true, true) => [255, 0, 0],
        (false, true) => [0, 255, 0],
        (true, false) => [0, 0, 255],
        (false, false) => [255, 255, 255],
    });
    let quad =
        json!({"type": "quad", "corner": [-1, -1, 0], "edge_u": [2, 0, 0], "edge_v": [0, 2, 0]});
    let mesh = json!({"type": "mesh", "file": quad_obj(d.path())});
    let mut images = Vec::new();
    for shape in [quad, mesh] {
        let m = json!({"color": [1, 1, 1], "color_map": {"file": "q.png", "encoding": "linear"}});
        let p = scene(d.path(), shape, m, true);
        let mut s: Value = serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
        s["ambient"] = json!([1, 1, 1]);
        s["lights"][0]["intensity"] = json!(0.0);
        std::fs::write(&p, s.to_string()).unwrap();
        images.push(render(&p));
    }
    // the quad spans 2 m of the 2 m high view: x in [8, 56) of 64
    let at = |img: &Image, x: u32, y: u32| img.get_pixel(x, y).0;
    for img in &images {
        assert_eq!(at(img, 18, 10), [255, 0, 0]);
        assert_eq!(at(img, 45, 10), [0, 255, 0]);
        assert_eq!(at(img, 18, 37), [0, 0, 255]);
        assert_eq!(at(img, 45, 37), [255, 255, 255]);
    }
    let (max, _) = diff(&images[0], &images[1]);
    assert!(max <= 1, "quad and mesh differ by {max}");
}

#[test]
fn the_specular_map_scales_the_highlight_and_the_shininess_map_sets_its_exponent() {
    let d = tempfile::tempdir().unwrap();
    png(&d.path().join("half.png"), 2, 2, |_, _| [128, 128, 128]);
    let ball = json!({"type": "sphere", "center": [0, 0.5, 0], "radius": 0.6});
    let m = |extra: Value| {
        let mut m = json!({"color": [0.5, 0.5, 0.5], "specular": 0.8, "shininess": 20});
        m.as_object_mut()
            .unwrap()
            .extend(extra.as_object().unwrap().clone());
        m
    };
    let half = 128.0 / 255.0;
    let scaled = render(&scene(
        d.path(),
        ball.clone(),
        m(json!({"specular": 0.8 * half})),
        false,
    ));
    let mapped = render(&scene(
        d.path(),
        ball.clone(),
        m(json!({"specular_map": {"file": "half.png", "encoding": "linear"}})),
        false,
    ));
    let (max, _) = diff(&scaled, &mapped);
    assert!(max <= 1, "specular map vs scalar: {max}");
    // range [0, 2 n]: the grey 128/255 means an exponent of ~n
    let n = 60.0;
    let exact = render(&scene(
        d.path(),
        ball.clone(),
        m(json!({"shininess": n * 2.0 * half})),
        false,
    ));
    let sharp =
        json!({"shininess_map": {"file": "half.png", "encoding": "linear", "range": [0, 2.0 * n]}});
    let mapped = render(&scene(d.path(), ball.clone(), m(sharp), false));
    let (max, _) = diff(&exact, &mapped);
    assert!(max <= 1, "shininess map vs scalar: {max}");
    let plain = render(&scene(d.path(), ball, m(json!({})), false));
    assert!(diff(&plain, &mapped).0 > 10, "the exponent changed nothing");
}

fn run(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_scenefit"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn bad_map_files_are_refused_in_one_line_naming_the_key_and_the_file() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("notes.png"), "not an image").unwrap();
    std::fs::write(
        d.path().join("huge.png"),
        helpers::png_header(100_000, 100_000),
    )
    .unwrap();
    std::fs::write(
        d.path().join("bare.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    png(&d.path().join("ok.png"), 2, 2, |_, _| [9, 9, 9]);
    png(&d.path().join("zero.png"), 2, 2, |_, _| [0, 0, 0]);
    let sphere = json!({"type": "sphere", "center": [0, 0.5, 0], "radius": 0.6});
    let cases = [
        (
            sphere.clone(),
            json!({"color_map": "missing.png"}),
            "missing.png",
        ),
        (
            sphere.clone(),
            json!({"specular_map": "notes.png"}),
            "could not decode",
        ),
        (
            sphere.clone(),
            json!({"color_map": "huge.png"}),
            "100000x100000",
        ),
        (
            sphere.clone(),
            json!({"color_map": {"file": "ok.png", "tile": 2}}),
            "expected an image file's path",
        ),
        (
            json!({"type": "mesh", "file": "bare.obj"}),
            json!({"color_map": "ok.png"}),
            "no texture coordinates",
        ),
        (
            sphere,
            json!({"shininess_map": "zero.png"}),
            "expected exponents above 0",
        ),
    ];
    for (shape, map, expect) in cases {
        let mut m = json!({"color": [0.5, 0.5, 0.5]});
        m.as_object_mut()
            .unwrap()
            .extend(map.as_object().unwrap().clone());
        let key = map.as_object().unwrap().keys().next().unwrap().clone();
        scene(d.path(), shape, m, false);
        let o = run(d.path(), &["render", "scene.json", "-o", "out.png"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{key}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains("scene.json") && err.contains(&key), "{err}");
        assert!(err.contains(expect), "{expect}: {err}");
        assert!(!d.path().join("out.png").exists());
    }
    // the same scene with a valid map renders
    let ok = json!({"color": [0.5, 0.5, 0.5], "color_map": "ok.png"});
    scene(
        d.path(),
        json!({"type": "sphere", "center": [0, 0.5, 0], "radius": 0.6}),
        ok,
        false,
    );
    let o = run(d.path(), &["render", "scene.json", "-o", "out.png"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[path = "backends_common/mod.rs"]
mod common;
#[path = "common/mod.rs"]
mod helpers;

/// A floor (colour map, tiled), a ball (colour, specular and shininess
/// maps, turned), a wall mesh (OBJ) and a panel mesh (PLY) with their own
/// coordinates (colour map), direct light only; the maps those of
/// scenes/textured/.
fn agreement_scene(dir: &Path) -> std::path::PathBuf {
    let tex = common::root().join("scenes/textured");
    let (checker, stripes) = (tex.join("checker.png"), tex.join("stripes.png"));
    let wall = dir.join("wall.obj");
    std::fs::write(
        &wall,
        "v -1.5 0 -1.2\nv 1.5 0 -1.2\nv 1.5 1.6 -1.2\nv -1.5 1.6 -1.2\nvt 0 0\nvt 2 0\nvt 2 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    )
    .unwrap();
    // a PLY quad on the right, facing the camera, its coordinates u v
    let side = dir.join("side.ply");
    std::fs::write(
        &side,
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n0.7 0.1 0.3 0 0\n1.3 0.1 0.5 1 0\n1.3 1.1 0.5 1 1\n0.7 1.1 0.3 0 1\n3 0 1 2\n3 0 2 3\n",
    )
    .unwrap();
    let s = json!({
        "format": "scenefit-scene/1",
        "image": {"width": 96, "height": 72},
        "camera": {"type": "perspective", "position": [0.2, 1.5, 4], "look_at": [0, 0.5, 0], "fov_y_deg": 40},
        "render": {"samples": 64, "indirect": false, "antialias": 4},
        "lights": [{"name": "key", "type": "point", "position": [1.5, 3, 3], "intensity": 12.0}],
        "objects": [
            {"name": "ball", "shape": {"type": "sphere", "center": [0, 0, 0], "radius": 0.5},
             "transform": {"rotate_deg": [0, 30, 0], "translate": [0, 0.5, 0]},
             "material": {"color": [0.9, 0.9, 0.9], "specular": 0.4, "shininess": 30,
                "color_map": checker, "specular_map": {"file": stripes, "scale": [2, 1]},
                "shininess_map": {"file": stripes, "range": [5, 60]}}},
            {"name": "floor", "shape": {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
             "material": {"color": [0.8, 0.8, 0.8], "color_map": {"file": checker, "scale": [0.5, 0.5]}}},
            {"name": "wall", "shape": {"type": "mesh", "file": wall},
             "material": {"color": [0.7, 0.7, 0.7], "color_map": checker}},
            {"name": "side", "shape": {"type": "mesh", "file": side},
             "material": {"color": [0.9, 0.9, 0.9], "color_map": checker}}
        ]
    });
    let p = dir.join("agree.json");
    std::fs::write(&p, s.to_string()).unwrap();
    p
}

/// The agreement scene with its ball's shape replaced by a turned box
/// (for the backends that draw maps on a box).
fn with_box(path: &Path) -> std::path::PathBuf {
    let mut s: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    s["objects"][0]["shape"] =
        json!({"type": "box", "min": [-0.4, -0.4, -0.4], "max": [0.4, 0.4, 0.4]});
    let p = path.with_file_name("agree_box.json");
    std::fs::write(&p, s.to_string()).unwrap();
    p
}

/// The agreement scene with bumps (a tangent-space normal map made by
/// the test, slopes up to 21 degrees): on the turned ball, the floor,
/// the wall mesh and a tilted quad with a highlight.
fn with_normal_maps(path: &Path) -> std::path::PathBuf {
    let bumps = path.with_file_name("bumps.png");
    helpers::bumps::write(&bumps, 64, 0.06);
    let mut s: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    for (i, scale) in [(0, [4.0, 2.0]), (1, [0.7, 0.7]), (2, [1.0, 1.0])] {
        s["objects"][i]["material"]["normal_map"] = json!({"file": bumps, "scale": scale});
    }
    s["objects"].as_array_mut().unwrap().push(json!({"name": "tile",
        "shape": {"type": "quad", "corner": [-1.6, 0.05, 0.4], "edge_u": [0.8, 0, 0.3], "edge_v": [0, 0.9, 0]},
        "material": {"color": [0.9, 0.7, 0.5], "specular": 0.3, "shininess": 20,
            "normal_map": {"file": bumps, "scale": [2, 2]}}}));
    let p = path.with_file_name("agree_normal.json");
    std::fs::write(&p, s.to_string()).unwrap();
    p
}

/// The deviation (%) of `backend`'s render of the scene at `path` from
/// the built-in tracer's; the images saved when SCENEFIT_TEXTURE_IMAGES
/// names a folder.
fn agreement(path: &Path, backend: &str) -> f64 {
    let scene = api::load_scene(path, &[]).unwrap();
    let phong = api::renderer("phong", &RenderOptions::default()).unwrap();
    let other = api::renderer(backend, &RenderOptions::default()).unwrap();
    let a = api::render(&scene, "phong", phong.as_ref(), 0).unwrap();
    let b = api::render(&scene, backend, other.as_ref(), 7).unwrap();
    if let Ok(out) = std::env::var("SCENEFIT_TEXTURE_IMAGES") {
        let stem = path.file_stem().unwrap().to_string_lossy();
        a.save(Path::new(&out).join(format!("{stem}_phong.png")))
            .unwrap();
        b.save(Path::new(&out).join(format!("{stem}_{backend}.png")))
            .unwrap();
    }
    let dev = scenefit::metric::deviation(&a, &b, None).average;
    eprintln!(
        "{backend} vs phong, {}: deviation {dev:.3} %",
        path.display()
    );
    dev
}

/// Mitsuba draws the colour, specular and shininess maps of a plane, a
/// turned sphere and meshes (OBJ and PLY) as the built-in tracer does,
/// and on a turned box too (its cube's coordinates replaced by
/// scenefit's per face): within 1 % over each image.
#[test]
fn mitsuba_draws_the_maps_as_the_built_in_tracer_does() {
    if !common::have_mitsuba() {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let p = agreement_scene(d.path());
    for path in [p.clone(), with_box(&p)] {
        let dev = agreement(&path, "mitsuba");
        assert!(dev <= 1.0, "{}: {dev:.3} %", path.display());
    }
}

/// POV-Ray draws the colour, specular and shininess maps on a turned box
/// (as its six faces, each a polygon with the texture placed on it) as
/// the built-in tracer does: within 1 % over the image, and within a
/// quarter of what the box's maps themselves change.
#[test]
fn povray_draws_the_maps_on_a_box_as_the_built_in_tracer_does() {
    if !common::have("povray", "POV-Ray") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let p = with_box(&agreement_scene(d.path()));
    let dev = agreement(&p, "povray");
    let scene = api::load_scene(&p, &[]).unwrap();
    let mut bare = scene.clone();
    let m = &mut bare.objects[0].material;
    (m.color_map, m.specular_map, m.shininess_map) = (None, None, None);
    let phong = api::renderer("phong", &RenderOptions::default()).unwrap();
    let [a, b] = [&scene, &bare].map(|s| api::render(s, "phong", phong.as_ref(), 0).unwrap());
    let effect = scenefit::metric::deviation(&a, &b, None).average;
    eprintln!("the box's maps' own effect: {effect:.3} %");
    assert!(
        dev <= 1.0 && dev < 0.25 * effect,
        "POV-Ray {dev:.3} %, the box's maps' own effect {effect:.3} %"
    );
}

/// POV-Ray draws the colour, specular and shininess maps as the
/// built-in tracer does (the agreement scene, its ball holding all
/// three; a quad holding the colour and specular maps, another the
/// specular and shininess maps, at different scales), on a plane, a
/// turned sphere, quads and meshes: within 1 %, and within half what
/// the shininess maps change.
#[test]
fn povray_draws_the_colour_specular_and_shininess_maps_as_the_built_in_tracer_does() {
    if !common::have("povray", "POV-Ray") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let p = agreement_scene(d.path());
    let mut s: Value = serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
    let checker = common::root().join("scenes/textured/checker.png");
    let stripes = common::root().join("scenes/textured/stripes.png");
    s["objects"].as_array_mut().unwrap().push(json!({"name": "tile",
        "shape": {"type": "quad", "corner": [-1.6, 0.05, 0.4], "edge_u": [0.8, 0, 0.3], "edge_v": [0, 0.9, 0]},
        "material": {"color": [0.9, 0.7, 0.5], "specular": 0.5, "shininess": 40,
            "color_map": {"file": checker, "scale": [1, 1.5]}, "specular_map": {"file": stripes, "scale": [2, 1]}}}));
    s["objects"].as_array_mut().unwrap().push(json!({"name": "tile2",
        "shape": {"type": "quad", "corner": [0.9, 0.05, 0.9], "edge_u": [0.8, 0, -0.3], "edge_v": [0, 0.9, 0]},
        "material": {"color": [0.5, 0.6, 0.7], "specular": 0.5, "shininess": 40,
            "specular_map": {"file": stripes, "scale": [2, 1]},
            "shininess_map": {"file": stripes, "range": [10, 80], "scale": [1, 3]}}}));
    let p = d.path().join("agree_pov.json");
    std::fs::write(&p, s.to_string()).unwrap();
    let dev = agreement(&p, "povray");
    assert!(dev <= 1.0, "{dev:.3} %");
    // The exponent maps move only the highlights, a small part of the
    // image: on the objects that hold them alone, POV-Ray's render is
    // also nearer the built-in tracer's with them than the built-in
    // tracer's without them is.
    let mut scene = api::load_scene(&p, &[]).unwrap();
    scene.objects.retain(|o| o.material.shininess_map.is_some());
    let mut without = scene.clone();
    without
        .objects
        .iter_mut()
        .for_each(|o| o.material.shininess_map = None);
    let render = |s: &api::Scene, backend: &str| {
        let r = api::renderer(backend, &RenderOptions::default()).unwrap();
        api::render(s, backend, r.as_ref(), 0).unwrap()
    };
    let phong = render(&scene, "phong");
    let pov = scenefit::metric::deviation(&render(&scene, "povray"), &phong, None).average;
    let moved = scenefit::metric::deviation(&render(&without, "phong"), &phong, None).average;
    eprintln!("the shininess maps' objects: POV-Ray {pov:.3} % from phong, the maps' own effect {moved:.3} %");
    assert!(
        pov < 0.5 * moved,
        "POV-Ray {pov:.3} %, the maps' own effect {moved:.3} %"
    );
}

/// One object `tile` seen from 3 m, 128 x 128, under one point light at
/// `light`: the scene of POV-Ray's planar-map agreement tests.
fn tile_scene(tile: Value, light: [f64; 3]) -> Value {
    json!({"format": "scenefit-scene/1", "image": {"width": 128, "height": 128},
        "camera": {"type": "perspective", "position": [0, 0, 3], "look_at": [0, 0, 0], "fov_y_deg": 40},
        "render": {"samples": 64, "indirect": false, "antialias": 4},
        "lights": [{"name": "key", "type": "point", "position": light, "intensity": 6.0}],
        "objects": [tile]})
}

/// The scene `s`, written into `dir`, rendered by `backend`.
fn render_in(dir: &Path, s: &Value, backend: &str) -> Result<Image, String> {
    let p = dir.join("scene.json");
    std::fs::write(&p, s.to_string()).unwrap();
    let scene = api::load_scene(&p, &[]).unwrap();
    let r = api::renderer(backend, &RenderOptions::default()).unwrap();
    api::render(&scene, backend, r.as_ref(), 0).map_err(|e| e.to_string())
}

/// The three maps together on a planar map, at three scales, where the
/// colour pattern sits inside both patterned textures and is carried by
/// both their transforms: POV-Ray draws a quad filling the view and a
/// tilted plane as the built-in tracer does, within 1 % (placed as the
/// outer texture alone carries it, the quad was measured 1.39 % off).
#[test]
fn povray_draws_the_three_maps_together_on_a_quad_and_a_plane() {
    if !common::have("povray", "POV-Ray") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let checker = common::root().join("scenes/textured/checker.png");
    let stripes = common::root().join("scenes/textured/stripes.png");
    let quad = json!({"type": "quad", "corner": [-0.9, -0.9, 0], "edge_u": [1.8, 0, 0], "edge_v": [0, 1.8, 0]});
    let plane = json!({"type": "plane", "point": [0, -0.5, 0], "normal": [0, 1, 0.4]});
    for (name, shape) in [("quad", quad), ("plane", plane)] {
        let tile = json!({"name": "tile", "shape": shape,
            "material": {"color": [0.3, 0.3, 0.3], "specular": 0.6, "shininess": 30,
                "specular_map": {"file": stripes, "scale": [1, 2]},
                "shininess_map": {"file": stripes, "range": [5, 60], "scale": [3, 1]},
                "color_map": {"file": checker, "scale": [1, 1.5]}}});
        let s = tile_scene(tile, [0.3, 0.2, 2.0]);
        let p = d.path().join(format!("three_maps_{name}.json"));
        std::fs::write(&p, s.to_string()).unwrap();
        let dev = agreement(&p, "povray");
        assert!(dev <= 1.0, "{name}: {dev:.3} %");
    }
}

/// The materials of the normal-map agreement tests: one with a
/// highlight, the same with colour, specular and shininess maps, and the
/// normal map (scenes/textured/bumps.png at scale 2).
fn normal_map_materials() -> (Value, Value, Value) {
    let root = common::root().join("scenes/textured");
    let (checker, stripes) = (root.join("checker.png"), root.join("stripes.png"));
    let plain = json!({"color": [0.6, 0.6, 0.6], "specular": 0.3, "shininess": 20});
    let mut all = plain.clone();
    all["color_map"] = json!({"file": checker, "scale": [1, 1.5]});
    all["specular_map"] = json!({"file": stripes, "scale": [1, 2]});
    all["shininess_map"] = json!({"file": stripes, "range": [5, 60], "scale": [3, 1]});
    let normal = json!({"file": root.join("bumps.png"), "scale": [2, 2]});
    (plain, all, normal)
}

/// Asserts POV-Ray's render of `scene(material + normal)` within 1 % of
/// the built-in tracer's and under a quarter of what the normal map
/// changes there (`scene(material)` against it).
fn povray_draws_the_normal_map(
    name: &str,
    render: &dyn Fn(&Value, &str) -> Result<Image, String>,
    scene: &dyn Fn(&Value) -> Value,
    material: &Value,
    normal: &Value,
) {
    let mut mapped = material.clone();
    mapped["normal_map"] = normal.clone();
    let phong = render(&scene(&mapped), "phong").unwrap();
    let pov = render(&scene(&mapped), "povray").unwrap();
    let flat = render(&scene(material), "phong").unwrap();
    let dev = scenefit::metric::deviation(&pov, &phong, None).average;
    let effect = scenefit::metric::deviation(&flat, &phong, None).average;
    eprintln!("{name}: POV-Ray {dev:.3} % from phong, the normal map's own effect {effect:.3} %");
    assert!(
        dev <= 1.0 && dev < 0.25 * effect,
        "{name}: {dev:.3} % (the map moves {effect:.3} %)"
    );
}

/// POV-Ray draws a normal map on a plane, quad or box (the height field
/// of its slopes, `render/pov_bumps.rs`; a box face by face) as the
/// built-in tracer does: on a quad and a box turned and scaled by their
/// transforms, a turned quad holding the colour, specular and shininess
/// maps too (the normal nested in their patterned textures), and a
/// tilted plane; within 1 % over the image and within a
/// quarter of what the normal map itself changes. A map stretched
/// unevenly, whose normals no height has, and a box scaled unevenly are
/// baked into a mesh (`pov_mesh_bumps`) and drawn as closely.
#[test]
fn povray_draws_a_normal_map_on_a_quad_a_box_and_a_plane_as_the_built_in_tracer_does() {
    if !common::have("povray", "POV-Ray") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let (plain, all, normal) = normal_map_materials();
    let front = json!({"type": "quad", "corner": [-0.9, -0.9, 0], "edge_u": [1.8, 0, 0], "edge_v": [0, 1.8, 0]});
    let turned = json!({"type": "quad", "corner": [-0.8, -0.8, 0.3], "edge_u": [1.5, 0, -0.6], "edge_v": [0, 1.6154, 0]});
    let plane = json!({"type": "plane", "point": [0, -0.5, 0], "normal": [0, 1, 0.4]});
    let cube = json!({"type": "box", "min": [-0.7, -0.7, -0.7], "max": [0.7, 0.7, 0.7]});
    let scene = |(shape, transform): (&Value, &Value), material: &Value| {
        let mut object = json!({"name": "tile", "shape": shape, "material": material});
        if !transform.is_null() {
            object["transform"] = transform.clone();
        }
        tile_scene(object, [0.8, 0.6, 2.0])
    };
    let render = |s: &Value, backend: &str| render_in(d.path(), s, backend);
    // turned and scaled (evenly) by its transform
    let moved = json!({"rotate_deg": [20, 30, 0], "scale": 0.8});
    let uneven = json!({"rotate_deg": [20, 30, 0], "scale": [0.9, 0.6, 0.8]});
    let none = Value::Null;
    for (name, shape, material) in [
        (
            "quad turned and scaled by its transform",
            (&front, &moved),
            &plain,
        ),
        ("turned quad, three maps besides", (&turned, &none), &all),
        (
            "box turned and scaled by its transform",
            (&cube, &moved),
            &plain,
        ),
        ("tilted plane", (&plane, &none), &plain),
        (
            "box turned and scaled unevenly (baked)",
            (&cube, &uneven),
            &plain,
        ),
    ] {
        let scene = |material: &Value| scene(shape, material);
        povray_draws_the_normal_map(name, &render, &scene, material, &normal);
    }
    // no height field has these slopes: baked into a mesh (`pov_mesh_bumps`)
    let stretched = json!({"file": normal["file"], "scale": [1, 3]});
    let scene = |material: &Value| scene((&front, &none), material);
    let name = "quad, its map stretched unevenly (baked)";
    povray_draws_the_normal_map(name, &render, &scene, &plain, &stretched);
}

/// POV-Ray draws a normal map made for a sphere (the height field over
/// its longitude and latitude, `pov_bumps::sphere_heights`, read as a
/// spherical image) as the built-in tracer does: on a sphere turned by
/// its transform, a smaller one, beside a colour map, and beside a
/// colour, a specular and a shininess map (every map of the sphere then a
/// spherical image, `pov_bumps::over_sphere`, one at a scale that is not
/// whole); within 1 % and a quarter of what the map itself changes. A
/// flat tile's map wrapped on a sphere, which no height there has, is
/// baked into a mesh (`pov_mesh_bumps`) and drawn as closely.
#[test]
fn povray_draws_a_normal_map_made_for_a_sphere_as_the_built_in_tracer_does() {
    if !common::have("povray", "POV-Ray") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    // made for a sphere by scripts/make-texture.py
    let textured = common::root().join("scenes/textured");
    let bumps = textured.join("sphere_bumps.png");
    let ball = |radius: f64, material: &Value, turned: bool| {
        let mut o = json!({"name": "ball", "material": material,
            "shape": {"type": "sphere", "center": [0.1, 0, 0], "radius": radius}});
        if turned {
            o["transform"] = json!({"rotate_deg": [20, 30, 0]});
        }
        tile_scene(o, [0.8, 0.6, 2.0])
    };
    let render = |s: &Value, backend: &str| render_in(d.path(), s, backend);
    let plain = json!({"color": [0.6, 0.6, 0.6], "specular": 0.3, "shininess": 20});
    let mut coloured = plain.clone();
    coloured["color_map"] = json!({"file": textured.join("checker.png"), "scale": [2, 1]});
    let mut patterned = coloured.clone();
    patterned["specular_map"] = json!({"file": textured.join("stripes.png"), "scale": [1.5, 1]});
    patterned["shininess_map"] =
        json!({"file": textured.join("stripes.png"), "scale": [3, 2], "range": [8, 60]});
    let mut shiny = plain.clone();
    shiny["specular"] = json!(0.8);
    shiny["shininess_map"] =
        json!({"file": textured.join("stripes.png"), "scale": [2, 2], "range": [3, 300]});
    for (name, radius, material, turned) in [
        ("turned", 0.9, &plain, true),
        ("small", 0.6, &plain, false),
        ("beside a colour map", 0.9, &coloured, true),
        (
            "beside colour, specular and shininess maps",
            0.9,
            &patterned,
            true,
        ),
        ("beside a shininess map", 0.9, &shiny, false),
    ] {
        let mut mapped = material.clone();
        mapped["normal_map"] = json!({"file": bumps});
        let phong = render(&ball(radius, &mapped, turned), "phong").unwrap();
        let pov = render(&ball(radius, &mapped, turned), "povray").unwrap();
        let flat = render(&ball(radius, material, turned), "phong").unwrap();
        let dev = scenefit::metric::deviation(&pov, &phong, None).average;
        let effect = scenefit::metric::deviation(&flat, &phong, None).average;
        eprintln!(
            "{name}: POV-Ray {dev:.3} % from phong, the normal map's own effect {effect:.3} %"
        );
        assert!(dev <= 1.0, "{name}: {dev:.3} %");
        if material == &plain {
            assert!(
                dev < 0.25 * effect,
                "{name}: {dev:.3} % (the map moves {effect:.3} %)"
            );
        }
        // the highlight's maps land where phong puts them, not just anywhere
        if material.get("shininess_map").is_some() {
            let mut bare = mapped.clone();
            let o = bare.as_object_mut().unwrap();
            o.remove("specular_map");
            o.remove("shininess_map");
            let bare = render(&ball(radius, &bare, turned), "phong").unwrap();
            let theirs = scenefit::metric::deviation(&bare, &phong, None).average;
            eprintln!("{name}: the specular and shininess maps' own effect {theirs:.3} %");
            assert!(
                dev < 0.5 * theirs,
                "{name}: {dev:.3} % (those maps move {theirs:.3} %)"
            );
        }
    }
    // a flat tile's map, which no height on the sphere has: baked into a mesh
    let flat_tile = json!({"file": textured.join("bumps.png"), "scale": [6, 3]});
    let scene = |material: &Value| ball(0.9, material, true);
    let name = "a flat tile's map wrapped on the sphere (baked)";
    povray_draws_the_normal_map(name, &render, &scene, &plain, &flat_tile);
}

/// A bent strip (OBJ, 16 triangles with vertex normals): an arc about
/// the y axis, its texture coordinates its angle and height.
fn bent_strip(dir: &Path) -> std::path::PathBuf {
    let mut obj = String::new();
    for a in 0..=8 {
        let angle = (-60.0 + 15.0 * a as f64).to_radians();
        let (x, z) = (angle.sin(), angle.cos() - 0.6);
        for y in [-0.8, 0.8] {
            obj += &format!(
                "v {x} {y} {z}\nvt {} {}\nvn {} 0 {}\n",
                a as f64 / 8.0,
                (y + 0.8) / 1.6,
                angle.sin(),
                angle.cos()
            );
        }
    }
    for a in 0..8 {
        let (p, q) = (2 * a + 1, 2 * a + 3);
        obj += &format!("f {p}/{p}/{p} {q}/{q}/{q} {}/{}/{}\n", q + 1, q + 1, q + 1);
        obj += &format!(
            "f {p}/{p}/{p} {}/{}/{} {}/{}/{}\n",
            q + 1,
            q + 1,
            q + 1,
            p + 1,
            p + 1,
            p + 1
        );
    }
    let path = dir.join("bent.obj");
    std::fs::write(&path, obj).unwrap();
    path
}

/// POV-Ray draws a normal map on a mesh (its triangles cut finer, each
/// corner's normal the map's: `pov_mesh_bumps`) as the built-in tracer
/// does: on a flat mesh without vertex normals, on a bent one with them,
/// on the flat one turned and scaled unevenly by its transform, and
/// beside colour, specular and shininess maps; within 1 % over the image
/// and within a quarter of what the normal map itself changes.
#[test]
fn povray_draws_a_normal_map_on_a_mesh_as_the_built_in_tracer_does() {
    if !common::have("povray", "POV-Ray") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let (plain, all, normal) = normal_map_materials();
    let square = d.path().join("square.obj");
    std::fs::write(
        &square,
        "v -0.9 -0.9 0\nv 0.9 -0.9 0\nv 0.9 0.9 0\nv -0.9 0.9 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    )
    .unwrap();
    let flat = json!({"type": "mesh", "file": square});
    let bent = json!({"type": "mesh", "file": bent_strip(d.path())});
    let uneven = json!({"rotate_deg": [20, 30, 0], "scale": [1.1, 0.7, 1.0]});
    let none = Value::Null;
    let render = |s: &Value, backend: &str| render_in(d.path(), s, backend);
    for (name, shape, transform, material) in [
        ("flat, no vertex normals", &flat, &none, &plain),
        ("bent, vertex normals", &bent, &none, &plain),
        ("flat, turned and scaled unevenly", &flat, &uneven, &plain),
        ("bent, three maps besides", &bent, &none, &all),
    ] {
        let scene = |material: &Value| {
            let mut o = json!({"name": "sheet", "shape": shape, "material": material});
            if !transform.is_null() {
                o["transform"] = transform.clone();
            }
            tile_scene(o, [0.8, 0.6, 2.0])
        };
        povray_draws_the_normal_map(name, &render, &scene, material, &normal);
    }
}

/// Mitsuba (`normalmap` BSDF) and Blender (Normal Map node) draw the
/// normal map as the built-in tracer does, on a turned box too:
/// within 1 % over the image.
#[test]
fn mitsuba_and_blender_draw_the_normal_map_as_the_built_in_tracer_does() {
    let d = tempfile::tempdir().unwrap();
    let plain = agreement_scene(d.path());
    let p = with_normal_maps(&plain);
    // the bumps matter: more than the 1 % the backends must keep to
    let phong = api::renderer("phong", &RenderOptions::default()).unwrap();
    let [a, b] = [&plain, &p].map(|s| {
        let scene = api::load_scene(s, &[]).unwrap();
        api::render(&scene, "phong", phong.as_ref(), 0).unwrap()
    });
    let bumped = scenefit::metric::deviation(&a, &b, None).average;
    eprintln!("phong, normal maps vs none: deviation {bumped:.3} %");
    assert!(bumped > 1.5, "{bumped:.3} %");
    for (backend, have) in [
        ("mitsuba", common::have_mitsuba()),
        ("blender", common::have("blender", "Blender")),
    ] {
        if !have {
            continue;
        }
        let dev = agreement(&p, backend);
        assert!(dev <= 1.0, "{backend}: {dev:.3} %");
        let dev = agreement(&with_box(&p), backend);
        assert!(dev <= 1.0, "{backend}, box: {dev:.3} %");
    }
}
