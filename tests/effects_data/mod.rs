//! Test data with undeclared effects: targets rendered with one effect the
//! fitting model does not declare, for every effect the diagnosis knows, over
//! scene variants, strengths, seeds and noise levels; and the fit of each
//! with the model that lacks the effect.

#![allow(dead_code)]

use rand::{Rng, SeedableRng};
use scenefit::fit::{self, FitConfig, FitTarget};
use scenefit::optimize::DeConfig;
use scenefit::raster::Image;
use scenefit::render::{from_spec, render_one};
use scenefit::scene::{Light, LightKind, Response, Scene, Vignetting};
use std::path::Path;

/// The effects the diagnosis of one photograph knows, in the order it
/// tries them, but the maps solved in closed form (`albedo_map`,
/// `specular_map`): planting one needs a map file, and one photograph
/// cannot tell it (tests/albedo_map.rs and tests/texture_set.rs try them
/// on sets).
pub fn effects() -> Vec<&'static str> {
    set_effects()
        .into_iter()
        .filter(|&e| !scenefit::diagnose::effects::by_name(e).is_some_and(|x| x.set_only()))
        .collect()
}

/// The effects a generated set plants: [`effects`] and those only a set
/// shows (each photograph's own light colour); not the maps.
pub fn set_effects() -> Vec<&'static str> {
    scenefit::diagnose::effects::names()
        .into_iter()
        .filter(|&e| !scenefit::diagnose::effects::by_name(e).is_some_and(|x| x.closed_form()))
        .collect()
}

/// One generated case.
pub struct Case {
    /// The effect planted ("none": noise only).
    pub effect: String,
    /// The model to fit: the true scene without the effect, free list set.
    pub model: Scene,
    /// The scene that rendered the target (with the effect).
    pub truth: Scene,
    pub target: Image,
}

/// The base scene: sphere_floor at `w` x `h`, a glossy ball, eleven free
/// parameters (light position and intensity, both colours, ball specular).
/// `variant` 1 lights it from behind and gives the floor a gloss (where
/// Fresnel shows); other variants move the light.
pub fn base(w: u32, h: u32, variant: u32) -> Scene {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/sphere_floor.json"),
    )
    .unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["image"] = serde_json::json!({"width": w, "height": h});
    v["free"] = serde_json::json!([
        {"param": "lights.key.position", "min": [-3, 0.5, -3], "max": [3, 5, 5]},
        {"param": "lights.key.intensity", "min": 1, "max": 50},
        {"param": "objects.ball.material.color", "min": [0, 0, 0], "max": [1, 1, 1]},
        {"param": "objects.floor.material.color", "min": [0, 0, 0], "max": [1, 1, 1]},
        {"param": "objects.ball.material.specular", "min": 0, "max": 2}
    ]);
    let mut s = scenefit::scene::parse(&v.to_string(), "sphere_floor.json", &[]).unwrap();
    match variant {
        1 => {
            s.lights[0].position = Some([1.5, 2.0, -2.0]);
            s.objects[1].material.specular = 0.6;
            s.objects[1].material.shininess = 15.0;
        }
        2 => s.lights[0].position = Some([-1.5, 3.5, 2.5]),
        _ => {}
    }
    s
}

/// `scene` with its key light made directional: from where the point
/// light was, its irradiance at the origin the same; direction and
/// intensity free.
pub fn far_lit(mut scene: Scene) -> Scene {
    let l = &mut scene.lights[0];
    let p = l.position.take().unwrap();
    let d2 = p.iter().map(|x| x * x).sum::<f64>();
    l.kind = LightKind::Directional;
    l.direction = Some(p.map(|x| x / d2.sqrt()));
    l.intensity /= d2;
    let text = r#"[
        {"param": "lights.key.direction", "min": [-1, 0, -1], "max": [1, 1, 1]},
        {"param": "lights.key.intensity", "min": 0.05, "max": 5}
    ]"#;
    let mut free: Vec<scenefit::scene::FreeParam> = serde_json::from_str(text).unwrap();
    free.extend(
        scene
            .free
            .drain(..)
            .filter(|f| !f.param.starts_with("lights.")),
    );
    scene.free = free;
    scene
}

/// Plants `effect` at `strength` (1 = the reference strength) into `truth`.
pub fn plant(truth: &mut Scene, effect: &str, strength: f64) {
    match effect {
        "ambient" => truth.ambient = [0.08 * strength; 3],
        "light_falloff" => truth.lights[0].falloff_power = Some(2.0 - 1.0 * strength),
        "second_light" => truth.lights.push(Light {
            name: "hidden".into(),
            kind: LightKind::Point,
            position: Some([-2.0, 2.5, 1.5]),
            direction: None,
            color: [1.0, 1.0, 1.0],
            intensity: 5.0 * strength,
            falloff: Default::default(),
            radius: 0.0,
            falloff_power: None,
            distance: None,
        }),
        "area_light" => truth.lights[0].radius = 0.7 * strength,
        "vignetting" => {
            truth.camera.vignetting = Some(Vignetting {
                strength: 0.5 * strength,
            })
        }
        "camera_response" => {
            truth.camera.response = Some(Response {
                gain: 1.0 + 0.2 * strength,
                gamma: 1.0 - 0.3 * strength,
                black: 0.0,
                ..Default::default()
            })
        }
        "indirect_light" => truth.indirect_light = Some(3.0 * strength),
        "fresnel" => {
            for o in &mut truth.objects {
                o.material.fresnel = Some(0.04_f64.powf(strength));
            }
        }
        "grazing_diffuse" => {
            // A smooth dielectric's diffuse term, fading towards grazing.
            for o in &mut truth.objects {
                o.material.diffuse_f90 = Some(1.0 - 0.8 * strength);
            }
        }
        // The lamp the model calls directional, 8 units from the origin
        // (one and a half times the camera's distance).
        "near_light" => truth.lights[0].distance = Some(8.0 / strength),
        "specular_lobe" => {
            truth.objects[0].material.specular2 = Some(0.8 * strength);
            truth.objects[0].material.shininess2 = Some(4.0);
        }
        _ => {}
    }
}

/// Adds Gaussian noise of `sigma` 8-bit codes (seeded).
pub fn add_noise(img: &mut Image, sigma: f64, seed: u64) {
    if sigma <= 0.0 {
        return;
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    for v in img.iter_mut() {
        // Box-Muller.
        let (u1, u2): (f64, f64) = (rng.gen::<f64>().max(1e-12), rng.gen());
        let z = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
        *v = (*v as f64 + sigma * z).round().clamp(0.0, 255.0) as u8;
    }
}

/// The case for `effect` (or "none") on scene `variant`.
pub fn case(effect: &str, variant: u32, strength: f64, seed: u64, noise: f64) -> Case {
    let (w, h) = (64, 48);
    let mut model = base(w, h, if effect == "fresnel" { 1 } else { variant });
    if effect == "near_light" {
        model = far_lit(model);
    }
    let mut truth = model.clone();
    plant(&mut truth, effect, strength);
    let mut target = render_one(from_spec("phong").unwrap().as_ref(), &truth, 0).unwrap();
    add_noise(&mut target, noise, seed);
    Case {
        effect: effect.into(),
        model,
        truth,
        target,
    }
}

/// Fits the case's model to its target into `dir` (the model lacks the effect).
pub fn fit_case(c: &Case, dir: &Path, seed: u64) -> fit::FitResult {
    let target = FitTarget {
        image: c.target.clone(),
        levels: None,
        mask: None,
        path: Some(dir.join("target.png")),
        encoding: None,
    };
    scenefit::raster::io::write_image(&c.target, &dir.join("target.png")).unwrap();
    let config = FitConfig {
        de: DeConfig {
            population: 30,
            seed,
            ..DeConfig::default()
        },
        generations: 60,
        // Start near the truth, as a fit that has converged would be.
        start_radius: Some(0.15),
        snapshot_every: 1000,
        // The directory holds the target written just above.
        mode: scenefit::rundir::Mode::Overwrite,
        ..FitConfig::default()
    };
    fit::run(
        &c.model,
        &target,
        from_spec("phong").unwrap().as_ref(),
        &config,
        dir,
        &mut (),
    )
    .unwrap()
    .result
}

/// The example scenes directory.
pub fn scenes() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}
