//! A set fit (`fit --shots`) resumes as a single fit does: killed with
//! SIGKILL at random moments (inside its blocks too), resumed after each
//! kill, it ends with the parameters and deviations of the uninterrupted
//! run with the same seed; a finished set run resumed gives its result
//! again.

mod common;

use common::{json, scenefit, stderr};
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// A small scene: the ball's colour shared, the light's intensity free
/// per photograph.
const SCENE: &str = r#"{
  "format": "scenefit-scene/1",
  "image": {"width": 64, "height": 48},
  "camera": {"type": "perspective", "position": [0, 1.5, 5], "look_at": [0, 0.5, 0],
             "up": [0, 1, 0], "fov_y_deg": 40},
  "lights": [{"name": "key", "type": "point", "position": [1, 3, 2], "color": [1, 1, 1],
              "intensity": 10.0}],
  "objects": [
    {"name": "ball", "shape": {"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5},
     "material": {"color": [0.8, 0.5, 0.2], "diffuse": 1.0, "specular": 0.3, "shininess": 40}},
    {"name": "floor", "shape": {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
     "material": {"color": [0.6, 0.6, 0.6], "diffuse": 1.0}}
  ],
  "free": [{"param": "objects.ball.material.color", "min": [0, 0, 0], "max": [1, 1, 1]},
           {"param": "lights.key.intensity", "min": 1, "max": 30, "per_shot": true}]
}"#;

/// The photographs: the light moved and dimmed from one to the next.
const SHOTS: [(&str, &str, f64); 3] = [
    ("a", "[1,3,2]", 12.0),
    ("b", "[-1.5,2.5,2]", 18.0),
    ("c", "[0,3.5,-1]", 9.0),
];

/// scene.json, one target per photograph and shots.json in `d`.
fn write_set(d: &Path) {
    std::fs::write(d.join("scene.json"), SCENE).unwrap();
    let mut shots = Vec::new();
    for (name, position, intensity) in SHOTS {
        let out = scenefit(
            d,
            &[
                "render",
                "scene.json",
                "-o",
                &format!("{name}.png"),
                "--set",
                &format!("lights.key.position={position}"),
                "--set",
                &format!("lights.key.intensity={intensity}"),
                "--set",
                "objects.ball.material.color=[0.3,0.6,0.4]",
            ],
        );
        assert!(out.status.success(), "{}", stderr(&out));
        shots.push(serde_json::json!({
            "name": name,
            "target": format!("{name}.png"),
            "set": {"lights.key.position": serde_json::from_str::<serde_json::Value>(position).unwrap()}
        }));
    }
    let file = serde_json::json!({"format": "scenefit-shots/1", "shots": shots});
    std::fs::write(d.join("shots.json"), file.to_string()).unwrap();
}

/// The set fit's arguments into `out`: small, and with the hybrid search
/// (its local runs are part of what a resume must restore).
fn args(out: &str) -> Vec<String> {
    [
        "fit",
        "scene.json",
        "--shots",
        "shots.json",
        "-o",
        out,
        "--strategy",
        "hybrid",
        "--population",
        "16",
        "--generations",
        "40",
        "--rounds",
        "2",
        "--seed",
        "5",
        "--jobs",
        "2",
        "-q",
    ]
    .map(String::from)
    .to_vec()
}

/// A small pseudo-random generator for the kill moments (its seed printed,
/// so a failure can be replayed with SCENEFIT_KILL_SEED).
struct Moments(u64);

impl Moments {
    fn below(&mut self, n: u64) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 33) % n.max(1)
    }
}

/// What must match: the shared parameters, the deviation, every
/// photograph's own parameters and deviation, and the standard errors.
fn outcome(dir: &Path) -> [serde_json::Value; 4] {
    let r = json(&dir.join("result.json"));
    [
        r["params"].clone(),
        r["deviation"].clone(),
        r["shots"].clone(),
        r["identifiability"].clone(),
    ]
}

#[test]
fn a_set_fit_killed_at_random_moments_resumes_to_the_same_result() {
    let d = tempfile::tempdir().unwrap();
    write_set(d.path());
    let started = Instant::now();
    let out = scenefit(
        d.path(),
        &args("straight")
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let run_ms = started.elapsed().as_millis() as u64;
    let straight = outcome(&d.path().join("straight"));
    // The hybrid's last shared block gives the shared colour's standard
    // errors, as a single fit's hybrid search does.
    let r = json(&d.path().join("straight/result.json"));
    let errors = &r["identifiability"]["standard_errors"];
    assert!(errors["objects.ball.material.color.r"].is_number(), "{r}");

    let seed = std::env::var("SCENEFIT_KILL_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .unwrap()
                .as_nanos() as u64
        });
    eprintln!("kill moments from SCENEFIT_KILL_SEED={seed}");
    let mut moments = Moments(seed);
    let killed = d.path().join("killed");
    let mut kills = 0;
    for _ in 0..12 {
        if killed.join("result.json").exists() {
            break;
        }
        let mut a = args("killed");
        // Killed before its first save, the directory holds nothing to
        // resume: the run starts afresh, as the refusal advises.
        if killed.join("checkpoint.json").exists() {
            a.push("--resume".into());
        }
        let mut child = Command::new(env!("CARGO_BIN_EXE_scenefit"))
            .args(&a)
            .current_dir(d.path())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        // At most a quarter of a run (a resumed run has less left to do):
        // every run but the last is killed.
        std::thread::sleep(Duration::from_millis(5 + moments.below(run_ms / 4)));
        if child.try_wait().unwrap().is_none() {
            kills += 1;
        }
        child.kill().unwrap();
        child.wait().unwrap();
    }
    assert!(kills >= 2, "only {kills} runs were killed before their end");
    let mut a = args("killed");
    if killed.join("checkpoint.json").exists() {
        a.push("--resume".into());
    }
    let out = scenefit(d.path(), &a.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(outcome(&killed), straight, "{kills} kills, seed {seed}");

    // A finished set run resumed: the same result again, nothing refused.
    let mut again = args("killed");
    again.push("--resume".into());
    let out = scenefit(
        d.path(),
        &again.iter().map(String::as_str).collect::<Vec<_>>(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(outcome(&killed), straight);
}

#[test]
fn a_set_resume_with_other_inputs_is_refused_naming_them() {
    let d = tempfile::tempdir().unwrap();
    write_set(d.path());
    let a = args("run");
    let out = scenefit(d.path(), &a.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(out.status.success(), "{}", stderr(&out));
    let mut b = a.clone();
    b.extend(["--resume", "--seed", "6"].map(String::from));
    let out = scenefit(d.path(), &b.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("--seed"), "{}", stderr(&out));
    // Without --resume or --overwrite an earlier set run is refused,
    // naming both.
    let out = scenefit(d.path(), &a.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    assert!(e.contains("--resume") && e.contains("--overwrite"), "{e}");
}

#[test]
fn a_set_saved_by_an_earlier_build_resumes_and_is_no_single_fits_checkpoint() {
    let d = tempfile::tempdir().unwrap();
    write_set(d.path());
    let a = args("run");
    let out = scenefit(d.path(), &a.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(out.status.success(), "{}", stderr(&out));
    let done = outcome(&d.path().join("run"));
    // One photograph's fit resumed from a set's checkpoint: one line
    // saying what the directory holds.
    let single = [
        "fit",
        "scene.json",
        "--target",
        "a.png",
        "-o",
        "run",
        "--resume",
    ];
    let out = scenefit(d.path(), &single);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("a set's fit"), "{}", stderr(&out));
    assert_eq!(stderr(&out).trim().lines().count(), 1, "{}", stderr(&out));
    // An earlier build saved the same state, format 2, as set_state.json.
    let run = d.path().join("run");
    let mut state = json(&run.join("checkpoint.json"));
    state["format"] = "scenefit-set-state/2".into();
    state.as_object_mut().unwrap().remove("last_shared");
    std::fs::write(run.join("set_state.json"), state.to_string()).unwrap();
    std::fs::remove_file(run.join("checkpoint.json")).unwrap();
    let mut b = a.clone();
    b.push("--resume".into());
    let out = scenefit(d.path(), &b.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(out.status.success(), "{}", stderr(&out));
    let again = outcome(&run);
    assert_eq!(again[..3], done[..3]);
}
