//! Generated photograph sets that trap the diagnosis into an imitation
//! (issue 32): a matte sphere with a painted albedo under 8–12 directional
//! lights, written as 8-bit files holding linear values or a gamma's
//! (1.8, 2.2) output, with a scene written as a user would (each
//! photograph's light direction and intensity free, the colour, specular
//! strength and shininess shared and free, no response declared), where a
//! broad specular lobe or a blurred light imitates the missing response;
//! and the opposite, a real broad lobe in sRGB files, where no response
//! must be taken. Each set is a directory `fit --shots` and `diagnose`
//! read as they are, with its true light directions (`lights.txt`, for
//! scripts/light-error.py) and the same model with the encoding declared
//! (`declared.json`, the reference fit).

use rand::{Rng, SeedableRng};
use scenefit::render::{from_spec, render_one};
use scenefit::scene::albedo_map::{self, AlbedoMap};
use serde_json::{json, Value};
use std::f64::consts::{PI, TAU};
use std::path::Path;

/// How the photographs of a set are written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// A matte sphere; the files hold `v^(1/gamma)` of the linear value
    /// `v` (gamma 1: linear values in a PNG, as a raw converter writes).
    Matte { gamma: f64 },
    /// A broad specular lobe on the sphere, the files sRGB-encoded: the
    /// model's lobe is real and the encoding is the one assumed.
    Lobe,
}

/// Image side, pixels: small, so that a set's diagnosis is cheap.
pub const SIDE: u32 = 64;

/// How large a set is: its images' side and its number of photographs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Size {
    pub side: u32,
    /// The photographs (one light each); None: 8–12, drawn with the seed.
    pub lights: Option<usize>,
}

/// The sets scripts/diagnose-traps.sh runs.
pub const FULL: Size = Size {
    side: SIDE,
    lights: None,
};

/// The ball's radius and the camera's frame height.
const RADIUS: f64 = 0.5;
const FRAME: f64 = 1.2;

/// The scene of one photograph, `light` its (direction, intensity).
fn scene_json(material: Value, light: ([f64; 3], f64), response: Option<f64>, side: u32) -> Value {
    let mut s = json!({
        "format": "scenefit-scene/1",
        "image": {"width": side, "height": side},
        "camera": {"type": "orthographic", "position": [0, 0, 5], "look_at": [0, 0, 0],
                   "up": [0, 1, 0], "height": FRAME},
        "ambient": [0.0, 0.0, 0.0],
        "render": {"samples": 4, "indirect": false},
        "lights": [{"name": "led", "type": "directional", "direction": light.0,
                    "color": [1, 1, 1], "intensity": light.1}],
        "objects": [{"name": "ball",
                     "shape": {"type": "sphere", "center": [0, 0, 0], "radius": RADIUS},
                     "material": material}],
    });
    if let Some(gamma) = response {
        // The camera writes the linear value through 1/gamma, as it is.
        s["camera"]["response"] = json!({"gamma": 1.0 / gamma, "encoding": "linear"});
    }
    s
}

/// A smooth painted albedo: per channel, 1 ± 0.25 over one or two waves
/// across the image, at seeded frequencies and phases (the same pattern
/// at any `side`: it is the image's, in pixels of that side).
fn painted(rng: &mut rand::rngs::StdRng, side: u32) -> AlbedoMap {
    let mut m = AlbedoMap::uniform(side, side, 1.0);
    let waves: Vec<[f64; 5]> = (0..3)
        .map(|_| {
            [
                rng.gen_range(0.15..0.3),
                rng.gen_range(0.5..1.5),
                rng.gen_range(0.5..1.5),
                rng.gen_range(0.0..TAU),
                rng.gen_range(0.0..TAU),
            ]
        })
        .collect();
    let n = side as usize;
    for y in 0..n {
        for x in 0..n {
            let (u, v) = (x as f64 / n as f64, y as f64 / n as f64);
            for (c, w) in waves.iter().enumerate() {
                let a = (TAU * w[1] * u + w[3]).sin() * (TAU * w[2] * v + w[4]).cos();
                m.values[3 * (y * n + x) + c] = (1.0 + w[0] * a) as f32;
            }
        }
    }
    m
}

/// 8–12 lights (`count` when given) spread around the view axis, 10°–50°
/// from it, with intensities that keep the brightest linear value below 1.
fn lights(rng: &mut rand::rngs::StdRng, count: Option<usize>) -> Vec<([f64; 3], f64)> {
    // Drawn even when `count` is given, so that the rest of the set is
    // drawn from the same stream.
    let drawn = rng.gen_range(8..=12);
    let n = count.unwrap_or(drawn);
    let turn = rng.gen_range(0.0..TAU);
    (0..n)
        .map(|i| {
            let phi = turn + TAU * i as f64 / n as f64 + rng.gen_range(-0.2..0.2);
            let theta = rng.gen_range(10.0f64..50.0).to_radians();
            let d = [
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ];
            (d, PI * rng.gen_range(0.8..1.1))
        })
        .collect()
}

/// The ball's mask, a pixel inside when its centre is 1.5 pixels within
/// the silhouette (as a photograph's mask is drawn inside the edge).
fn mask(side: u32) -> scenefit::raster::Image {
    let px = FRAME / side as f64;
    scenefit::raster::Image::from_fn(side, side, |x, y| {
        let u = (x as f64 + 0.5) * px - FRAME / 2.0;
        let v = (y as f64 + 0.5) * px - FRAME / 2.0;
        let inside = (u * u + v * v).sqrt() < RADIUS - 1.5 * px;
        let l = if inside { 255 } else { 0 };
        image::Rgb([l, l, l])
    })
}

/// Writes the set `kind` with `seed` (light layout, albedo pattern,
/// colour) into `dir`: `s0.png`…, `mask.png`, `albedo.exr`, `scene.json`
/// (the model), `declared.json` (the model with the files' encoding
/// declared), `shots.json` and `lights.txt`.
pub fn write(dir: &Path, kind: Kind, seed: u64) {
    write_sized(dir, kind, seed, FULL);
}

/// [`write`] at `size`.
pub fn write_sized(dir: &Path, kind: Kind, seed: u64, size: Size) {
    std::fs::create_dir_all(dir).unwrap();
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let map = painted(&mut rng, size.side);
    let map_path = std::path::absolute(dir.join("albedo.exr")).unwrap();
    albedo_map::write(&map_path, map).unwrap();
    let color: Vec<f64> = (0..3).map(|_| rng.gen_range(0.45..0.75)).collect();
    let lights = lights(&mut rng, size.lights);
    let (material, response) = match kind {
        Kind::Matte { gamma } => (
            json!({"color": color, "diffuse": 1.0, "specular": 0.0}),
            Some(gamma),
        ),
        Kind::Lobe => (
            json!({"color": color, "diffuse": 1.0, "specular": rng.gen_range(0.2..0.35),
                   "shininess": rng.gen_range(3.0..6.0)}),
            None,
        ),
    };
    let mut material = material;
    material["albedo_map"] = json!(map_path.display().to_string());
    let phong = from_spec("phong").unwrap();
    let mut shots = Vec::new();
    let mut truth = String::new();
    scenefit::raster::io::write_image(&mask(size.side), &dir.join("mask.png")).unwrap();
    for (i, &light) in lights.iter().enumerate() {
        let s = scene_json(material.clone(), light, response, size.side);
        let scene = scenefit::scene::load::from_value(s, "trap.json").unwrap();
        let img = render_one(phong.as_ref(), &scene, 0).unwrap();
        let name = format!("s{i}");
        scenefit::raster::io::write_image(&img, &dir.join(format!("{name}.png"))).unwrap();
        shots.push(json!({"name": name, "target": format!("{name}.png"), "mask": "mask.png"}));
        let d = light.0;
        truth += &format!("{} {} {}\n", d[0], d[1], d[2]);
    }
    std::fs::write(dir.join("lights.txt"), truth).unwrap();
    let shots = json!({"format": "scenefit-shots/1", "shots": shots});
    std::fs::write(dir.join("shots.json"), shots.to_string()).unwrap();
    let user = model(None, size.side);
    std::fs::write(dir.join("scene.json"), user.to_string()).unwrap();
    let declared = model(response, size.side);
    std::fs::write(dir.join("declared.json"), declared.to_string()).unwrap();
}

/// The scene a user writes for such a set: one light whose direction and
/// intensity each photograph has its own of, the material's colour,
/// specular strength and shininess shared and free; `response` a gamma
/// the files are declared to hold (None: nothing declared).
fn model(response: Option<f64>, side: u32) -> Value {
    let material = json!({"color": [0.5, 0.5, 0.5], "diffuse": 1.0, "specular": 0.3,
                          "shininess": 30.0});
    let mut s = scene_json(material, ([0.0, 0.0, 1.0], 3.0), response, side);
    s["free"] = json!([
        {"param": "lights.led.direction", "min": [-1, -1, 0.05], "max": [1, 1, 1], "per_shot": true},
        {"param": "lights.led.intensity", "min": 0.01, "max": 20, "per_shot": true},
        {"param": "objects.ball.material.color", "min": [0, 0, 0], "max": [1, 1, 1]},
        {"param": "objects.ball.material.specular", "min": 0, "max": 2},
        {"param": "objects.ball.material.shininess", "min": 1, "max": 300}
    ]);
    s
}

/// The gamma of the `i`-th trap set: linear, 1.8 and 2.2 in turn.
pub fn trap_gamma(i: usize) -> f64 {
    [1.0, 1.8, 2.2][i % 3]
}
