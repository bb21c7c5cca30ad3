//! One material convention in every backend (docs/renderers.md, "One
//! material convention"): on glossy scenes (specular 0.1-1, shininess
//! 10-500, with and without `fresnel`, direct light only) every backend
//! draws the built-in tracer's highlight within 3 % on the highlight's
//! pixels and within 1 % over the image, and a scene as `scenefit diagnose`
//! leaves it (with `falloff_power` and `specular2`) re-renders in Blender,
//! Mitsuba and POV-Ray within 1 % of the built-in tracer. Blender's lobe
//! with two lights (its colour follows the first) is measured and held to
//! the same 3 % and 1 %.
//! Renderers run for real; a missing one skips its test unless CI=true.

#[path = "backends_common/mod.rs"]
mod common;

use common::*;
use scenefit::raster::Image;
use scenefit::render::{from_spec, render_one, Renderer};
use scenefit::scene::{parse, ParamSpace, Scene};

/// Highlight pixels: the specular lobe changes them by more than this.
const LOBE_LEVELS: i32 = 2;

/// One glossy case: specular, shininess, fresnel F0 (None: no Fresnel).
type Case = (f64, f64, Option<f64>);

const CASES: [Case; 7] = [
    (0.1, 10.0, None),
    (0.3, 40.0, None),
    (0.9, 300.0, None),
    (1.0, 500.0, None),
    (0.5, 100.0, None),
    (0.3, 40.0, Some(0.05)),
    (0.9, 300.0, Some(0.1)),
];

/// A yellow ball on a grey floor under one point light, direct light only,
/// 128x96. With Fresnel the light stands behind the ball, so that the
/// highlight is seen at a grazing angle where Schlick's factor matters.
/// The intensity keeps the highlight's peak below white (a clipped
/// highlight would agree whatever its shape).
fn glossy(case: Case, specular: bool) -> Scene {
    let (ks, n, f0) = case;
    let lobe_peak = ks * (n + 8.0) / (8.0 * std::f64::consts::PI);
    let position = if f0.is_some() {
        [0.5, 2.5, -3.0]
    } else {
        [1.0, 3.0, 2.0]
    };
    let mut material = serde_json::json!({
        "color": [0.8, 0.7, 0.1], "diffuse": 1.0,
        "specular": if specular { ks } else { 0.0 }, "shininess": n
    });
    if let Some(f0) = f0 {
        material["fresnel"] = f0.into();
    }
    let v = serde_json::json!({
        "format": "scenefit-scene/1",
        "image": {"width": 128, "height": 96},
        "camera": {"type": "perspective", "position": [0, 1.5, 5], "look_at": [0, 0.5, 0], "up": [0, 1, 0], "fov_y_deg": 40},
        "render": {"samples": 16, "indirect": false, "antialias": 4},
        "lights": [{"name": "key", "type": "point", "position": position,
                    "intensity": 4.0 / (1.0 + lobe_peak)}],
        "objects": [
            {"name": "ball", "shape": {"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5},
             "material": material},
            {"name": "floor", "shape": {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
             "material": {"color": [0.6, 0.6, 0.6], "diffuse": 1.0}}
        ]
    });
    parse(&v.to_string(), "glossy scene", &[]).expect("valid scene")
}

/// Renders every scene with `spec`: the process-backed renderers in one
/// session (one worker start), the built-in tracer one session per scene
/// (a session caches what its base scene does not declare free, such as
/// the shadows of its light).
fn render_all(spec: &str, scenes: &[Scene]) -> Vec<Image> {
    let r: Box<dyn Renderer> = from_spec(spec).unwrap();
    if spec == "phong" {
        return scenes
            .iter()
            .map(|s| render_one(r.as_ref(), s, 0).expect("phong renders"))
            .collect();
    }
    let mut session = r
        .session(&scenes[0], &ParamSpace::default(), 1)
        .unwrap_or_else(|e| panic!("{spec}: {e}"));
    session
        .render_batch(scenes, 7)
        .into_iter()
        .map(|r| r.unwrap_or_else(|f| panic!("{spec}: {f}")))
        .collect()
}

/// Mean absolute difference, per cent of 255 per channel, over the
/// highlight's pixels and over the image.
struct Agreement {
    highlight: f64,
    image: f64,
    pixels: usize,
    peak: (u8, u8),
}

fn agreement(phong: &Image, matte: &Image, other: &Image) -> Agreement {
    let (mut hl, mut all, mut pixels, mut peak) = (0.0, 0.0, 0usize, (0u8, 0u8));
    for ((p, m), o) in phong.pixels().zip(matte.pixels()).zip(other.pixels()) {
        let d: f64 = (0..3)
            .map(|c| (p[c] as f64 - o[c] as f64).abs())
            .sum::<f64>()
            / 3.0
            / 255.0
            * 100.0;
        all += d;
        if (0..3).any(|c| (p[c] as i32 - m[c] as i32).abs() > LOBE_LEVELS) {
            hl += d;
            pixels += 1;
            peak = (peak.0.max(p.0[1]), peak.1.max(o.0[1]));
        }
    }
    let n = (phong.width() * phong.height()) as f64;
    Agreement {
        highlight: hl / pixels.max(1) as f64,
        image: all / n,
        pixels,
        peak,
    }
}

/// Every case within 3 % on the highlight and 1 % over the image.
fn glossy_agrees(spec: &str, cases: &[Case]) {
    let lit: Vec<Scene> = cases.iter().map(|&c| glossy(c, true)).collect();
    let matte: Vec<Scene> = cases.iter().map(|&c| glossy(c, false)).collect();
    let phong = render_all("phong", &lit);
    let phong_matte = render_all("phong", &matte);
    let other = render_all(spec, &lit);
    for (i, case) in cases.iter().enumerate() {
        let a = agreement(&phong[i], &phong_matte[i], &other[i]);
        eprintln!(
            "{spec} {case:?}: highlight {} px {:.2} %, image {:.3} %, green peak phong {} {spec} {}",
            a.pixels, a.highlight, a.image, a.peak.0, a.peak.1
        );
        assert!(a.pixels >= 5, "{case:?}: the lobe must show");
        assert!(a.peak.0 < 255, "{case:?}: the highlight must not clip");
        assert!(
            a.highlight <= 3.0,
            "{spec} {case:?}: highlight {:.2} %",
            a.highlight
        );
        assert!(a.image <= 1.0, "{spec} {case:?}: image {:.3} %", a.image);
    }
}

#[test]
fn blender_draws_the_phong_highlight() {
    if have("blender", "Blender") {
        glossy_agrees("blender", &CASES);
    }
}

#[test]
fn mitsuba_draws_the_phong_highlight() {
    if have_mitsuba() {
        glossy_agrees("mitsuba", &CASES);
    }
}

/// POV-Ray has no Fresnel term on its highlight (refused): the cases
/// without it.
#[test]
fn povray_draws_the_phong_highlight() {
    if have("povray", "POV-Ray") {
        let cases: Vec<Case> = CASES.iter().copied().filter(|c| c.2.is_none()).collect();
        glossy_agrees("povray", &cases);
    }
}

/// The scene `scenefit diagnose` writes when it accepts a light falloff
/// and a second lobe: the fitted scene plus `falloff_power` and
/// `specular2`/`shininess2`, direct light.
fn diagnosed() -> Scene {
    let v = serde_json::json!({
        "format": "scenefit-scene/1",
        "image": {"width": 128, "height": 96},
        "camera": {"type": "perspective", "position": [0, 1.5, 5], "look_at": [0, 0.5, 0], "up": [0, 1, 0], "fov_y_deg": 40},
        "render": {"samples": 16, "indirect": false, "antialias": 4},
        "lights": [{"name": "key", "type": "point", "position": [1.2, 2.6, 2.2], "intensity": 1.7,
                    "falloff_power": 1.4}],
        "objects": [
            {"name": "ball", "shape": {"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5},
             "material": {"color": [0.75, 0.3, 0.2], "diffuse": 0.9, "specular": 0.35,
                          "shininess": 70, "specular2": 0.25, "shininess2": 6}},
            {"name": "floor", "shape": {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
             "material": {"color": [0.6, 0.6, 0.6], "diffuse": 1.0}}
        ]
    });
    parse(&v.to_string(), "diagnosed scene", &[]).expect("valid scene")
}

fn diagnosed_agrees(spec: &str) {
    let scene = diagnosed();
    let phong = render_all("phong", std::slice::from_ref(&scene));
    let other = render_all(spec, std::slice::from_ref(&scene));
    let d = scenefit::metric::deviation(&phong[0], &other[0], None);
    eprintln!("{spec}: diagnosed scene, deviation {:.3} %", d.average);
    assert!(d.average <= 1.0, "{spec}: {:.3} %", d.average);
    // without the effects the image is another: the test can fail
    let mut plain = scene.clone();
    plain.lights[0].falloff_power = None;
    plain.objects[0].material.specular2 = None;
    let plain = render_all("phong", std::slice::from_ref(&plain));
    assert!(scenefit::metric::deviation(&phong[0], &plain[0], None).average > 2.0 * d.average);
}

#[test]
fn blender_renders_a_diagnosed_scene() {
    if have("blender", "Blender") {
        diagnosed_agrees("blender");
    }
}

/// POV-Ray draws the second lobe as a transparent texture layer.
#[test]
fn povray_renders_a_diagnosed_scene() {
    if have("povray", "POV-Ray") {
        diagnosed_agrees("povray");
    }
}

#[test]
fn mitsuba_renders_a_diagnosed_scene() {
    if have_mitsuba() {
        diagnosed_agrees("mitsuba");
    }
}

/// The Fresnel cases can fail: a backend that ignored `fresnel` would
/// miss the built-in tracer's highlight by more than the 3 % allowed.
#[test]
fn the_fresnel_cases_depend_on_fresnel() {
    for case in CASES.iter().copied().filter(|c| c.2.is_some()) {
        let mut without = glossy(case, true);
        without.objects[0].material.fresnel = None;
        let imgs = render_all("phong", &[glossy(case, true), glossy(case, false), without]);
        let a = agreement(&imgs[0], &imgs[1], &imgs[2]);
        eprintln!("{case:?} without fresnel: highlight {:.2} %", a.highlight);
        assert!(a.highlight > 3.0, "{case:?}: {:.2} %", a.highlight);
    }
}

/// Blender's lobe colour is computed for the scene's first light
/// (docs/renderers.md): a second light sees that light's colour. Two
/// lights on a glossy ball, each making its own highlight, direct light:
/// the second highlight is approximate; this measures how far and holds
/// it to the convention's 3 % on the highlights and 1 % over the image.
fn two_lights(specular: bool) -> Scene {
    let mut scene = glossy((0.5, 100.0, None), specular);
    let mut fill = scene.lights[0].clone();
    fill.name = "fill".into();
    fill.position = Some([-2.5, 1.5, 1.5]);
    scene.lights.push(fill);
    scene
}

#[test]
fn blender_second_light_highlight() {
    if !have("blender", "Blender") {
        return;
    }
    let phong = render_all("phong", &[two_lights(true), two_lights(false)]);
    let other = render_all("blender", &[two_lights(true)]);
    let a = agreement(&phong[0], &phong[1], &other[0]);
    eprintln!(
        "blender, two lights: highlight {} px {:.2} %, image {:.3} %, green peak phong {} blender {}",
        a.pixels, a.highlight, a.image, a.peak.0, a.peak.1
    );
    assert!(a.pixels >= 10, "both highlights must show");
    assert!(a.highlight <= 3.0, "highlight {:.2} %", a.highlight);
    assert!(a.image <= 1.0, "image {:.3} %", a.image);
}
