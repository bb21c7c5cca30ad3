//! Renders per second of a backend inside a fit, and the share of the
//! pool's time spent outside the renderer: a fit of scenes/sphere_floor.json
//! (128x96, 16 samples, its five free parameters) to a target the same
//! backend rendered. Figures in docs/benchmarks-backends.md.
//!
//! cargo run --release --example backend_speed -- RENDERER [--jobs N]
//!     [--population P] [--generations G] [--direct]
//!
//! `--direct` sets `render.indirect` false. Renders/s counts the fit's
//! evaluations over its wall time (worker start-up excluded, as the fit
//! reports it); "outside" is 1 - (time renderers were busy) / (slots x
//! wall time), slots = min(jobs, population); "no render in flight" is the
//! share of the fit's wall time in which scenefit alone was working (the
//! optimizer, the metric, checkpoints, writing requests, reading images). CPU per render splits the
//! CPU time into scenefit's own and its renderer processes' (workers are
//! counted once they exit, at the end of the fit).
//!
//! A second line is the row of the table in docs/benchmarks-backends.md,
//! with the 1-minute load average read before the fit;
//! scripts/bench-backends.sh runs the three backends and prints the table.

use scenefit::exec::stats;
use scenefit::fit::{self, FitConfig, FitTarget};
use scenefit::optimize::DeConfig;
use scenefit::render::{from_spec, render_one};
use scenefit::scene::load;
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(renderer_name) = args.first().cloned() else {
        eprintln!("usage: backend_speed RENDERER [--jobs N] [--population P] [--generations G] [--direct]");
        std::process::exit(2);
    };
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .and_then(|v| v.parse::<usize>().ok())
    };
    let renderer = from_spec(&renderer_name).unwrap_or_else(|e| fail(&e.to_string()));
    let jobs = value("--jobs").unwrap_or_else(|| renderer.default_jobs());
    let population = value("--population").unwrap_or(80);
    let generations = value("--generations").unwrap_or(3);

    let mut scene = load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/sphere_floor.json"))
        .unwrap_or_else(|e| fail(&e.to_string()));
    scene.render.samples = 16;
    if args.iter().any(|a| a == "--direct") {
        scene.render.indirect = false;
    }
    let load = load_average();
    let target = render_one(renderer.as_ref(), &scene, 0).unwrap_or_else(|e| fail(&e.to_string()));
    let dir = tempfile::tempdir().unwrap_or_else(|e| fail(&e.to_string()));
    let config = FitConfig {
        de: DeConfig {
            population,
            seed: 5,
            ..DeConfig::default()
        },
        generations,
        jobs,
        snapshot_every: 1000,
        ..FitConfig::default()
    };
    stats::reset();
    let cpu_before = cpu_seconds();
    let started = std::time::Instant::now();
    let result = fit::run(
        &scene,
        &FitTarget {
            image: target,
            levels: None,
            mask: None,
            path: None,
            encoding: None,
        },
        renderer.as_ref(),
        &config,
        dir.path(),
        &mut (),
    )
    .unwrap_or_else(|e| fail(&e.to_string()))
    .result;
    let total = started.elapsed().as_secs_f64();
    let cpu_after = cpu_seconds();
    let (own, children) = (cpu_after.0 - cpu_before.0, cpu_after.1 - cpu_before.1);
    let (attempts, busy, idle) = stats::snapshot();
    let wall = result.wall_seconds;
    let slots = jobs.min(population) as f64;
    let outside = 1.0 - busy.as_secs_f64() / (slots * wall);
    // no render in flight, less what the fit does not count (start-up)
    let idle_share = ((idle.as_secs_f64() - (total - wall)) / wall).max(0.0);
    println!(
        "{renderer_name}: jobs {jobs}, population {population}, {} renders in {wall:.2} s = {:.1} renders/s; \
         renderer busy {:.1} % of {slots} slots, outside {:.1} %; no render in flight {:.1} % of the time; {attempts} attempts, {} failed; \
         run incl. start-up {total:.2} s; deviation {:.3} %; \
         CPU per render: scenefit {:.1} ms, renderer processes {:.1} ms ({:.1} % in scenefit)",
        result.evaluations,
        result.evaluations as f64 / wall,
        100.0 * (1.0 - outside),
        100.0 * outside,
        100.0 * idle_share,
        result.failed_renders,
        result.deviation.average,
        1e3 * own / result.evaluations as f64,
        1e3 * children / result.evaluations as f64,
        100.0 * own / (own + children).max(1e-12)
    );
    let mode = format!(
        "{jobs} {}, {}",
        if renderer_name == "povray" {
            "processes"
        } else {
            "workers"
        },
        if scene.render.indirect {
            "indirect"
        } else {
            "direct"
        }
    );
    println!(
        "| {renderer_name} | {mode} | {load} | {:.1} | {:.1} ms | {:.2} ms | {:.1} % | {:.1} % |",
        result.evaluations as f64 / wall,
        1e3 * children / result.evaluations as f64,
        1e3 * own / result.evaluations as f64,
        100.0 * outside,
        100.0 * idle_share
    );
}

/// The 1-minute load average (/proc/loadavg), or "?".
fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "?".into())
}

/// CPU seconds of this process and of its waited-for children
/// (/proc/self/stat utime + stime, cutime + cstime).
fn cpu_seconds() -> (f64, f64) {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // fields after the command name, which ends with ')'
    let rest = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = rest
        .split_whitespace()
        .map(|x| x.parse().unwrap_or(0.0))
        .collect();
    let tick = 100.0; // USER_HZ on Linux
    let get = |i: usize| f.get(i).copied().unwrap_or(0.0) / tick;
    // utime, stime, cutime, cstime are fields 14-17; `rest` starts at field 3
    (get(11) + get(12), get(13) + get(14))
}

fn fail(msg: &str) -> ! {
    eprintln!("error: {msg}");
    std::process::exit(1)
}
