//! Helpers shared by the backend and plug-in tests: the scenes they render,
//! running the real `scenefit` binary in a fresh directory, and skipping
//! (only when CI is not "true") when a renderer is not installed.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub const BIN: &str = env!("CARGO_BIN_EXE_scenefit");

/// The crate's root, where examples/ and tests/plugins/ are.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// True when `program` can run; otherwise skips the test (prints why and
/// returns false) or, with CI=true, fails it.
pub fn have(program: &str, what: &str) -> bool {
    let found = which(program);
    if !found {
        let msg = format!("skipping: {what} not installed ({program} not found; scripts/install-renderers.sh installs it)");
        if std::env::var("CI").as_deref() == Ok("true") {
            panic!("{msg}; CI=true requires every renderer");
        }
        eprintln!("{msg}");
    }
    found
}

/// Mitsuba needs its Python package too.
pub fn have_mitsuba() -> bool {
    if !have("python3", "mitsuba (python3)") {
        return false;
    }
    let ok = Command::new("python3")
        .args(["-c", "import mitsuba"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !ok {
        let msg = "skipping: mitsuba not installed (python3 -m pip install mitsuba, or scripts/install-renderers.sh)";
        if std::env::var("CI").as_deref() == Ok("true") {
            panic!("{msg}; CI=true requires every renderer");
        }
        eprintln!("{msg}");
    }
    ok
}

fn which(program: &str) -> bool {
    std::env::var_os("PATH")
        .map(|paths| std::env::split_paths(&paths).any(|d| d.join(program).is_file()))
        .unwrap_or(false)
}

/// A fresh directory for one test.
pub fn tempdir() -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix("scenefit-test-")
        .tempdir()
        .expect("temp dir")
}

/// Runs the binary with `args` in `dir` (and extra environment).
pub fn run(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(BIN);
    c.args(args).current_dir(dir);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("scenefit runs")
}

/// Panics with the output when `o` did not exit with `code`.
pub fn expect_code(o: &Output, code: i32) {
    if o.status.code() != Some(code) {
        panic!(
            "expected exit code {code}, got {:?}\nstdout: {}\nstderr: {}",
            o.status.code(),
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

/// A diffuse-only scene: a yellow ball on a grey floor under one point
/// light with inverse-square falloff, hard shadows, direct light only.
pub fn diffuse_scene(samples: u32, antialias: u32) -> serde_json::Value {
    serde_json::json!({
        "format": "scenefit-scene/1",
        "image": {"width": 128, "height": 96},
        "camera": {"type": "perspective", "position": [0, 1.5, 5], "look_at": [0, 0.5, 0], "up": [0, 1, 0], "fov_y_deg": 40},
        "ambient": [0, 0, 0],
        "render": {"samples": samples, "indirect": false, "antialias": antialias},
        "lights": [{"name": "key", "type": "point", "position": [1, 3, 2], "color": [1, 1, 1], "intensity": 10.0,
                    "falloff": "inverse_square", "radius": 0.0}],
        "objects": [
            {"name": "ball", "shape": {"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5},
             "material": {"color": [0.8, 0.7, 0.1], "diffuse": 1.0}},
            {"name": "floor", "shape": {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
             "material": {"color": [1, 1, 1], "diffuse": 0.6}}
        ]
    })
}

/// `scene` with free parameters: the light's intensity and the floor's diffuse.
pub fn with_free(mut scene: serde_json::Value) -> serde_json::Value {
    scene["free"] = serde_json::json!([
        {"param": "lights.key.intensity", "min": 4, "max": 20},
        {"param": "objects.floor.material.diffuse", "min": 0.2, "max": 1.0}
    ]);
    scene
}

/// Writes JSON to `dir/name`, returning the file name.
pub fn write_json(dir: &Path, name: &str, v: &serde_json::Value) -> String {
    std::fs::write(
        dir.join(name),
        serde_json::to_string_pretty(v).expect("json"),
    )
    .expect("write");
    name.to_string()
}

/// result.json of a fit.
pub fn result(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("result.json")).expect("result.json");
    serde_json::from_str(&text).expect("result.json is JSON")
}
