//! Builds the repository's copy of the DiLiGenT ball data from the original
//! photographs: `cargo run --release --example diligent_data -- SOURCE_DIR`
//! reads SOURCE_DIR/001.png … 096.png, mask.png and light_directions.txt
//! (256x192 crops) and writes, at the size scenes/diligent_ball.json
//! renders (128x96):
//!
//! - tests/data/diligent_ball/NNN.png: the photograph averaged over 2x2 blocks;
//! - tests/data/diligent_ball/NNN_mask.png: the pixels that count, white:
//!   on the ball and no source pixel saturated (the highlight clips at 255);
//! - tests/data/diligent_ball/mask.png: the ball alone, reduced the same way;
//! - tests/data/diligent_ball/light_directions.txt: copied;
//! - scenes/diligent_ball/shots.json: each photograph with its mask and its
//!   calibrated light direction.
//!
//! The fits only ever used the reduced images, so the repository keeps
//! those (under 1 MB) rather than the 1.9 MB originals.

use scenefit::diagnose::photo;
use scenefit::metric::Mask;
use scenefit::raster::io as image_io;
use serde_json::json;
use std::path::{Path, PathBuf};

const COUNT: usize = 96;
const FACTOR: u32 = 2;

fn main() {
    let Some(source) = std::env::args().nth(1).map(PathBuf::from) else {
        eprintln!("usage: diligent_data SOURCE_DIR (the original 256x192 DiLiGenT ball crops)");
        std::process::exit(2);
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = root.join("tests/data/diligent_ball");
    std::fs::create_dir_all(&out).unwrap();
    let ball = image::open(source.join("mask.png"))
        .expect("mask.png")
        .to_luma8();
    let directions =
        std::fs::read_to_string(source.join("light_directions.txt")).expect("light_directions.txt");
    std::fs::write(out.join("light_directions.txt"), &directions).unwrap();
    let directions: Vec<Vec<f64>> = directions
        .lines()
        .map(|l| {
            l.split_whitespace()
                .map(|x| x.parse().expect("a number"))
                .collect()
        })
        .collect();
    assert_eq!(
        directions.len(),
        COUNT,
        "one light direction per photograph"
    );

    // The ball alone: a photograph with nothing saturated leaves only the
    // ball mask's own test.
    let dark = image::RgbImage::new(ball.width(), ball.height());
    save_mask(
        &photo::reduced_mask(&ball, &dark, FACTOR),
        &out.join("mask.png"),
    );

    let mut shots = Vec::new();
    for (i, d) in (1..=COUNT).zip(&directions) {
        let name = format!("{i:03}");
        let full = image_io::read_image(&source.join(format!("{name}.png")), "photo").unwrap();
        image_io::write_image(
            &photo::downsample(&full, FACTOR),
            &out.join(format!("{name}.png")),
        )
        .unwrap();
        save_mask(
            &photo::reduced_mask(&ball, &full, FACTOR),
            &out.join(format!("{name}_mask.png")),
        );
        shots.push(json!({
            "name": name,
            "target": format!("../../tests/data/diligent_ball/{name}.png"),
            "mask": format!("../../tests/data/diligent_ball/{name}_mask.png"),
            "encoding": "srgb",
            // The data's camera frame (x right, y up, z towards the camera)
            // is the scene's: the camera looks down -z with y up.
            "set": {"lights.led.direction": [d[0], d[1], d[2]]},
        }));
    }
    let shots = json!({"format": "scenefit-shots/1", "shots": shots});
    let path = root.join("scenes/diligent_ball/shots_calibrated.json");
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    let text = serde_json::to_string_pretty(&shots).unwrap() + "\n";
    scenefit::fsio::write_atomic(&path, text.as_bytes()).unwrap();
    println!(
        "{COUNT} photographs -> {}, {}",
        out.display(),
        path.display()
    );
}

/// A mask as an image: white where a pixel counts.
fn save_mask(mask: &Mask, path: &Path) {
    let (w, h) = mask.size();
    let mut img = image::GrayImage::new(w, h);
    for &p in mask.pixels() {
        img.put_pixel(p % w, p / w, image::Luma([255]));
    }
    img.save(path).unwrap();
}
