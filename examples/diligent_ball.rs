//! Fits scenes/diligent_ball.json to DiLiGenT ball photographs (reduced to
//! 128x96, saturated pixels masked out), reports the angular error of the
//! recovered light direction against the calibrated one, and diagnoses each
//! fit: `cargo run --release --example diligent_ball -- [OUT_DIR] [IMAGES]`
//! with IMAGES like `1,9,17` (default: 12 spread over the 96); `GAMMA=2.2`
//! declares the camera response of linear photographs, `ROUNDS=n` bounds
//! the effects the diagnosis may add (default 2).

use scenefit::diagnose::{self, photo, DiagnoseConfig, Inputs, SetInputs};
use scenefit::fit::{self, FitConfig, FitTarget};
use scenefit::metric::Mask;
use scenefit::optimize::DeConfig;
use scenefit::raster::io as image_io;
use scenefit::render::from_spec;
use scenefit::scene::{load, Value};
use std::path::{Path, PathBuf};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let out = PathBuf::from(args.get(1).map(String::as_str).unwrap_or("diligent_out"));
    let images: Vec<usize> = args
        .get(2)
        .map(|s| s.split(',').filter_map(|x| x.parse().ok()).collect())
        .unwrap_or_else(|| (0..12).map(|i| 1 + i * 8).collect());
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let data = root.join("tests/data/diligent_ball");
    let mut scene = load(&root.join("scenes/diligent_ball.json")).expect("scene");
    // GAMMA=2.2: the photographs store linear values (DiLiGenT's are), so
    // the camera response v^2.2 before sRGB encoding gives back v.
    if let Some(g) = std::env::var("GAMMA")
        .ok()
        .and_then(|g| g.parse::<f64>().ok())
    {
        scene.camera.response = Some(scenefit::scene::Response {
            gamma: g,
            ..Default::default()
        });
    }
    let dirs: Vec<[f64; 3]> = std::fs::read_to_string(data.join("light_directions.txt"))
        .expect("light_directions.txt")
        .lines()
        .map(|l| {
            let v: Vec<f64> = l
                .split_whitespace()
                .filter_map(|x| x.parse().ok())
                .collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    let renderer = from_spec("phong").unwrap();
    println!("| image | true direction | fitted direction | angular error (°) | after diagnose (°) | deviation fit (%) | after diagnose (%) | accepted | fit s | diagnose s |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let mut errors = Vec::new();
    let mut errors_after = Vec::new();
    for i in images {
        // The photograph at the scene's size and its mask (the ball without
        // the saturated pixels), as examples/diligent_data.rs made them.
        let target =
            image_io::read_image(&data.join(format!("{i:03}.png")), "photo").expect("photo");
        let mask = Mask::load(
            &data.join(format!("{i:03}_mask.png")),
            target.width(),
            target.height(),
        )
        .expect("mask");
        let dir = out.join(format!("{i:03}"));
        std::fs::create_dir_all(&dir).unwrap();
        image_io::write_image(&target, &dir.join("target.png")).unwrap();
        let config = FitConfig {
            de: DeConfig {
                population: 40,
                seed: i as u64,
                strategy: scenefit::optimize::Strategy::Shade,
                ..DeConfig::default()
            },
            generations: 150,
            snapshot_every: 1000,
            ..FitConfig::default()
        };
        let t = std::time::Instant::now();
        let fit_target = FitTarget {
            image: target.clone(),
            levels: None,
            mask: Some(mask.clone()),
            path: Some(dir.join("target.png")),
            encoding: None,
        };
        let fit_dir = dir.join("fit");
        let r = fit::run(
            &scene,
            &fit_target,
            renderer.as_ref(),
            &config,
            &fit_dir,
            &mut (),
        )
        .expect("fit")
        .result;
        let fit_s = t.elapsed().as_secs_f64();
        let fitted = load(&fit_dir.join("fitted_scene.json")).unwrap();
        let d = match scenefit::scene::Field::resolve(&fitted, "lights.led.direction")
            .unwrap()
            .get(&fitted)
        {
            Some(Value::Vector(v)) => v,
            _ => unreachable!(),
        };
        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let d = [d[0] / n, d[1] / n, d[2] / n];
        let g = dirs[i - 1];
        let err = photo::angle_deg(d, g);
        errors.push(err);
        let t = std::time::Instant::now();
        let inputs = SetInputs::one(&Inputs {
            scene: fitted,
            target,
            mask: Some(mask),
        });
        let diag = diagnose::run(
            &inputs,
            &dir.join("diagnose"),
            &DiagnoseConfig {
                max_rounds: std::env::var("ROUNDS")
                    .ok()
                    .and_then(|r| r.parse().ok())
                    .unwrap_or(2),
                seed: i as u64,
                ..DiagnoseConfig::default()
            },
        )
        .expect("diagnose")
        .diagnosis;
        let after = diag
            .params_after
            .get("lights.led.direction")
            .and_then(|v| serde_json::from_value::<[f64; 3]>(v.clone()).ok())
            .map_or(f64::NAN, |a| photo::angle_deg(a, g));
        errors_after.push(after);
        println!(
            "| {i:03} | [{:.3}, {:.3}, {:.3}] | [{:.3}, {:.3}, {:.3}] | {err:.2} | {after:.2} | {:.3} | {:.3} | {} | {fit_s:.1} | {:.1} |",
            g[0], g[1], g[2], d[0], d[1], d[2],
            r.deviation.average,
            diag.deviation_after.average,
            if diag.accepted.is_empty() { "none".into() } else { diag.accepted.join(", ") },
            t.elapsed().as_secs_f64()
        );
    }
    errors.sort_by(f64::total_cmp);
    errors_after.sort_by(f64::total_cmp);
    println!(
        "median angular error after diagnose {:.2}°",
        photo::median(&errors_after)
    );
    println!(
        "\nmedian angular error {:.2}° over {} images (max {:.2}°)",
        photo::median(&errors),
        errors.len(),
        errors.last().unwrap()
    );
}
