//! Helpers shared by the integration tests: run the real binary in a fresh
//! temporary directory, and find the example scenes.

#![allow(dead_code)]

pub mod bumps;
pub mod icosphere;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The example scenes directory.
pub fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

/// Runs `scenefit ARGS` in `dir`.
pub fn scenefit(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_scenefit"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .output()
        .expect("the scenefit binary runs")
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).to_string()
}

/// Reads a JSON file.
pub fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(
        &std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())),
    )
    .unwrap()
}

pub mod texture_set;
pub mod traps;

/// A diagnosis's short search per trial (each trial's refit starts from
/// the fit): for the tests that diagnose a generated set end to end, so
/// that a set takes minutes, not an hour (docs/results.md, textured sets).
pub const QUICK_DIAGNOSE: [&str; 6] = [
    "--population",
    "8",
    "--generations",
    "6",
    "--restart-generations",
    "0",
];

/// Fits the set in `dir` through the CLI (`scenefit fit FIT... -o fit`),
/// then diagnoses the fit (`scenefit diagnose fit -o diag DIAGNOSE...`),
/// each asserted to succeed; diag/diagnosis.json.
pub fn fit_and_diagnose(dir: &Path, fit: &[&str], diagnose: &[&str]) -> serde_json::Value {
    let fit: Vec<&str> = [&["fit"][..], fit, &["-o", "fit"]].concat();
    let diagnose: Vec<&str> = [&["diagnose", "fit", "-o", "diag"][..], diagnose].concat();
    for args in [fit, diagnose] {
        let o = scenefit(dir, &args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    }
    json(&dir.join("diag/diagnosis.json"))
}

/// The effects a diagnosis.json accepted, in order.
pub fn accepted(d: &serde_json::Value) -> Vec<String> {
    let list = d["accepted"].as_array().expect("accepted is a list");
    list.iter()
        .filter_map(|v| v.as_str().map(String::from))
        .collect()
}

/// The signature and header chunk of a PNG of `w` x `h`, nothing else.
pub fn png_header(w: u32, h: u32) -> Vec<u8> {
    let mut chunk = b"IHDR".to_vec();
    chunk.extend(w.to_be_bytes());
    chunk.extend(h.to_be_bytes());
    chunk.extend([8, 2, 0, 0, 0]);
    let mut b = b"\x89PNG\r\n\x1a\n".to_vec();
    // the header, then an empty data chunk: a decoder has read the
    // header in full before it finds no pixels
    for chunk in [chunk, b"IDAT".to_vec(), b"IEND".to_vec()] {
        b.extend((chunk.len() as u32 - 4).to_be_bytes());
        b.extend(&chunk);
        b.extend(crc32(&chunk).to_be_bytes());
    }
    b
}

pub fn crc32(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}
