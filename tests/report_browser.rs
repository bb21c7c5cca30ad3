//! The report as a reader sees it: a tiny pipeline (Phong in both stages,
//! so no external renderer is needed) and a tiny fit, their report.html
//! opened in headless Chromium. Every <img> must load, every link must
//! point at a file that exists, and the screenshot must show a page.
//!
//! Chromium is Debian's `chromium` (scripts/install-browser.sh installs
//! it). Without it the test is skipped, except on CI (CI=true), where it
//! fails.

mod common;
use common::*;
use std::path::{Path, PathBuf};
use std::process::Command;

fn chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    ["chromium", "chromium-browser", "google-chrome"]
        .iter()
        .find_map(|name| which(name))
}

fn which(name: &str) -> Option<PathBuf> {
    std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|d| d.join(name))
            .find(|p| p.is_file())
    })
}

/// Headless Chromium with the flags this machine's closed network needs
/// and a fresh profile.
fn headless(browser: &Path, profile: &Path) -> Command {
    let mut c = Command::new(browser);
    c.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--hide-scrollbars",
    ])
    .arg(format!("--user-data-dir={}", profile.display()));
    c
}

/// Every value of `attr="..."` in the page.
fn attribute_values(html: &str, attr: &str) -> Vec<String> {
    let needle = format!("{attr}=\"");
    let mut out = Vec::new();
    let mut rest = html;
    while let Some(i) = rest.find(&needle) {
        rest = &rest[i + needle.len()..];
        if let Some(end) = rest.find('"') {
            out.push(rest[..end].to_string());
            rest = &rest[end..];
        }
    }
    out
}

/// Undoes the report's percent-encoding of link paths.
fn decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            if let Ok(v) = u8::from_str_radix(&s[i + 1..i + 3], 16) {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).to_string()
}

/// Checks one report directory in the browser; returns the screenshot.
fn check_in_browser(browser: &Path, run: &Path, work: &Path) -> PathBuf {
    let html = std::fs::read_to_string(run.join("report.html")).unwrap();
    assert!(
        !html.contains("http://") && !html.contains("https://"),
        "the report must not reach the network"
    );
    assert!(!html.contains("<script"), "the report is static");
    let images = attribute_values(&html, "src");
    assert!(
        images.len() >= 6,
        "only {} images in the report",
        images.len()
    );
    for link in images.iter().chain(&attribute_values(&html, "href")) {
        if link.starts_with('#') {
            continue;
        }
        let target = run.join(decode(link));
        assert!(target.is_file(), "broken link in report.html: {link}");
    }

    // The browser's own verdict: a copy of the page with a script that
    // counts images the browser could not decode.
    let probe = run.join("report_probe.html");
    let script = "<script>window.addEventListener('load', () => {\
        const bad = [...document.images].filter(i => !i.complete || i.naturalWidth === 0);\
        document.body.dataset.images = document.images.length;\
        document.body.dataset.broken = bad.length;\
        document.body.dataset.brokenSrc = bad.map(i => i.getAttribute('src')).join(' ');\
        });</script></body>";
    std::fs::write(&probe, html.replace("</body>", script)).unwrap();
    let profile = tempfile::tempdir_in(work).unwrap();
    let out = headless(browser, profile.path())
        .args(["--virtual-time-budget=10000", "--dump-dom"])
        .arg(format!("file://{}", probe.display()))
        .output()
        .expect("chromium runs");
    let dom = String::from_utf8_lossy(&out.stdout).to_string();
    std::fs::remove_file(&probe).unwrap();
    assert!(
        dom.contains("data-broken=\"0\""),
        "images the browser could not load: {:?}\n{}",
        attribute_values(&dom, "data-broken-src"),
        String::from_utf8_lossy(&out.stderr)
    );
    let counted = attribute_values(&dom, "data-images");
    assert_eq!(counted, vec![images.len().to_string()]);

    // A screenshot, to look at and to check that something was drawn.
    let shot = work.join(format!(
        "{}_screenshot.png",
        run.file_name().unwrap().to_string_lossy()
    ));
    let profile = tempfile::tempdir_in(work).unwrap();
    let out = headless(browser, profile.path())
        .arg(format!("--screenshot={}", shot.display()))
        .arg("--window-size=1400,3800")
        .arg(format!("file://{}", run.join("report.html").display()))
        .output()
        .expect("chromium runs");
    assert!(
        shot.is_file(),
        "no screenshot: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let img = image::open(&shot).unwrap().to_rgb8();
    let inked = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
    let dark = img.pixels().filter(|p| p.0.iter().all(|&c| c < 60)).count();
    assert!(
        inked > img.pixels().len() / 20,
        "the screenshot is almost blank"
    );
    assert!(
        dark > 1000,
        "no dark pixels: neither text nor renders were drawn"
    );
    shot
}

#[test]
fn report_loads_every_image_and_link_in_headless_chromium() {
    let Some(browser) = chromium() else {
        let msg = "chromium not found (bash scripts/install-browser.sh installs it)";
        if std::env::var("CI").as_deref() == Ok("true") {
            panic!("{msg}");
        }
        eprintln!("skipping: {msg}");
        return;
    };
    // Kept when SCENEFIT_KEEP_REPORT is set, to look at the screenshots.
    let work = match std::env::var_os("SCENEFIT_KEEP_REPORT") {
        Some(d) => {
            let d = PathBuf::from(d);
            std::fs::create_dir_all(&d).unwrap();
            d
        }
        None => tempfile::tempdir().unwrap().keep(),
    };
    let scene = scenes().join("sphere_floor.json");
    let scene = scene.to_str().unwrap();
    let t = scenefit(
        &work,
        &[
            "render",
            scene,
            "-o",
            "target.png",
            "--set",
            "lights.key.position=[1.5,2.5,2.5]",
        ],
    );
    assert!(t.status.success(), "{}", stderr(&t));

    // A pipeline directory: both stages.
    let out = scenefit(
        &work,
        &[
            "pipeline",
            scene,
            "--target",
            "target.png",
            "-o",
            "pipe",
            "--stage2",
            "phong",
            "--stage1-population",
            "20",
            "--stage1-generations",
            "30",
            "--stage2-population",
            "10",
            "--stage2-generations",
            "20",
            "-q",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let shot = check_in_browser(&browser, &work.join("pipe"), &work);
    eprintln!("pipeline report screenshot: {}", shot.display());

    // A fit directory: one stage, regenerated by `scenefit report`.
    let out = scenefit(
        &work,
        &[
            "fit",
            scene,
            "--target",
            "target.png",
            "-o",
            "fit",
            "--population",
            "20",
            "--generations",
            "30",
            "-q",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let out = scenefit(&work, &["report", "fit", "-q"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let shot = check_in_browser(&browser, &work.join("fit"), &work);
    eprintln!("fit report screenshot: {}", shot.display());
    if std::env::var_os("SCENEFIT_KEEP_REPORT").is_none() {
        let _ = std::fs::remove_dir_all(&work);
    }
}
