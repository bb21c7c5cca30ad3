//! Known-answer tests of the built-in tracer: analytic radiance, shadows,
//! and that the cached per-run hits give the same image as a fresh trace.

use rand::{Rng, SeedableRng};
use scenefit::metric::deviation;
use scenefit::render::{from_spec, render_one, srgb};
use scenefit::scene::{load, parse, ParamSpace, Scene};
use std::path::Path;

fn scene_file(name: &str) -> Scene {
    load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes")
            .join(name),
    )
    .unwrap()
}

const PLANE: &str = r#"{
  "format": "scenefit-scene/1",
  "image": {"width": 16, "height": 12},
  "camera": {"type": "orthographic", "position": [0, 5, 0], "look_at": [0, 0, 0], "up": [0, 0, -1], "height": 0.01},
  "lights": [{"name": "l", "type": "point", "position": [0, 1, 0], "intensity": 1.0}],
  "objects": [{"name": "p", "shape": {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
               "material": {"color": [0.5, 0.5, 0.5]}}]
}"#;

#[test]
fn lambertian_plane_under_point_light_has_albedo_over_pi_radiance() {
    // E = I / d^2 = 1 at the centre; L = 0.5/pi.
    let scene = parse(PLANE, "plane", &[]).unwrap();
    let img = render_one(from_spec("phong").unwrap().as_ref(), &scene, 0).unwrap();
    let expected = srgb::encode(0.5 / std::f64::consts::PI);
    assert_eq!(expected, 111);
    let c = img.get_pixel(8, 6).0;
    assert_eq!(c, [expected; 3]);
}

#[test]
fn directional_light_at_60_degrees_gives_half_the_irradiance() {
    let mut scene = parse(PLANE, "plane", &[]).unwrap();
    scene.lights[0].kind = scenefit::scene::LightKind::Directional;
    scene.lights[0].position = None;
    let a = 60f64.to_radians();
    scene.lights[0].direction = Some([a.sin(), a.cos(), 0.0]);
    scene.lights[0].intensity = 2.0;
    let img = render_one(from_spec("phong").unwrap().as_ref(), &scene, 0).unwrap();
    assert_eq!(
        img.get_pixel(3, 3).0,
        [srgb::encode(0.5 / std::f64::consts::PI); 3]
    );
}

#[test]
fn ambient_adds_albedo_times_radiance_and_shadows_are_black_without_it() {
    let mut scene = scene_file("sphere_floor.json");
    // Straight below the light, behind the ball: the floor at the shadow's centre.
    scene.lights[0].position = Some([0.0, 3.0, 0.0]);
    let r = from_spec("phong").unwrap();
    let img = render_one(r.as_ref(), &scene, 0).unwrap();
    // The camera sees the floor just in front of the ball's base: in shadow? No:
    // pick the pixel straight under the ball's silhouette bottom edge instead.
    let dark = img.pixels().filter(|p| p.0 == [0, 0, 0]).count();
    assert!(
        dark > 50,
        "a shadow (and the black sky) should be present, got {dark} black pixels"
    );
    scene.ambient = [0.2, 0.2, 0.2];
    let lit = render_one(r.as_ref(), &scene, 0).unwrap();
    let still_black = lit
        .pixels()
        .zip(img.pixels())
        .filter(|(a, b)| b.0 == [0, 0, 0] && a.0 == [0, 0, 0])
        .count();
    // Only the sky stays black: the shadow now shows albedo * ambient.
    assert!(still_black < dark, "ambient should lift the shadow");
}

/// A session caches what camera rays hit and which surfaces may shadow
/// them for moving lights; its images must equal a fresh trace per scene.
#[test]
fn cached_session_matches_fresh_render() {
    for file in ["paper_box.json", "sphere_floor.json", "diligent_ball.json"] {
        let scene = scene_file(file);
        let space = ParamSpace::from_scene(&scene);
        let phong = from_spec("phong").unwrap();
        let mut session = phong.session(&scene, &space, 2).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let scenes: Vec<Scene> = (0..12)
            .map(|_| {
                let u: Vec<f64> = (0..space.dim()).map(|_| rng.gen()).collect();
                space.scene_at(&scene, &u)
            })
            .collect();
        let batch = session.render_batch(&scenes, 0);
        for (s, img) in scenes.iter().zip(batch) {
            let img = img.unwrap();
            let fresh = render_one(phong.as_ref(), s, 0).unwrap();
            let d = deviation(&fresh, &img, None);
            let max = fresh
                .as_raw()
                .iter()
                .zip(img.as_raw())
                .map(|(a, b)| a.abs_diff(*b))
                .max()
                .unwrap();
            let off = fresh
                .as_raw()
                .chunks(3)
                .zip(img.as_raw().chunks(3))
                .filter(|(a, b)| a.iter().zip(b.iter()).any(|(x, y)| x.abs_diff(*y) > 1))
                .count();
            // Shadow edges may fall one pixel apart (f32 vs f64 shadow rays).
            assert!(
                off <= 3 && d.average < 0.01,
                "{file}: cached vs fresh differ in {off} pixels: max {max}, {d:?}"
            );
        }
    }
}

#[test]
fn mirror_ball_reflects_the_floor() {
    let mut scene = scene_file("sphere_floor.json");
    let r = from_spec("phong").unwrap();
    let matte = render_one(r.as_ref(), &scene, 0).unwrap();
    scene.objects[0].material.reflection = 0.8;
    scene.objects[0].material.diffuse = 0.1;
    let mirror = render_one(r.as_ref(), &scene, 0).unwrap();
    let d = deviation(&matte, &mirror, None);
    assert!(
        d.average > 0.5,
        "a mirror ball should look different: {d:?}"
    );
}
