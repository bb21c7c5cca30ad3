//! Renders per second of the built-in tracer inside a fit: a generation of
//! 80 candidates of an example scene, only its free parameters changing.
//! `cargo bench --bench render`; figures in docs/benchmarks.md.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rand::{Rng, SeedableRng};
use scenefit::render::{from_spec, RenderSession};
use scenefit::scene::{load, ParamSpace, Scene};
use std::path::Path;

fn generation(scene_file: &str) -> (Box<dyn RenderSession>, Vec<Scene>) {
    let scene = load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes")
            .join(scene_file),
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
    let jobs = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let session = from_spec("phong")
        .unwrap()
        .session(&scene, &space, jobs)
        .unwrap();
    (session, scenes)
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("phong_generation_of_80");
    group.throughput(Throughput::Elements(80));
    group.sample_size(30);
    // The last two: the same ball and photograph size, its centre fixed
    // (hits traced once) and free (hits traced per candidate).
    for file in [
        "sphere_floor.json",
        "paper_box.json",
        "diligent_ball.json",
        "diligent_ball/scene.json",
    ] {
        let (mut session, scenes) = generation(file);
        group.bench_function(file, |b| b.iter(|| session.render_batch(&scenes, 0)));
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
