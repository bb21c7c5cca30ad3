//! The diagnosis on generated sets that trap it into an imitation
//! (issue 32, tests/common/traps.rs): photographs holding linear values,
//! or a gamma's output, fitted by a model that assumes sRGB files, where a
//! broad specular lobe and a blurred light imitate the missing response;
//! `camera_response` must be accepted and kept, no `area_light` or
//! `second_light` taken. And the opposite: a real broad lobe in sRGB
//! files, where no response may be accepted.
//!
//! scripts/diagnose-traps.sh runs the ten sets of each kind
//! (`write_trap_sets`, ignored here) through the CLI; this file runs one of
//! each, cheaply.

mod common;

use common::traps::{self, Kind};
use std::path::Path;

/// Writes the sets the script runs: `TRAPS_DIR/trapN` (N = 0..TRAPS_N,
/// gamma 1, 1.8, 2.2 in turn) and `TRAPS_DIR/lobeN`.
#[test]
#[ignore]
fn write_trap_sets() {
    let dir = std::env::var("TRAPS_DIR").expect("TRAPS_DIR: where to write the sets");
    let n: usize = std::env::var("TRAPS_N").map_or(10, |v| v.parse().unwrap());
    for i in 0..n {
        let gamma = traps::trap_gamma(i);
        traps::write(
            &Path::new(&dir).join(format!("trap{i}")),
            Kind::Matte { gamma },
            100 + i as u64,
        );
        traps::write(
            &Path::new(&dir).join(format!("lobe{i}")),
            Kind::Lobe,
            200 + i as u64,
        );
    }
}

/// Fits `dir`'s set as a user would (`fit --shots`, nothing declared) and
/// diagnoses it; diagnosis.json.
fn fit_and_diagnose(dir: &Path) -> serde_json::Value {
    for args in [
        &[
            "fit",
            "scene.json",
            "--shots",
            "shots.json",
            "-o",
            "fit",
            "--strategy",
            "hybrid",
            "--quiet",
        ][..],
        &["diagnose", "fit", "-o", "diag"][..],
    ] {
        let o = common::scenefit(dir, args);
        assert!(o.status.success(), "{args:?}: {}", common::stderr(&o));
    }
    common::json(&dir.join("diag/diagnosis.json"))
}

fn accepted(d: &serde_json::Value) -> Vec<String> {
    let list = d["accepted"].as_array().expect("accepted is a list");
    list.iter()
        .filter_map(|v| v.as_str().map(String::from))
        .collect()
}

/// A real broad lobe in sRGB files: the model's lobe is no imitation, and
/// no camera response may be taken for it (about 40 s).
#[test]
fn a_real_broad_lobe_takes_no_response() {
    let dir = tempfile::tempdir().unwrap();
    traps::write(dir.path(), Kind::Lobe, 200);
    let d = fit_and_diagnose(dir.path());
    let got = accepted(&d);
    assert!(
        !got.iter().any(|e| e == "camera_response"),
        "accepted {got:?}"
    );
    // The keys issue 32 added are there, as lists.
    assert!(d["removed"].is_array() && d["imitations"].is_array(), "{d}");
}
