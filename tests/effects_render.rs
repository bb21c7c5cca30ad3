//! The optional effect fields (docs/scene-format.md "Effects"): absent,
//! they change nothing; present, each changes the image the way it says;
//! each can be freed.

use scenefit::raster::Image;
use scenefit::render::{from_spec, render_one};
use scenefit::scene::{load, parse, ParamSpace, Scene, Vignetting};
use std::path::Path;

fn scene(name: &str) -> Scene {
    let mut s = load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes")
            .join(name),
    )
    .unwrap();
    s.image.width = 64;
    s.image.height = 48;
    s
}

fn render(s: &Scene) -> Image {
    render_one(from_spec("phong").unwrap().as_ref(), s, 0).unwrap()
}

fn mean(img: &Image) -> f64 {
    img.as_raw().iter().map(|&v| v as f64).sum::<f64>() / img.as_raw().len() as f64
}

fn diff(a: &Image, b: &Image) -> f64 {
    a.as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(&x, &y)| (x as f64 - y as f64).abs())
        .sum::<f64>()
        / a.as_raw().len() as f64
}

#[test]
fn neutral_values_render_identically() {
    for name in ["sphere_floor.json", "paper_box.json"] {
        let base = scene(name);
        let img = render(&base);
        let mut s = base.clone();
        s.camera.vignetting = Some(Vignetting { strength: 0.0 });
        s.camera.response = Some(Default::default());
        s.indirect_light = Some(0.0);
        for l in &mut s.lights {
            if l.falloff == scenefit::scene::Falloff::InverseSquare {
                l.falloff_power = Some(2.0);
            }
        }
        for o in &mut s.objects {
            o.material.fresnel = Some(1.0);
            o.material.specular2 = Some(0.0);
            o.material.diffuse_f90 = Some(1.0);
        }
        let img2 = render(&s);
        // The general passes round differently in f32: at most one code.
        let worst = img
            .as_raw()
            .iter()
            .zip(img2.as_raw())
            .map(|(&a, &b)| a.abs_diff(b))
            .max()
            .unwrap();
        assert!(
            worst <= 1,
            "{name}: neutral effect values moved a pixel by {worst}"
        );
    }
}

#[test]
fn each_effect_changes_the_image() {
    let base = scene("sphere_floor.json");
    let img = render(&base);
    type Change = Box<dyn Fn(&mut Scene)>;
    let cases: Vec<(&str, Change)> = vec![
        (
            "vignetting",
            Box::new(|s| s.camera.vignetting = Some(Vignetting { strength: 0.5 })),
        ),
        (
            "response",
            Box::new(|s| {
                s.camera.response = Some(scenefit::scene::Response {
                    gain: 1.3,
                    gamma: 0.8,
                    black: 0.02,
                    ..Default::default()
                })
            }),
        ),
        (
            "falloff",
            Box::new(|s| s.lights[0].falloff_power = Some(1.0)),
        ),
        ("radius", Box::new(|s| s.lights[0].radius = 0.6)),
        ("indirect", Box::new(|s| s.indirect_light = Some(1.0))),
        (
            "grazing",
            Box::new(|s| s.objects[0].material.diffuse_f90 = Some(0.2)),
        ),
        (
            "fresnel",
            Box::new(|s| s.objects[0].material.fresnel = Some(0.05)),
        ),
        (
            "lobe",
            Box::new(|s| {
                s.objects[0].material.specular2 = Some(0.5);
                s.objects[0].material.shininess2 = Some(5.0)
            }),
        ),
    ];
    let mut backlit = base.clone();
    backlit.lights[0].position = Some([2.0, 2.0, -2.0]);
    let backlit_img = render(&backlit);
    for (what, f) in cases {
        let (mut s, img) = if what == "fresnel" {
            (backlit.clone(), &backlit_img)
        } else {
            (base.clone(), &img)
        };
        f(&mut s);
        let d = diff(img, &render(&s));
        assert!(d > 0.02, "{what}: mean change {d}");
    }
}

#[test]
fn vignetting_darkens_and_indirect_brightens() {
    let base = scene("sphere_floor.json");
    let m = mean(&render(&base));
    let mut v = base.clone();
    v.camera.vignetting = Some(Vignetting { strength: 0.5 });
    assert!(mean(&render(&v)) < m);
    let mut i = base.clone();
    i.indirect_light = Some(1.0);
    assert!(mean(&render(&i)) > m);
}

#[test]
fn effect_fields_are_free_able_and_absent_ones_are_refused() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/sphere_floor.json"),
    )
    .unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["camera"]["vignetting"] = serde_json::json!({"strength": 0.1});
    v["free"] = serde_json::json!([{"param": "camera.vignetting.strength", "min": 0, "max": 0.8}]);
    let s = parse(&v.to_string(), "t.json", &[]).unwrap();
    assert_eq!(ParamSpace::from_scene(&s).dim(), 1);
    v["free"] =
        serde_json::json!([{"param": "objects.ball.material.fresnel", "min": 0.02, "max": 1}]);
    let e = parse(&v.to_string(), "t.json", &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("fresnel"), "{e}");
}

/// A matte ball lit from the camera (orthographic, so N·L = N·V = c at
/// every pixel): with `diffuse_f90` f each pixel's linear value is the
/// Lambertian one × (1 + (f − 1)(1 − c)⁵)², c read from the Lambertian
/// render itself (its value over the centre's).
#[test]
fn the_grazing_factor_scales_the_diffuse_term_as_stated() {
    let text = r#"{"format": "scenefit-scene/1", "image": {"width": 96, "height": 96},
        "camera": {"type": "orthographic", "position": [0, 0, 5], "look_at": [0, 0, 0],
                   "up": [0, 1, 0], "height": 1.2},
        "ambient": [0, 0, 0],
        "lights": [{"name": "sun", "type": "directional", "direction": [0, 0, 1],
                    "color": [1, 1, 1], "intensity": 2.5}],
        "objects": [{"name": "ball", "shape": {"type": "sphere", "center": [0, 0, 0], "radius": 0.5},
                     "material": {"color": [0.8, 0.8, 0.8], "specular": 0}}]}"#;
    let base = parse(text, "ball.json", &[]).unwrap();
    let linear = |img: &Image| -> Vec<f64> {
        img.as_raw()
            .chunks(3)
            .map(|p| scenefit::render::srgb::decode(p[1]))
            .collect()
    };
    let lambert = linear(&render(&base));
    let peak = lambert.iter().copied().fold(0.0, f64::max);
    assert!(peak > 0.5 && peak < 0.99, "peak {peak}");
    for f in [0.0, 0.5, 2.0] {
        let mut s = base.clone();
        s.objects[0].material.diffuse_f90 = Some(f);
        let got = linear(&render(&s));
        let mut checked = 0;
        for (&l, &g) in lambert.iter().zip(&got) {
            // Where one 8-bit step is small against the value.
            if l < 0.1 * peak {
                continue;
            }
            let c = (l / peak).min(1.0);
            let want = l * (1.0 + (f - 1.0) * (1.0 - c).powi(5)).powi(2);
            assert!(
                (g - want).abs() <= 0.01 + 0.03 * want,
                "f90 {f}, cos {c:.3}: {g:.4} against {want:.4}"
            );
            checked += 1;
        }
        assert!(checked > 3000, "{checked} pixels checked");
    }
    // Out of range: refused naming the file and the key.
    let mut v: serde_json::Value = serde_json::from_str(text).unwrap();
    v["objects"][0]["material"]["diffuse_f90"] = serde_json::json!(-0.5);
    let e = parse(&v.to_string(), "ball.json", &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("ball.json") && e.contains("diffuse_f90"), "{e}");
}
