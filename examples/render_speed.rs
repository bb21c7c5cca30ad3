//! Renders generations of an example scene on one thread, for profiling the
//! built-in tracer: `cargo run --release --example render_speed -- paper_box.json 100`.

use rand::{Rng, SeedableRng};
use scenefit::render::from_spec;
use scenefit::scene::{load, ParamSpace, Scene};
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let file = args.get(1).map(String::as_str).unwrap_or("paper_box.json");
    let generations: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(50);
    let scene = load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes")
            .join(file),
    )
    .expect("example scene loads");
    let space = ParamSpace::from_scene(&scene);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let scenes: Vec<Scene> = (0..80)
        .map(|_| {
            let u: Vec<f64> = (0..space.dim()).map(|_| rng.gen()).collect();
            space.scene_at(&scene, &u)
        })
        .collect();
    let mut session = from_spec("phong")
        .unwrap()
        .session(&scene, &space, 1)
        .unwrap();
    let t = std::time::Instant::now();
    for g in 0..generations {
        session.render_batch(&scenes, g as u64);
    }
    let n = (generations * 80) as f64;
    println!(
        "{file}: {:.0} renders/s on one thread (wall)",
        n / t.elapsed().as_secs_f64()
    );
}
