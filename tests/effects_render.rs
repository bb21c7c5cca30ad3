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
