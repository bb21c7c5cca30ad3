//! Normal maps (`material.normal_map`; docs/scene-format.md "Textures")
//! drawn by the built-in tracer: a flat map draws as the unmapped scene
//! on every shape; a tilted texel turns the shading normal towards +u
//! (red) and +v (green: OpenGL, +Y up), by the angle it encodes, and
//! turns with the object's transform; a triangle whose texture
//! coordinates are in a line falls back to its own frame (no NaN, no
//! black); hostile map files (missing, truncated, too large, NaN, grey)
//! are refused in one line, exit 2, and a 1x1 map is a valid one. Cheap:
//! 48x48 renders.

mod common;
use common::*;
#[path = "backends_common/mod.rs"]
mod backends;
use scenefit::api::{self, Image, RenderOptions};
use serde_json::{json, Value};
use std::path::Path;

/// One object seen by an orthographic camera from +z, lit by a
/// directional light from the direction `from`, no ambient.
fn scene(dir: &Path, object: Value, from: [f64; 3]) -> std::path::PathBuf {
    let s = json!({
        "format": "scenefit-scene/1",
        "image": {"width": 48, "height": 48},
        "camera": {"type": "orthographic", "position": [0, 0, 5], "look_at": [0, 0, 0], "height": 2.0},
        "lights": [{"name": "sun", "type": "directional", "direction": from, "intensity": 1.0}],
        "objects": [object]
    });
    let p = dir.join("scene.json");
    std::fs::write(&p, s.to_string()).unwrap();
    p
}

fn render(path: &Path) -> Image {
    let scene = api::load_scene(path, &[]).unwrap();
    let phong = api::renderer("phong", &RenderOptions::default()).unwrap();
    api::render(&scene, "test", phong.as_ref(), 0).unwrap()
}

/// A map of one texel (16-bit PNG, 1x1: a valid map, the same tilt
/// everywhere).
fn texel(path: &Path, rgb: [f64; 3]) {
    let c = rgb.map(|x| (x * 65535.0).round() as u16);
    image::ImageBuffer::<image::Rgb<u16>, Vec<u16>>::from_pixel(1, 1, image::Rgb(c))
        .save(path)
        .unwrap();
}

/// The linear value of the red channel at the image centre.
fn centre(img: &Image) -> f64 {
    let c = img.get_pixel(24, 24).0[0] as f64 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn quad(material: Value, transform: Option<Value>) -> Value {
    let mut o = json!({"name": "tile",
        "shape": {"type": "quad", "corner": [-2, -2, 0], "edge_u": [4, 0, 0], "edge_v": [0, 4, 0]},
        "material": material});
    if let Some(t) = transform {
        o["transform"] = t;
    }
    o
}

#[test]
fn a_flat_map_draws_as_the_unmapped_scene_on_every_shape() {
    let d = tempfile::tempdir().unwrap();
    texel(&d.path().join("flat.png"), [0.5, 0.5, 1.0]);
    bumps::write(&d.path().join("bumps.png"), 32, 0.05);
    std::fs::write(
        d.path().join("q.obj"),
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    )
    .unwrap();
    let shapes = [
        json!({"type": "sphere", "center": [0, 0, 0], "radius": 0.8}),
        json!({"type": "plane", "point": [0, 0, 0], "normal": [0, 0.2, 1]}),
        json!({"type": "box", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]}),
        json!({"type": "mesh", "file": "q.obj"}),
    ];
    for shape in shapes {
        let m = json!({"color": [0.8, 0.6, 0.4], "specular": 0.3, "shininess": 20});
        let mut o = json!({"name": "thing", "shape": shape, "material": m,
            "transform": {"rotate_deg": [20, 30, 0]}});
        let a = render(&scene(d.path(), o.clone(), [0.3, 0.5, 1.0]));
        o["material"]["normal_map"] = json!("flat.png");
        let b = render(&scene(d.path(), o.clone(), [0.3, 0.5, 1.0]));
        let most = a.iter().zip(b.iter()).map(|(x, y)| x.abs_diff(*y)).max();
        assert!(most <= Some(1), "{shape}: {most:?}");
        // and a bumpy one changes it
        o["material"]["normal_map"] = json!({"file": "bumps.png", "scale": [3, 3]});
        let c = render(&scene(d.path(), o, [0.3, 0.5, 1.0]));
        let changed = a
            .iter()
            .zip(c.iter())
            .filter(|(x, y)| x.abs_diff(**y) > 2)
            .count();
        assert!(changed > 50, "{shape}: {changed} values changed");
    }
}

/// A texel tilting the normal by 20 degrees towards +u (red) or +v
/// (green), under a light 40 degrees off the surface normal in that
/// direction: the diffuse radiance grows by cos 20 / cos 40 (1.227), on
/// a quad as it is and turned a quarter about the view (light turned
/// alike).
#[test]
fn red_tilts_towards_u_green_towards_v_and_the_map_turns_with_its_object() {
    let d = tempfile::tempdir().unwrap();
    let (a, b) = (20f64.to_radians(), 40f64.to_radians());
    let (s, c) = (a.sin() * 0.5 + 0.5, a.cos() * 0.5 + 0.5);
    texel(&d.path().join("red.png"), [s, 0.5, c]);
    texel(&d.path().join("green.png"), [0.5, s, c]);
    let turn = json!({"rotate_deg": [0, 0, 90]});
    let cases = [
        ("red.png", [b.sin(), 0.0, b.cos()], None),
        ("green.png", [0.0, b.sin(), b.cos()], None),
        // turned: u along +y, v along -x
        ("red.png", [0.0, b.sin(), b.cos()], Some(turn.clone())),
        ("green.png", [-b.sin(), 0.0, b.cos()], Some(turn)),
    ];
    let want = (b - a).cos() / b.cos();
    for (file, from, t) in cases {
        let m = json!({"color": [0.9, 0.9, 0.9]});
        let plain = centre(&render(&scene(d.path(), quad(m.clone(), t.clone()), from)));
        let mut mapped = m;
        mapped["normal_map"] = json!(file);
        let bent = centre(&render(&scene(d.path(), quad(mapped, t.clone()), from)));
        let ratio = bent / plain;
        assert!(
            (ratio / want - 1.0).abs() < 0.01,
            "{file} {t:?}: {ratio} vs {want}"
        );
    }
}

/// Texture coordinates all alike (no dP/du): the frame falls back to the
/// triangle's own, the image is finite and lit, and a flat texel leaves
/// it as it is.
#[test]
fn a_degenerate_uv_triangle_falls_back_to_its_own_frame() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(
        d.path().join("flat.obj"),
        "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0.5 0.5\nf 1/1 2/1 3/1\n",
    )
    .unwrap();
    texel(&d.path().join("flat.png"), [0.5, 0.5, 1.0]);
    bumps::write(&d.path().join("bumps.png"), 16, 0.1);
    let m = json!({"color": [0.9, 0.9, 0.9]});
    let obj = |m: Value| json!({"name": "tri", "shape": {"type": "mesh", "file": "flat.obj"}, "material": m});
    let plain = render(&scene(d.path(), obj(m.clone()), [0.3, 0.3, 1.0]));
    for file in ["flat.png", "bumps.png"] {
        let mut mm = m.clone();
        mm["normal_map"] = json!(file);
        let img = render(&scene(d.path(), obj(mm), [0.3, 0.3, 1.0]));
        let lit = img.pixels().filter(|p| p.0[0] > 30).count();
        assert!(lit > 300, "{file}: {lit} lit pixels");
        if file == "flat.png" {
            let most = plain
                .iter()
                .zip(img.iter())
                .map(|(x, y)| x.abs_diff(*y))
                .max();
            assert!(most <= Some(1), "{most:?}");
        }
    }
}

/// POV-Ray refuses a normal map that no height field has on a plane (one
/// tilt everywhere: a height that repeats cannot slope one way
/// throughout), naming the field, before it starts; on a sphere and a
/// quad it bakes such a map into a mesh (`pov_mesh_bumps`) and draws it
/// as the built-in tracer does (within 1 % over the image); a flat map
/// it draws everywhere.
#[test]
fn povray_refuses_a_normal_map_no_height_field_has_on_a_plane_and_bakes_it_elsewhere() {
    let d = tempfile::tempdir().unwrap();
    texel(&d.path().join("flat.png"), [0.5, 0.5, 1.0]);
    texel(&d.path().join("tilt.png"), [0.7, 0.5, 0.9]);
    let povray = [
        "render",
        "scene.json",
        "-o",
        "o.png",
        "--renderer",
        "povray",
    ];
    let ball = |map: &str| {
        json!({"name": "ball", "shape": {"type": "sphere", "center": [0, 0, 0], "radius": 0.8},
            "material": {"color": [0.9, 0.9, 0.9], "normal_map": map}})
    };
    let tile = |map: &str| quad(json!({"color": [0.9, 0.9, 0.9], "normal_map": map}), None);
    let floor = |map: &str| {
        json!({"name": "floor", "shape": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]},
            "material": {"color": [0.9, 0.9, 0.9], "normal_map": map}})
    };
    let from = [0.3, 0.2, 1.0];
    scene(d.path(), floor("tilt.png"), from);
    let o = scenefit(d.path(), &povray);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("objects.floor.material.normal_map") && err.lines().count() == 1,
        "{err}"
    );
    assert!(!d.path().join("o.png").exists());
    if !backends::have("povray", "POV-Ray") {
        return;
    }
    let pov = api::renderer("povray", &RenderOptions::default()).unwrap();
    for object in [
        tile("tilt.png"),
        ball("tilt.png"),
        tile("flat.png"),
        ball("flat.png"),
        floor("flat.png"),
    ] {
        let name = format!("{} {}", object["name"], object["material"]["normal_map"]);
        let p = scene(d.path(), object, from);
        let s = api::load_scene(&p, &[]).unwrap();
        let drawn = api::render(&s, "povray", pov.as_ref(), 0).unwrap();
        let dev = scenefit::metric::deviation(&drawn, &render(&p), None).average;
        eprintln!("{name}: POV-Ray {dev:.3} % from phong");
        assert!(dev <= 1.0, "{name}: {dev:.3} %");
    }
}

/// Bad normal map files: one line naming the scene file, the key and the
/// map's file, exit 2, nothing written.
#[test]
fn bad_normal_maps_are_refused_in_one_line() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("cut.png"), png_header(64, 64)).unwrap();
    std::fs::write(d.path().join("huge.png"), png_header(100_000, 100_000)).unwrap();
    let nan = image::Rgb32FImage::from_pixel(2, 2, image::Rgb([0.5, f32::NAN, 1.0]));
    nan.save(d.path().join("nan.exr")).unwrap();
    let grey = image::GrayAlphaImage::from_pixel(4, 4, image::LumaA([128, 200]));
    grey.save(d.path().join("grey.png")).unwrap();
    let cases = [
        ("missing.png", "missing.png"),
        ("cut.png", "cut.png"),
        ("huge.png", "100000x100000"),
        ("nan.exr", "expected finite values"),
        ("grey.png", "a grey image"),
    ];
    for (file, expect) in cases {
        let m = json!({"color": [0.9, 0.9, 0.9], "normal_map": file});
        scene(d.path(), quad(m, None), [0.0, 0.0, 1.0]);
        let o = scenefit(d.path(), &["render", "scene.json", "-o", "o.png"]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{file}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(
            err.contains("scene.json") && err.contains("normal_map"),
            "{err}"
        );
        assert!(err.contains(expect), "{expect}: {err}");
        assert!(!d.path().join("o.png").exists());
    }
}
