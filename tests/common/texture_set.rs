//! Generated textured sets (tests/texture_set.rs, docs/results.md): a
//! sphere or a plane photographed 10 times, the camera (known, in each
//! shot's `set`) and the light (unknown, fitted per photograph) moving
//! from one photograph to the next, 1 level of noise, the last photograph
//! held out. Textured: a colour texture the model does not know and a
//! second material region whose specular strength is a quarter of the
//! rest's. Uniform: one colour, one specular strength. The model knows
//! the shininess; its colour and specular strength are free.
//!
//! Also the measures of what a diagnosis recovered: the colour error on
//! the texels seen by 3 photographs or more, and the noise floor of each
//! photograph.

use rand::{Rng, SeedableRng};
use scenefit::metric::deviation;
use scenefit::raster::Image;
use scenefit::render::{from_spec, render_one, surface_coords};
use scenefit::scene::texture::{self, Encoding};
use scenefit::scene::Scene;
use serde_json::{json, Value};
use std::path::Path;

/// Photographs in a set; the last is held out.
pub const SHOTS: usize = 10;
/// Noise of the photographs, 8-bit levels (one standard deviation).
pub const SIGMA: f64 = 1.0;
/// The region of lower gloss: its specular strength times this.
pub const LOW_GLOSS: f64 = 0.25;
/// The glossy set's exponents: the second region's broad lobe, the
/// rest's (the model's scalar).
pub const EXPONENTS: (f64, f64) = (10.0, 40.0);
/// A plane's texture tile, metres.
const TILE: f64 = 2.4;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Surface {
    Sphere,
    Plane,
}

/// The true colour (linear) at texture coordinates `uv` of the tile.
pub fn colour_at(surface: Surface, uv: [f64; 2]) -> [f64; 3] {
    const COLOURS: [[f64; 3]; 3] = [[0.9, 0.8, 0.3], [0.3, 0.5, 0.9], [0.7, 0.3, 0.3]];
    let (nu, nv) = match surface {
        Surface::Sphere => (8.0, 4.0),
        Surface::Plane => (6.0, 6.0),
    };
    let i = (uv[0].rem_euclid(1.0) * nu) as usize;
    let j = (uv[1].rem_euclid(1.0) * nv) as usize;
    COLOURS[(i + 2 * j) % 3]
}

/// The true specular multiplier at `uv` of the tile: `LOW_GLOSS` in the
/// second region (on the sphere alternate quarters of longitude, so the
/// front shows both; on the plane the half of lower u), else 1.
pub fn gloss_at(surface: Surface, uv: [f64; 2]) -> f64 {
    let low = match surface {
        Surface::Sphere => ((uv[0].rem_euclid(1.0) * 4.0) as usize).is_multiple_of(2),
        Surface::Plane => uv[0].rem_euclid(1.0) < 0.5,
    };
    if low {
        LOW_GLOSS
    } else {
        1.0
    }
}

/// Writes a 16-bit linear texture of `w` x `h` texels from `f(uv)`.
fn write_texture(path: &Path, (w, h): (u32, u32), f: impl Fn([f64; 2]) -> [f64; 3]) {
    let img = image::ImageBuffer::from_fn(w, h, |x, y| {
        let uv = [
            (x as f64 + 0.5) / w as f64,
            1.0 - (y as f64 + 0.5) / h as f64,
        ];
        image::Rgb(f(uv).map(|c| (c * 65535.0).round() as u16))
    });
    img.save(path).unwrap();
}

/// The model: the surface under a directional light, colour and specular
/// strength free, the light per photograph.
fn model(surface: Surface) -> Value {
    let (camera, object) = match surface {
        Surface::Sphere => (
            json!({"type": "perspective", "position": [0, 0.6, 4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 35}),
            json!({"name": "body", "shape": {"type": "sphere", "center": [0, 0, 0], "radius": 1}}),
        ),
        Surface::Plane => (
            json!({"type": "perspective", "position": [0, 3, 1.5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 40}),
            json!({"name": "body", "shape": {"type": "plane", "point": [-1.2, 0, 1.2], "normal": [0, 1, 0]}}),
        ),
    };
    let mut object = object;
    object["material"] = json!({"color": [0.5, 0.5, 0.5], "specular": 0.3, "shininess": 40});
    json!({
        "format": "scenefit-scene/1",
        "image": {"width": 96, "height": 96},
        "camera": camera,
        "ambient": [0.03, 0.03, 0.03],
        "lights": [{"name": "key", "type": "directional", "direction": [0.3, 0.5, 1], "intensity": 3}],
        "objects": [object],
        "free": [
            {"param": "lights.key.direction", "min": [-1, -0.2, -1], "max": [1, 1, 1], "per_shot": true},
            {"param": "objects.body.material.color", "min": [0, 0, 0], "max": [1, 1, 1]},
            {"param": "objects.body.material.specular", "min": 0, "max": 1}
        ]
    })
}

/// Shot `i`'s camera position and light direction: the camera swings
/// across 100 degrees, the light turns out of step with it, so that the
/// highlights fall on both regions.
pub fn shot(surface: Surface, i: usize) -> ([f64; 3], [f64; 3]) {
    let t = i as f64 / (SHOTS - 1) as f64;
    let a = (-50.0 + 100.0 * t).to_radians();
    let b = (55.0 * (2.4 * i as f64 + 0.5).sin()).to_radians();
    let up = 0.5 + 0.3 * (1.7 * i as f64).cos();
    match surface {
        Surface::Sphere => ([4.0 * a.sin(), 0.6, 4.0 * a.cos()], [b.sin(), up, b.cos()]),
        Surface::Plane => (
            [1.6 * a.sin(), 3.0, 1.6 * a.cos()],
            [0.6 * b.sin(), 1.0, 0.6 * b.cos() - 0.3],
        ),
    }
}

/// What varies over the true material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Truth {
    /// Nothing: one colour, one specular strength.
    Uniform,
    /// The colour, and the specular strength (`gloss_at`).
    Textured,
    /// The colour, and the exponent: the second region's lobe broad
    /// (`EXPONENTS`), the strength the same everywhere.
    Glossy,
}

/// The truth: the model with the true material, its maps written into
/// `dir`.
fn truth(dir: &Path, surface: Surface, kind: Truth) -> Scene {
    let mut t = model(surface);
    let m = &mut t["objects"][0]["material"];
    if kind != Truth::Uniform {
        let scale = match surface {
            Surface::Sphere => json!([1.0, 1.0]),
            Surface::Plane => json!([1.0 / TILE, 1.0 / TILE]),
        };
        write_texture(&dir.join("truth_color.png"), (96, 48), |uv| {
            colour_at(surface, uv)
        });
        write_texture(&dir.join("truth_specular.png"), (96, 48), |uv| {
            [gloss_at(surface, uv); 3]
        });
        m["color"] = json!([1.0, 1.0, 1.0]);
        m["specular"] = json!(0.6);
        let map = |f: &str| json!({"file": dir.join(f), "encoding": "linear", "scale": scale});
        m["color_map"] = map("truth_color.png");
        if kind == Truth::Textured {
            m["specular_map"] = map("truth_specular.png");
        } else {
            let (broad, rest) = EXPONENTS;
            write_texture(&dir.join("truth_shininess.png"), (96, 48), |uv| {
                [if gloss_at(surface, uv) < 1.0 {
                    broad / rest
                } else {
                    1.0
                }; 3]
            });
            let mut shine = map("truth_shininess.png");
            shine["range"] = json!([0.0, rest]);
            m["shininess_map"] = shine;
        }
    } else {
        m["color"] = json!([0.7, 0.5, 0.4]);
        m["specular"] = json!(0.4);
    }
    scenefit::scene::parse(&t.to_string(), "truth.json", &[]).unwrap()
}

/// Gaussian noise of `sigma` levels (seeded).
fn add_noise(img: &mut Image, sigma: f64, seed: u64) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    for v in img.iter_mut() {
        let (u1, u2): (f64, f64) = (rng.gen::<f64>().max(1e-12), rng.gen());
        let z = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
        *v = (*v as f64 + sigma * z).round().clamp(0.0, 255.0) as u8;
    }
}

/// The truth with shot `i`'s camera and light.
fn shot_scene(truth: &Scene, surface: Surface, i: usize) -> Scene {
    let (cam, light) = shot(surface, i);
    let mut s = truth.clone();
    s.camera.position = Some(cam);
    s.lights[0].direction = Some(light);
    s
}

/// Writes the set into `dir` (photographs, model.json, shots.json, the
/// true maps); each photograph's noise floor (its deviation from the
/// noise-free render), in percent.
pub fn write(dir: &Path, surface: Surface, textured: bool) -> Vec<f64> {
    let kind = if textured {
        Truth::Textured
    } else {
        Truth::Uniform
    };
    write_truth(dir, surface, kind)
}

/// [`write`] of the material `kind`.
pub fn write_truth(dir: &Path, surface: Surface, kind: Truth) -> Vec<f64> {
    let truth = truth(dir, surface, kind);
    let phong = from_spec("phong").unwrap();
    let (mut list, mut floors) = (Vec::new(), Vec::new());
    for i in 0..SHOTS {
        let clean = render_one(phong.as_ref(), &shot_scene(&truth, surface, i), 0).unwrap();
        let mut img = clean.clone();
        add_noise(&mut img, SIGMA, 500 + i as u64);
        floors.push(deviation(&img, &clean, None).average);
        scenefit::raster::io::write_image(&img, &dir.join(format!("s{i}.png"))).unwrap();
        let (cam, _) = shot(surface, i);
        list.push(
            json!({"name": format!("s{i}"), "target": format!("s{i}.png"),
            "set": {"camera.position": cam}}),
        );
    }
    list[SHOTS - 1]["hold_out"] = json!(true);
    let shots = json!({"format": "scenefit-shots/1", "shots": list});
    std::fs::write(dir.join("shots.json"), shots.to_string()).unwrap();
    std::fs::write(dir.join("model.json"), model(surface).to_string()).unwrap();
    floors
}

/// A map the diagnosis wrote, read linear as the tracer reads it, and
/// the value its brightest texel stands for (`range`'s top).
fn read_map(t: &texture::TextureRef) -> (std::sync::Arc<texture::Texels>, f64) {
    let texels = texture::get(Path::new(t.file()), Encoding::Linear).unwrap();
    (texels, t.range()[1])
}

/// The colour error of the colour map in `improved` (a loaded scene):
/// per texel, the map's value times the scalar colour against the mean
/// true colour of the surface points the photographs fitted (all but the
/// held-out one) see in it, mean absolute over channels and the texels
/// seen by 3 photographs or more, linear; and how many such texels.
/// Without a colour map, every texel holds the scalar colour.
pub fn colour_error(improved: &Scene, surface: Surface) -> (f64, usize) {
    let m = &improved.objects[0].material;
    let map = m
        .color_map
        .as_ref()
        .map(|t| (read_map(t).0, t.scale(), t.range()[1]));
    let side = map.as_ref().map_or(1, |(t, _, _)| t.width as usize);
    let rows = map.as_ref().map_or(1, |(t, _, _)| t.height as usize);
    let scale = map.as_ref().map_or([1.0, 1.0], |(_, s, _)| *s);
    let truth_scale = match surface {
        Surface::Sphere => 1.0,
        Surface::Plane => 1.0 / TILE,
    };
    // Per texel: photographs seen from (a bit each), truth sum, count.
    let mut seen = vec![(0u32, [0.0_f64; 3], 0usize); side * rows];
    for i in 0..SHOTS - 1 {
        let (cam, _) = shot(surface, i);
        let mut s = improved.clone();
        s.camera.position = Some(cam);
        for p in surface_coords(&s).points.iter().flatten() {
            let uv = p.uv.map(f64::from);
            let (x, y) = (uv[0] * scale[0], uv[1] * scale[1]);
            let tx = ((x.rem_euclid(1.0) * side as f64) as usize).min(side - 1);
            let ty = (((1.0 - y.rem_euclid(1.0)) * rows as f64) as usize).min(rows - 1);
            let cell = &mut seen[ty * side + tx];
            cell.0 |= 1 << i;
            let c = colour_at(surface, uv.map(|x| x * truth_scale));
            (0..3).for_each(|k| cell.1[k] += c[k]);
            cell.2 += 1;
        }
    }
    let (mut err, mut counted) = (0.0, 0);
    for (k, (photos, sum, n)) in seen.iter().enumerate() {
        if photos.count_ones() < 3 {
            continue;
        }
        let value = |c: usize| {
            map.as_ref()
                .map_or(1.0, |(t, _, hi)| t.values[3 * k + c] as f64 * hi)
        };
        err += (0..3)
            .map(|c| (value(c) * m.color[c] - sum[c] / *n as f64).abs())
            .sum::<f64>()
            / 3.0;
        counted += 1;
    }
    (err / counted.max(1) as f64, counted)
}

/// The median exponent of `improved`'s shininess map (a loaded scene,
/// the sphere's parametrisation: uv the tile's) over the texels the
/// diagnosis solved (an exponent off the scalar, or a specular strength
/// off 1), in the broad region and in the rest.
pub fn shininess_by_region(improved: &Scene, surface: Surface) -> [f64; 2] {
    let m = &improved.objects[0].material;
    let (shine, hi) = read_map(m.shininess_map.as_ref().expect("a shininess map"));
    let strength = m.specular_map.as_ref().map(read_map);
    let (w, h) = (shine.width as usize, shine.height as usize);
    let mut regions = [Vec::new(), Vec::new()];
    for y in 0..h {
        for x in 0..w {
            let k = 3 * (y * w + x);
            let e = shine.values[k] as f64 * hi;
            let moved = (e - m.shininess).abs() > 1e-3 * m.shininess;
            let solved = strength
                .as_ref()
                .is_some_and(|(t, hi)| (t.values[k] as f64 * hi - 1.0).abs() > 1e-3);
            if !moved && !solved {
                continue;
            }
            let uv = [
                (x as f64 + 0.5) / w as f64,
                1.0 - (y as f64 + 0.5) / h as f64,
            ];
            regions[usize::from(gloss_at(surface, uv) >= 1.0)].push(e);
        }
    }
    regions.map(|mut r| {
        r.sort_by(f64::total_cmp);
        r.get(r.len() / 2).copied().unwrap_or(f64::NAN)
    })
}
