//! Hostile scenes and inputs (issue 11, input side): each case is one entry
//! of a table, run through the real binary in a fresh directory. Every case
//! must exit with code 2, print exactly one line that names the file, key
//! or option and what was expected, and write no output.

mod common;
use common::*;
use serde_json::{json, Value};
use std::path::Path;

/// One hostile input.
struct Case {
    label: String,
    /// Files written into the case's directory first.
    files: Vec<(String, Vec<u8>)>,
    /// The command line after `scenefit`.
    args: Vec<String>,
    /// Text the one line must hold (file, key or option; what was expected).
    needles: Vec<String>,
}

fn base() -> Value {
    json(&scenes().join("sphere_floor.json"))
}

fn edited(edit: impl FnOnce(&mut Value)) -> Vec<u8> {
    let mut v = base();
    edit(&mut v);
    v.to_string().into_bytes()
}

/// `render s.json -o out.png` of an edited scene.
fn render_case(label: &str, edit: impl FnOnce(&mut Value), needles: &[&str]) -> Case {
    Case {
        label: label.into(),
        files: vec![("s.json".into(), edited(edit))],
        args: ["render", "s.json", "-o", "out.png"]
            .map(String::from)
            .to_vec(),
        needles: needles.iter().map(|s| s.to_string()).collect(),
    }
}

/// `fit s.json --target t.png -o out` with extra options.
fn fit_case(label: &str, scene: Vec<u8>, extra: &[&str], needles: &[&str]) -> Case {
    let mut args: Vec<String> = ["fit", "s.json", "--target", "t.png", "-o", "out", "-q"]
        .map(String::from)
        .to_vec();
    args.extend(extra.iter().map(|s| s.to_string()));
    Case {
        label: label.into(),
        files: vec![("s.json".into(), scene), ("t.png".into(), target_png())],
        args,
        needles: needles.iter().map(|s| s.to_string()).collect(),
    }
}

/// A 128x96 grey PNG: the example scene's size.
fn target_png() -> Vec<u8> {
    let img = image::RgbImage::from_pixel(128, 96, image::Rgb([90, 90, 90]));
    let mut buf = std::io::Cursor::new(Vec::new());
    img.write_to(&mut buf, image::ImageFormat::Png).unwrap();
    buf.into_inner()
}

/// A BMP header declaring `w` x `h` pixels with almost no pixel data.
fn bmp_header(w: i32, h: i32) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend(b"BM");
    b.extend(1000u32.to_le_bytes()); // file size (a lie)
    b.extend([0u8; 4]);
    b.extend(54u32.to_le_bytes()); // pixel data offset
    b.extend(40u32.to_le_bytes()); // BITMAPINFOHEADER
    b.extend(w.to_le_bytes());
    b.extend(h.to_le_bytes());
    b.extend(1u16.to_le_bytes());
    b.extend(24u16.to_le_bytes());
    b.extend([0u8; 24]);
    b.extend([0u8; 16]);
    b
}

/// Writes a number somewhere into a scene.
type SetNumber = fn(&mut Value, f64);

fn cases() -> Vec<Case> {
    let mut c = Vec::new();

    // 1. SDL injection through names, and the name character set.
    let bad_names = [
        ("newline", "key\n#fopen F \"/tmp/scenefit_injected\" write"),
        ("include", "x\n#include \"/etc/passwd\""),
        ("dot", "key.left"),
        ("leading dot", ".hidden"),
        ("space", "key light"),
        ("empty", ""),
        ("too long", &"n".repeat(65)),
        ("quote", "a\"b"),
        ("slash", "a/b"),
        ("hash", "#declare"),
        ("brace", "a}b"),
        ("non-ascii", "schlüssel"),
        ("tab", "a\tb"),
        ("carriage return", "a\rb"),
        ("nul", "a\u{0}b"),
        ("escape", "a\u{1b}[31mred"),
    ];
    for (what, name) in bad_names {
        let n = name.to_string();
        c.push(render_case(
            &format!("light name: {what}"),
            |v| v["lights"][0]["name"] = json!(n),
            &["s.json", "lights[0].name", "A-Z a-z 0-9 _ -"],
        ));
        let n = name.to_string();
        c.push(render_case(
            &format!("object name: {what}"),
            |v| v["objects"][1]["name"] = json!(n),
            &["s.json", "objects[1].name", "A-Z a-z 0-9 _ -"],
        ));
    }
    c.push(render_case(
        "name with a newline via povray",
        |v| v["lights"][0]["name"] = json!("k\n#fopen F \"/tmp/scenefit_injected\" write"),
        &["lights[0].name"],
    ));
    c.last_mut()
        .unwrap()
        .args
        .extend(["--renderer", "povray"].map(String::from));

    // 4. Recursion depth and other counts.
    for depth in [65u64, 4000, 100_000] {
        c.push(render_case(
            &format!("max_depth {depth}"),
            |v| v["render"]["max_depth"] = json!(depth),
            &["render.max_depth", "0 to 64"],
        ));
    }
    c.push(render_case(
        "max_depth 4294967295",
        |v| v["render"]["max_depth"] = json!(4_294_967_295u64),
        &["render.max_depth", "expected"],
    ));
    c.push(fit_case(
        "fit with max_depth 4000",
        edited(|v| v["render"]["max_depth"] = json!(4000)),
        &["--generations", "1"],
        &["render.max_depth", "0 to 64"],
    ));
    for samples in [0u64, 65_537, 1_000_000] {
        c.push(render_case(
            &format!("samples {samples}"),
            |v| v["render"]["samples"] = json!(samples),
            &["render.samples", "expected 1 to 65536"],
        ));
    }
    for aa in [0, 17, 1000] {
        c.push(render_case(
            &format!("antialias {aa}"),
            |v| v["render"]["antialias"] = json!(aa),
            &["render.antialias", "expected 1 to 16"],
        ));
    }
    for (w, h) in [(0, 96), (128, 0), (16385, 96), (128, 100_000)] {
        c.push(render_case(
            &format!("image {w}x{h}"),
            |v| v["image"] = json!({"width": w, "height": h}),
            &["image", "between 1 and 16384"],
        ));
    }
    c.push(render_case(
        "257 lights",
        |v| {
            let l = v["lights"][0].clone();
            v["lights"] = Value::Array(
                (0..257)
                    .map(|i| {
                        let mut l = l.clone();
                        l["name"] = json!(format!("l{i}"));
                        l
                    })
                    .collect(),
            );
            v["free"] = json!([]);
        },
        &["lights", "at most 256"],
    ));
    c.push(render_case(
        "10001 objects",
        |v| {
            let o = v["objects"][0].clone();
            v["objects"] = Value::Array(
                (0..10_001)
                    .map(|i| {
                        let mut o = o.clone();
                        o["name"] = json!(format!("o{i}"));
                        o
                    })
                    .collect(),
            );
            v["free"] = json!([]);
        },
        &["objects", "at most 10000"],
    ));
    c.push(render_case(
        "257 free entries",
        |v| {
            let f = v["free"][1].clone();
            v["free"] = Value::Array((0..257).map(|_| f.clone()).collect());
        },
        &["free", "at most 256"],
    ));
    for p in [16.5, 1000.0] {
        c.push(render_case(
            &format!("falloff_power {p}"),
            |v| v["lights"][0]["falloff_power"] = json!(p),
            &["lights[0].falloff_power", "at most 16"],
        ));
    }
    c.push(render_case(
        "distance on a point light",
        |v| v["lights"][0]["distance"] = json!(5.0),
        &["lights[0].distance", "point light"],
    ));
    c.push(render_case(
        "near light at distance 0",
        |v| {
            v["lights"][0] = json!({"name": "sun", "type": "directional",
                "direction": [0, 1, 0], "intensity": 1.0, "distance": 0.0});
        },
        &["lights[0].distance", "positive"],
    ));

    // 9. Numbers: every one within +-1e9, bounds whose span stays finite.
    let numbers: [(&str, SetNumber); 14] = [
        ("camera.position[0]", |v, x| {
            v["camera"]["position"][0] = json!(x)
        }),
        ("camera.look_at[2]", |v, x| {
            v["camera"]["look_at"][2] = json!(x)
        }),
        ("camera.fov_y_deg", |v, x| {
            v["camera"]["fov_y_deg"] = json!(x)
        }),
        ("ambient[1]", |v, x| v["ambient"][1] = json!(x)),
        ("lights[0].position[1]", |v, x| {
            v["lights"][0]["position"][1] = json!(x)
        }),
        ("lights[0].intensity", |v, x| {
            v["lights"][0]["intensity"] = json!(x)
        }),
        ("lights[0].color[0]", |v, x| {
            v["lights"][0]["color"][0] = json!(x)
        }),
        ("lights[0].radius", |v, x| {
            v["lights"][0]["radius"] = json!(x)
        }),
        ("objects[0].shape.radius", |v, x| {
            v["objects"][0]["shape"]["radius"] = json!(x)
        }),
        ("objects[0].shape.center[0]", |v, x| {
            v["objects"][0]["shape"]["center"][0] = json!(x)
        }),
        ("objects[0].material.shininess", |v, x| {
            v["objects"][0]["material"]["shininess"] = json!(x)
        }),
        ("objects[0].material.color[2]", |v, x| {
            v["objects"][0]["material"]["color"][2] = json!(x)
        }),
        ("objects[1].shape.point[1]", |v, x| {
            v["objects"][1]["shape"]["point"][1] = json!(x)
        }),
        ("free[1].max", |v, x| v["free"][1]["max"] = json!(x)),
    ];
    for (key, set) in numbers {
        for x in [1e10, -1e308, 1.7e308] {
            c.push(render_case(
                &format!("{key} = {x:e}"),
                |v| set(v, x),
                &[key, "between -1e9 and 1e9"],
            ));
        }
    }
    for (label, min, max) in [
        ("+-1e308 bounds", json!(-1e308), json!(1e308)),
        (
            "vector bounds 1e300",
            json!([-1e300, 0, 0]),
            json!([1e300, 1, 1]),
        ),
    ] {
        c.push(fit_case(
            label,
            edited(|v| {
                v["free"][0]["min"] = min;
                v["free"][0]["max"] = max;
            }),
            &["--generations", "1"],
            &["free[0].m", "between -1e9 and 1e9"],
        ));
    }
    for (label, bound) in [
        ("string bound", json!("a")),
        ("two numbers", json!([1, 2])),
        ("four numbers", json!([1, 2, 3, 4])),
        ("object bound", json!({"x": 1})),
        ("null bound", Value::Null),
        ("boolean bound", json!(true)),
        ("strings in a vector bound", json!(["1", "2", "3"])),
    ] {
        c.push(render_case(
            &format!("free bound: {label}"),
            |v| v["free"][1]["min"] = bound,
            &[
                "free[1].min",
                "expected a number or an array of three numbers",
            ],
        ));
    }
    c.push(render_case(
        "min above max",
        |v| {
            v["free"][1]["min"] = json!(50);
            v["free"][1]["max"] = json!(1);
        },
        &["free[1].max", "max >= min"],
    ));
    c.push(render_case(
        "number too large for JSON",
        |v| v["lights"][0]["intensity"] = json!(0),
        &[],
    ));
    // (the edit is replaced: serde_json cannot write 1e400, so the text is)
    c.last_mut().unwrap().files[0].1 = String::from_utf8(edited(|_| {}))
        .unwrap()
        .replacen("\"intensity\":10.0", "\"intensity\":1e400", 1)
        .into_bytes();
    c.last_mut().unwrap().needles = vec!["s.json".into(), "not valid JSON".into()];

    // 12. One clear line.
    c.push(render_case(
        "huge format string",
        |v| v["format"] = json!("f".repeat(1_000_000)),
        &[
            "format",
            "expected \"scenefit-scene/1\"",
            "(1000000 characters)",
        ],
    ));
    c.push(render_case(
        "format with newlines",
        |v| v["format"] = json!("a\nb\nc"),
        &["format", "a\\nb\\nc"],
    ));
    c.push(render_case(
        "huge unknown key",
        |v| v[&"k".repeat(100_000)] = json!(1),
        &["s.json", "unknown field", "..."],
    ));
    c.push(render_case(
        "unknown key with a newline",
        |v| v["camera"]["a\nb"] = json!(1),
        &["s.json", "camera", "unknown field"],
    ));
    c.push(render_case(
        "huge free param",
        |v| v["free"][1]["param"] = json!(format!("lights.{}.intensity", "z".repeat(100_000))),
        &["free[1].param", "characters)"],
    ));
    for (label, text) in [
        ("top-level array", "[]".to_string()),
        ("top-level array of a scene", format!("[{}]", base())),
        ("top-level string", "\"scene\"".to_string()),
        ("top-level number", "42".to_string()),
        ("top-level null", "null".to_string()),
    ] {
        c.push(Case {
            label: label.into(),
            files: vec![("s.json".into(), text.into_bytes())],
            args: ["render", "s.json", "-o", "out.png"]
                .map(String::from)
                .to_vec(),
            needles: vec![
                "s.json".into(),
                "(top level)".into(),
                "expected a JSON object".into(),
            ],
        });
    }
    for (label, bytes, needle) in [
        ("empty file", Vec::new(), "not valid JSON"),
        ("binary file", vec![0xff, 0xfe, 0x00, 0x81], "not UTF-8"),
        (
            "two BOMs",
            "\u{feff}\u{feff}{}".as_bytes().to_vec(),
            "not valid JSON",
        ),
        (
            "BOM then garbage",
            "\u{feff}}".as_bytes().to_vec(),
            "not valid JSON",
        ),
    ] {
        c.push(Case {
            label: label.into(),
            files: vec![("s.json".into(), bytes)],
            args: ["render", "s.json", "-o", "out.png"]
                .map(String::from)
                .to_vec(),
            needles: vec!["s.json".into(), needle.into()],
        });
    }
    let plain = edited(|_| {});
    let render = |label: &str, args: &[&str], needles: &[&str]| Case {
        label: label.into(),
        files: vec![("s.json".into(), plain.clone()), ("dir".into(), Vec::new())],
        args: args.iter().map(|s| s.to_string()).collect(),
        needles: needles.iter().map(|s| s.to_string()).collect(),
    };
    c.push(render(
        "-o a directory",
        &["render", "s.json", "-o", "dir"],
        &["-o dir", "is a directory"],
    ));
    c.push(render(
        "-o . ",
        &["render", "s.json", "-o", "."],
        &["is a directory"],
    ));
    // 13. The extension is checked before rendering.
    for ext in ["x.jpg", "x.tiff", "x", "x.png.txt"] {
        c.push(render(
            &format!("-o {ext}"),
            &["render", "s.json", "-o", ext],
            &[ext, "ending in .png or .bmp"],
        ));
    }
    for (opt, value) in [
        ("--width", "-5"),
        ("--width", "0"),
        ("--width", "99999"),
        ("--width", "abc"),
        ("--height", "-1"),
        ("--height", "1.5"),
    ] {
        c.push(render(
            &format!("{opt} {value}"),
            &["render", "s.json", "-o", "out.png", opt, value],
            &[opt, "whole number of pixels"],
        ));
    }
    for set in [
        "noequals",
        "lights.key.intensity=",
        "lights.key.intensity=1e400",
        "lights.key.intensity={",
    ] {
        c.push(render(
            &format!("--set {set}"),
            &["render", "s.json", "-o", "out.png", "--set", set],
            &["--set"],
        ));
    }
    for (set, needles) in [
        (
            "lights.nosuch.intensity=1",
            vec!["lights.nosuch.intensity", "no entry named"],
        ),
        ("lights.key.name=\"a\\nb\"", vec!["lights[0].name", "a\\nb"]),
        ("render.max_depth=5000", vec!["render.max_depth"]),
        (
            "lights.key.intensity=1e12",
            vec!["lights[0].intensity", "1e9"],
        ),
        ("image.width=0", vec!["image"]),
    ] {
        c.push(render(
            &format!("--set {set}"),
            &["render", "s.json", "-o", "out.png", "--set", set],
            &needles,
        ));
    }

    // 5. Files without limit: scenes, targets, masks.
    c.push(Case {
        label: "/dev/zero as scene".into(),
        files: vec![],
        args: ["render", "/dev/zero", "-o", "out.png"]
            .map(String::from)
            .to_vec(),
        needles: vec![
            "/dev/zero".into(),
            "a device; expected a regular file".into(),
        ],
    });
    c.push(Case {
        label: "directory as scene".into(),
        files: vec![("dir".into(), Vec::new())],
        args: ["render", "dir", "-o", "out.png"]
            .map(String::from)
            .to_vec(),
        needles: vec!["dir".into(), "is a directory".into()],
    });
    c.push(Case {
        label: "missing scene".into(),
        files: vec![],
        args: ["render", "nosuch.json", "-o", "out.png"]
            .map(String::from)
            .to_vec(),
        needles: vec!["nosuch.json".into()],
    });
    c.push(fit_case("/dev/zero as target", plain.clone(), &[], &[]));
    c.last_mut().unwrap().args[3] = "/dev/zero".into();
    c.last_mut().unwrap().needles = vec![
        "/dev/zero".into(),
        "--target".into(),
        "a device; expected a regular file".into(),
    ];
    // Options of a set fit without a set: refused, not silently ignored.
    for flag in [&["--joint"][..], &["--rounds", "2"][..]] {
        c.push(fit_case(
            &format!("{} without --shots", flag[0]),
            plain.clone(),
            flag,
            &[flag[0], "--shots"],
        ));
    }
    c.push(fit_case(
        "/dev/zero as mask",
        plain.clone(),
        &["--mask", "/dev/zero"],
        &["--mask", "a device; expected a regular file"],
    ));
    let mut huge = fit_case(
        "target declaring 20000x20000",
        plain.clone(),
        &[],
        &["--target", "between 1 and 16384", "20000x20000"],
    );
    huge.files[1].1 = bmp_header(20000, 20000);
    c.push(huge);
    let mut wrong = fit_case(
        "target of another size",
        plain.clone(),
        &[],
        &["--target", "expected 128x96", "got 640x480"],
    );
    wrong.files[1].1 = bmp_header(640, 480);
    c.push(wrong);
    let mut mask = fit_case(
        "mask declaring 16385 wide",
        plain.clone(),
        &["--mask", "m.bmp"],
        &["--mask", "between 1 and 16384"],
    );
    mask.files.push(("m.bmp".into(), bmp_header(16385, 1)));
    c.push(mask);
    let mut garbage = fit_case(
        "target not an image",
        plain.clone(),
        &[],
        &["--target", "could not decode"],
    );
    garbage.files[1].1 = b"not an image at all".to_vec();
    c.push(garbage);
    let mut dir_target = fit_case(
        "target a directory",
        plain.clone(),
        &[],
        &["--target", "is a directory"],
    );
    dir_target.files.push(("d".into(), Vec::new()));
    dir_target.args[3] = "d".into();
    c.push(dir_target);
    // The memory check and the population's value parser.
    for pop in ["1000000000", "100000000000"] {
        c.push(fit_case(
            &format!("--population {pop}"),
            plain.clone(),
            &["--population", pop],
            &["--population", "GiB", "expected a population up to"],
        ));
    }
    for pop in ["-5", "0", "-1000000000", "abc", "2.5", ""] {
        c.push(fit_case(
            &format!("--population {pop:?}"),
            plain.clone(),
            &["--population", pop],
            &["--population", "positive whole number"],
        ));
    }
    c.push(fit_case(
        "image.width 16384 with a large population",
        edited(|v| v["image"] = json!({"width": 16384, "height": 16384})),
        &["--population", "2000"],
        &[],
    ));
    // the memory first, before any photograph is decoded: an image this
    // large needs more than any machine here has, whatever the population
    c.last_mut().unwrap().needles = vec!["image.width".into(), "expected a smaller image".into()];
    c
}

/// The one-line user error a case must produce.
fn check(case: &Case, dir: &Path, out: &std::process::Output) -> Result<(), String> {
    let err = stderr(out);
    if out.status.code() != Some(2) {
        return Err(format!("exit code {:?}, stderr {err:?}", out.status.code()));
    }
    if err.contains("panicked") || err.contains("RUST_BACKTRACE") {
        return Err(format!("panic: {err}"));
    }
    let lines = err.lines().filter(|l| !l.trim().is_empty()).count();
    if lines != 1 {
        return Err(format!("{lines} lines: {err:?}"));
    }
    if err.len() > 2100 {
        return Err(format!("a line of {} bytes", err.len()));
    }
    for n in &case.needles {
        if !err.contains(n.as_str()) {
            return Err(format!("should mention {n:?}: {err}"));
        }
    }
    for written in ["out.png", "out", "x.jpg", "x.tiff", "x", "x.png.txt"] {
        if dir.join(written).exists() {
            return Err(format!("wrote {written}: {err}"));
        }
    }
    if Path::new("/tmp/scenefit_injected").exists() {
        return Err("the injected #fopen wrote /tmp/scenefit_injected".into());
    }
    Ok(())
}

#[test]
fn hostile_inputs_exit_2_with_one_line_and_no_output() {
    let cases = cases();
    assert!(cases.len() >= 100, "{} cases", cases.len());
    let mut failures = Vec::new();
    for case in &cases {
        let d = tempfile::tempdir().unwrap();
        for (name, bytes) in &case.files {
            if name == "dir" || name == "d" {
                std::fs::create_dir(d.path().join(name)).unwrap();
            } else {
                std::fs::write(d.path().join(name), bytes).unwrap();
            }
        }
        let args: Vec<&str> = case.args.iter().map(String::as_str).collect();
        let out = scenefit(d.path(), &args);
        if let Err(m) = check(case, d.path(), &out) {
            failures.push(format!("{}: {m}", case.label));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

/// The limits leave real scenes alone: a scene at every limit's edge
/// (64-character names, depth 64, a UTF-8 BOM) renders.
#[test]
fn scenes_at_the_limits_still_render() {
    let d = tempfile::tempdir().unwrap();
    let name = "N".repeat(64);
    let mut v = base();
    v["lights"][0]["name"] = json!(name);
    v["objects"][0]["name"] = json!("ball_1-A");
    v["render"]["max_depth"] = json!(64);
    v["objects"][0]["material"]["reflection"] = json!(0.5);
    v["objects"][0]["material"]["transmission"] = json!(0.5);
    v["image"] = json!({"width": 16, "height": 12});
    v["free"] = json!([{"param": format!("lights.{name}.intensity"), "min": -0.0, "max": 1e9}]);
    let text = format!("\u{feff}{v}");
    std::fs::write(d.path().join("s.json"), text).unwrap();
    let out = scenefit(d.path(), &["render", "s.json", "-o", "out.png"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(d.path().join("out.png").exists());
}

/// A float target's NaN and infinite pixels are left out with their count,
/// never fitted as black; a target with no finite pixel is refused.
#[test]
fn nan_targets_are_masked_or_refused() {
    let d = tempfile::tempdir().unwrap();
    let mut v = base();
    v["image"] = json!({"width": 16, "height": 12});
    std::fs::write(d.path().join("s.json"), v.to_string()).unwrap();
    let exr = |name: &str, bad: usize| {
        let mut img = image::Rgb32FImage::from_pixel(16, 12, image::Rgb([0.2, 0.2, 0.2]));
        for (i, p) in img.pixels_mut().take(bad).enumerate() {
            p.0[i % 3] = if i % 2 == 0 { f32::NAN } else { f32::INFINITY };
        }
        img.save(d.path().join(name)).unwrap();
    };
    exr("part.exr", 7);
    exr("all.exr", 16 * 12);
    let fit = |target: &str, out: &str| {
        scenefit(
            d.path(),
            &[
                "fit",
                "s.json",
                "--target",
                target,
                "-o",
                out,
                "--population",
                "6",
                "--generations",
                "2",
            ],
        )
    };
    let o = fit("part.exr", "part");
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(
        err.contains("part.exr: 7 pixels with a NaN or infinite channel left out of the fit"),
        "{err}"
    );
    let o = fit("all.exr", "all");
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("all.exr") && err.contains("every pixel is NaN or infinite"),
        "{err}"
    );
}
