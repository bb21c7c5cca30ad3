//! Renders per second of the built-in tracer on meshes: an icosphere of
//! 1,280 and of 81,920 triangles (vertex normals, a floor, one point light
//! with shadows, 128x96), against the analytic sphere it approximates, in a
//! generation of 80 candidates with (a) the light free (position and
//! intensity; camera hits traced once, shadow rays per candidate), (b)
//! the floor free and (c) the ball's pose free (yaw and position; in both
//! every camera and shadow ray is traced per candidate). Then, timed once:
//! reading a 1,310,720-triangle mesh, building its BVH alone and its
//! whole traced structure (BVH and inner ball) on two threads, a session
//! on two threads (which builds them) and a render. Each timed case also
//! prints its renders per CPU second (both threads' time summed), which a
//! shared machine's load changes far less than the wall-clock rate, and,
//! where every ray is traced per candidate, the rays a render traces
//! (counted: camera, reflected, and one shadow ray per hit facing the
//! light, however it is answered) and so the rays per second. `cargo
//! bench --bench mesh`; figures in docs/benchmarks.md.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rand::{Rng, SeedableRng};
use scenefit::render::{from_spec, RenderSession};
use scenefit::scene::{parse, ParamSpace, Scene};
use std::path::Path;

#[path = "../tests/common/icosphere.rs"]
mod icosphere;

/// The unit icosphere subdivided `level` times, scaled to `radius` about
/// `c`, as binary PLY with vertex normals (20 * 4^level triangles).
fn icosphere(path: &Path, level: u32, c: [f32; 3], radius: f32) {
    let (verts, faces) = icosphere::unit_icosphere(level);
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        verts.len(),
        faces.len()
    )
    .into_bytes();
    for v in &verts {
        for k in 0..3 {
            out.extend((c[k] + radius * v[k]).to_le_bytes());
        }
        for x in v {
            out.extend(x.to_le_bytes());
        }
    }
    for f in &faces {
        out.push(3);
        for i in f {
            out.extend((*i as i32).to_le_bytes());
        }
    }
    std::fs::write(path, out).unwrap();
}

/// The bench scene with `shape` as the object and `free` free.
fn scene(shape: serde_json::Value, free: serde_json::Value) -> Scene {
    let v = serde_json::json!({
        "format": "scenefit-scene/1",
        "image": {"width": 128, "height": 96},
        "camera": {"type": "perspective", "position": [0, 1.5, 5], "look_at": [0, 0.5, 0], "up": [0, 1, 0], "fov_y_deg": 40},
        "render": {"indirect": false},
        "lights": [{"name": "key", "type": "point", "position": [1, 3, 2], "color": [1, 1, 1], "intensity": 10.0}],
        "objects": [
            {"name": "ball", "shape": shape, "transform": {"rotate_deg": [0, 0, 0], "translate": [0, 0, 0]}, "material": {"color": [0.8, 0.7, 0.1], "specular": 0.3, "shininess": 30}},
            {"name": "floor", "shape": {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
             "material": {"color": [0.6, 0.6, 0.6]}}
        ],
        "free": free
    });
    parse(&v.to_string(), "bench scene", &[]).expect("bench scene is valid")
}

fn generation(base: &Scene) -> (Box<dyn RenderSession>, Vec<Scene>, ParamSpace) {
    let space = ParamSpace::from_scene(base);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let scenes: Vec<Scene> = (0..80)
        .map(|_| {
            let u: Vec<f64> = (0..space.dim()).map(|_| rng.gen()).collect();
            space.scene_at(base, &u)
        })
        .collect();
    let jobs = std::thread::available_parallelism().map_or(1, |n| n.get());
    let session = from_spec("phong")
        .unwrap()
        .session(base, &space, jobs)
        .unwrap();
    (session, scenes, space)
}

fn bench(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let mut shapes = vec![(
        "sphere".to_string(),
        serde_json::json!({"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5}),
    )];
    for level in [3, 6] {
        let p = dir.path().join(format!("ico{level}.ply"));
        icosphere(&p, level, [0.0, 0.5, 0.0], 0.5);
        let faces = 20 * 4u32.pow(level);
        shapes.push((
            format!("mesh_{faces}"),
            serde_json::json!({"type": "mesh", "file": p}),
        ));
    }
    let light = serde_json::json!([
        {"param": "lights.key.position", "min": [-3, 0.5, -3], "max": [3, 5, 5]},
        {"param": "lights.key.intensity", "min": 1, "max": 50}
    ]);
    let floor = serde_json::json!([{"param": "objects.floor.shape.point", "min": [0, -0.1, 0], "max": [0, 0, 0]}]);
    let pose = serde_json::json!([
        {"param": "objects.ball.transform.rotate_deg", "min": [0, -90, 0], "max": [0, 90, 0]},
        {"param": "objects.ball.transform.translate", "min": [-0.3, 0, -0.3], "max": [0.3, 0, 0.3]}
    ]);
    let mut group = c.benchmark_group("phong_mesh_generation_of_80");
    group.throughput(Throughput::Elements(80));
    group.sample_size(10);
    for (what, free) in [
        ("light_free", &light),
        ("geometry_moves", &floor),
        ("pose_free", &pose),
    ] {
        for (name, shape) in &shapes {
            let (mut session, scenes, space) = generation(&scene(shape.clone(), free.clone()));
            group.bench_function(format!("{what}/{name}"), |b| {
                b.iter(|| session.render_batch(&scenes, 0))
            });
            // renders per CPU second besides: on a shared machine the
            // wall-clock rate above says how busy the machine was
            let (t, c) = (std::time::Instant::now(), cpu());
            let mut n = 0;
            while n < 3 || t.elapsed().as_secs_f64() < 1.0 {
                session.render_batch(&scenes, 0);
                n += 1;
            }
            let renders = (n * scenes.len()) as f64;
            let (wall, per_cpu) = (renders / t.elapsed().as_secs_f64(), renders / (cpu() - c));
            eprintln!("{what}/{name}: {per_cpu:.0} renders per CPU second");
            if what != "light_free" {
                rays(&format!("{what}/{name}"), &scenes, &space, wall, per_cpu);
            }
        }
    }
    group.finish();
    big_mesh(dir.path());
}

/// The rays a render of each of `scenes` traces, counted, and so the rays
/// per second at `wall` renders per second and `per_cpu` per CPU second.
fn rays(what: &str, scenes: &[Scene], space: &ParamSpace, wall: f64, per_cpu: f64) {
    let mut all = scenefit::render::phong::measure::Rays::default();
    for s in scenes {
        let r = scenefit::render::phong::measure::rays_traced(s, space);
        all.camera += r.camera;
        all.secondary += r.secondary;
        all.shadow += r.shadow;
    }
    let n = scenes.len() as f64;
    let per_render = (all.camera + all.secondary + all.shadow) as f64 / n;
    eprintln!(
        "{what}: {per_render:.0} rays per render ({:.0} camera, {:.0} reflected or refracted, {:.0} shadow); {:.2} M rays/s ({wall:.0} renders/s over the CPU-rate loop), {:.2} M rays per CPU second",
        all.camera as f64 / n,
        all.secondary as f64 / n,
        all.shadow as f64 / n,
        per_render * wall * 1e-6,
        per_render * per_cpu * 1e-6
    );
}

/// Reading, checking and building the BVH of 1.3 M triangles, once.
fn big_mesh(dir: &Path) {
    let p = dir.join("ico8.ply");
    icosphere(&p, 8, [0.0, 0.5, 0.0], 0.5);
    let t = std::time::Instant::now();
    let mesh = scenefit::scene::mesh::read(&p).unwrap();
    let read = t.elapsed();
    build_alone(&mesh);
    // the scene reads the file (once per process) ...
    let big = scene(
        serde_json::json!({"type": "mesh", "file": p}),
        serde_json::json!([]),
    );
    // ... the session (two threads) builds the BVH (once per process) and
    // traces the camera rays; a render then shades them. Wall and CPU
    // seconds both: on a shared machine the wall time says little.
    let (t, c) = (std::time::Instant::now(), cpu());
    let mut session = from_spec("phong")
        .unwrap()
        .session(&big, &ParamSpace::default(), 2)
        .unwrap();
    let (build, build_cpu) = (t.elapsed(), cpu() - c);
    let t = std::time::Instant::now();
    session.render_batch(std::slice::from_ref(&big), 0)[0]
        .as_ref()
        .unwrap();
    eprintln!(
        "1310720 triangles: file read and checked in {read:.2?}; session on 2 threads (BVH built, camera rays traced) {build:.2?} wall, {build_cpu:.2} s CPU; a render {:.2?}",
        t.elapsed()
    );
}

/// The traced structure of `mesh` built alone on two threads, three
/// times each: the BVH, then everything (BVH, triangles in its order,
/// inner ball); medians of wall and CPU time, and per million triangles.
fn build_alone(mesh: &scenefit::scene::mesh::Mesh) {
    use scenefit::render::phong::measure;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let m = mesh.triangles.len() as f64 * 1e-6;
    let time = |f: &(dyn Fn() + Sync)| {
        let mut runs: Vec<(f64, f64)> = (0..3)
            .map(|_| {
                let (t, c) = (std::time::Instant::now(), cpu());
                pool.install(f);
                (t.elapsed().as_secs_f64(), cpu() - c)
            })
            .collect();
        runs.sort_by(|a, b| a.0.total_cmp(&b.0));
        runs[1]
    };
    let bvh = time(&|| assert_eq!(measure::build_bvh(mesh), mesh.triangles.len()));
    let all = time(&|| assert!(measure::build_mesh(mesh), "the icosphere is closed"));
    eprintln!(
        "{} triangles built alone on 2 threads (median of 3): BVH {:.3} s wall, {:.3} s CPU; BVH and inner ball {:.3} s wall, {:.3} s CPU; per million triangles {:.3} s wall, {:.3} s CPU",
        mesh.triangles.len(),
        bvh.0,
        bvh.1,
        all.0,
        all.1,
        all.0 / m,
        all.1 / m
    );
}

/// CPU seconds this process has used, over all its threads.
fn cpu() -> f64 {
    // SAFETY: getrusage only writes the struct it is given.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    let s = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    s(u.ru_utime) + s(u.ru_stime)
}

criterion_group!(benches, bench);
criterion_main!(benches);
