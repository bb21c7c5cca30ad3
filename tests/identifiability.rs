//! A fit with the hybrid strategy reports, in result.json and the report,
//! a standard error for every search coordinate and the strongest
//! correlations, from its final Jacobian.

mod common;

use common::{json, scenefit, scenes, stderr};

#[test]
fn hybrid_fit_reports_standard_errors_and_correlations() {
    let d = tempfile::tempdir().unwrap();
    let scene = scenes().join("sphere_floor.json");
    let s = scene.to_str().unwrap();
    let out = scenefit(
        d.path(),
        &[
            "render",
            s,
            "-o",
            "t.png",
            "--set",
            "lights.key.position=[1.5,2.5,2.5]",
            "--width",
            "64",
            "--height",
            "48",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let out = scenefit(
        d.path(),
        &[
            "fit",
            s,
            "--target",
            "t.png",
            "-o",
            "f",
            "--strategy",
            "hybrid",
            "--generations",
            "300",
            "--set",
            "image.width=64",
            "--set",
            "image.height=48",
            "-q",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let r = json(&d.path().join("f/result.json"));
    assert_eq!(r["strategy"], "hybrid");
    let se = r["identifiability"]["standard_errors"]
        .as_object()
        .expect("standard errors in result.json");
    // sphere_floor frees the light's position (3), intensity (1) and the
    // ball's colour (3).
    assert_eq!(se.len(), 7, "{se:?}");
    for (k, v) in se {
        let v = v.as_f64().unwrap_or_else(|| panic!("{k}: {v}"));
        assert!(v.is_finite() && v > 0.0, "{k}: {v}");
    }
    for c in r["identifiability"]["correlations"].as_array().unwrap() {
        let x = c["r"].as_f64().unwrap();
        assert!((0.5..=1.0).contains(&x.abs()), "{c}");
    }
    let out = scenefit(d.path(), &["report", "f"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let html = std::fs::read_to_string(d.path().join("f/report.html")).unwrap();
    assert!(html.contains("Identifiability"));
}

/// Noisy targets fitted for the spread of the answers.
const FITS: u64 = 30;

/// Photon noise: each value decoded to linear light, replaced by a
/// Poisson count of `full_well` photons at full scale (Gaussian with the
/// count's variance), and encoded back to 8-bit sRGB.
fn add_photon_noise(path: &std::path::Path, full_well: f64, seed: u64) {
    use rand::{Rng, SeedableRng};
    let mut img = image::open(path).unwrap().to_rgb8();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let decode = |c: f64| {
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let encode = |l: f64| {
        if l <= 0.0031308 {
            12.92 * l
        } else {
            1.055 * l.powf(1.0 / 2.4) - 0.055
        }
    };
    for v in img.iter_mut() {
        let photons = decode(*v as f64 / 255.0) * full_well;
        let (u1, u2): (f64, f64) = (rng.gen::<f64>().max(1e-12), rng.gen());
        let z = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
        let counted = (photons + photons.sqrt() * z).max(0.0) / full_well;
        *v = (255.0 * encode(counted.min(1.0))).round() as u8;
    }
    img.save(path).unwrap();
}

/// Issue 12: the standard errors a fit reports from its final Jacobian
/// are the spread its answer would have over other photographs of the same
/// scene. Thirty targets, each its own photon-noise realisation of one
/// truth, each fitted with its own seed: for every coordinate the standard
/// deviation of the answers and the median reported standard error agree
/// within a factor of 2. (Ten fits, as the issue asks, pin a standard
/// deviation only to about ±35 %, so a correct estimate would fail a
/// factor of 2 on one of seven coordinates one run in ten; docs/benchmarks.md
/// gives the first ten's figures too.)
#[test]
fn standard_errors_match_the_spread_of_noisy_fits() {
    let d = tempfile::tempdir().unwrap();
    // sphere_floor at 64x48 with the ball's colour searched in RGB, so
    // that result.json's values and the standard errors share coordinates.
    let mut scene = json(&scenes().join("sphere_floor.json"));
    scene["image"] = serde_json::json!({"width": 64, "height": 48});
    scene["free"] = serde_json::json!([
        {"param": "lights.key.position", "min": [-3, 0.5, -3], "max": [3, 5, 5]},
        {"param": "lights.key.intensity", "min": 1, "max": 50},
        {"param": "objects.ball.material.color", "min": [0, 0, 0], "max": [1, 1, 1]}
    ]);
    std::fs::write(d.path().join("scene.json"), scene.to_string()).unwrap();
    let out = scenefit(
        d.path(),
        &[
            "render",
            "scene.json",
            "-o",
            "truth.png",
            "--set",
            "lights.key.position=[1.4,3.6,2.5]",
            "--set",
            "lights.key.intensity=14",
            "--set",
            "objects.ball.material.color=[0.3,0.6,0.8]",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let names = [
        ("lights.key.position", 3),
        ("lights.key.intensity", 1),
        ("objects.ball.material.color", 3),
    ];
    let suffixes = |n: &str, dim: usize| -> Vec<String> {
        match dim {
            1 => vec![n.to_string()],
            _ if n.ends_with("color") => ["r", "g", "b"].map(|c| format!("{n}.{c}")).to_vec(),
            _ => ["x", "y", "z"].map(|c| format!("{n}.{c}")).to_vec(),
        }
    };
    let mut values: Vec<Vec<f64>> = Vec::new();
    let mut errors: Vec<Vec<f64>> = Vec::new();
    for seed in 1..=FITS {
        let target = d.path().join(format!("t{seed}.png"));
        std::fs::copy(d.path().join("truth.png"), &target).unwrap();
        add_photon_noise(&target, 2000.0, seed);
        let dir = format!("f{seed}");
        let seed_arg = seed.to_string();
        let out = scenefit(
            d.path(),
            &[
                "fit",
                "scene.json",
                "--target",
                target.to_str().unwrap(),
                "-o",
                &dir,
                "--strategy",
                "hybrid",
                "--seed",
                &seed_arg,
                "--generations",
                "400",
                "-q",
            ],
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let r = json(&d.path().join(&dir).join("result.json"));
        let (mut v, mut e) = (Vec::new(), Vec::new());
        for (n, dim) in names {
            let p = &r["params"][n];
            let xs: Vec<f64> = match dim {
                1 => vec![p.as_f64().unwrap()],
                _ => p
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_f64().unwrap())
                    .collect(),
            };
            v.extend(xs);
            for c in suffixes(n, dim) {
                let se = r["identifiability"]["standard_errors"][&c]
                    .as_f64()
                    .unwrap_or_else(|| panic!("seed {seed}: no standard error for {c}"));
                e.push(se);
            }
        }
        values.push(v);
        errors.push(e);
    }
    let coords: Vec<String> = names
        .iter()
        .flat_map(|&(n, dim)| suffixes(n, dim))
        .collect();
    let mut report = Vec::new();
    let mut worst: f64 = 1.0;
    for (i, c) in coords.iter().enumerate() {
        let xs: Vec<f64> = values.iter().map(|v| v[i]).collect();
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        let sd =
            (xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (xs.len() - 1) as f64).sqrt();
        let mut se: Vec<f64> = errors.iter().map(|e| e[i]).collect();
        se.sort_by(f64::total_cmp);
        let median = se[se.len() / 2];
        let ratio = sd / median;
        worst = if (ratio.ln()).abs() > worst.ln().abs() {
            ratio
        } else {
            worst
        };
        report.push(format!(
            "{c}: spread {sd:.5}, standard error {median:.5}, ratio {ratio:.2}"
        ));
    }
    println!("{FITS} fits\n{}", report.join("\n"));
    assert!(
        (0.5..=2.0).contains(&worst),
        "spread / standard error {worst:.2} outside [0.5, 2]:\n{}",
        report.join("\n")
    );
}
