//! The hostile matrix (issue 30): every file every command reads, replaced
//! in turn by each of the same hostile stand-ins, run through the real
//! binary with a timeout. Generated from two tables, [`INPUTS`] (one entry
//! per command and file it reads) and [`STAND_INS`], so that an input
//! added later is covered by adding one entry.
//!
//! Every case must: exit 2 (bad input) or 1 (failed run); print one line
//! that names the file; never panic; finish within `TIME_BOUND` (a FIFO
//! must not hang); and write nothing outside its output, change no input
//! and leave the file a link points to untouched.

mod common;
use common::*;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant, SystemTime};

/// Longer than any case takes (a bad input is refused before any work).
const TIME_BOUND: Duration = Duration::from_secs(20);

/// What a file holds, which decides its truncated, wrong-format and
/// huge-declared stand-ins.
#[derive(Clone, Copy, Debug)]
enum Kind {
    Json,
    Image,
    Exr,
    Font,
    /// A mesh shape's file (PLY).
    Mesh,
    /// A calibration tool's text file (COLMAP's cameras.txt and
    /// images.txt, an OpenCV YAML).
    Text,
    /// A .blend file (`scenefit import`; Blender reads it).
    Blend,
}

/// One file a command reads: the command line (run in a copy of the
/// fixture), the file replaced (relative to it), what it holds, and what
/// the command may write (its output, relative).
struct Input {
    label: &'static str,
    args: &'static [&'static str],
    file: &'static str,
    kind: Kind,
    output: &'static str,
}

/// The small budget of every fit, so that a case that wrongly accepted its
/// input still ends within the bound.
const G: &[&str] = &["-q", "--population", "6", "--generations", "2"];

/// Commands x the files they read, one entry each. `demo` reads no
/// file (its scene and targets are built in), so it has no entry.
const INPUTS: &[Input] = &[
    Input {
        label: "render",
        args: &["render", "sm.json", "-o", "out.png"],
        file: "m.ply",
        kind: Kind::Mesh,
        output: "out.png",
    },
    Input {
        label: "render",
        args: &["render", "sn.json", "-o", "out.png"],
        file: "n.png",
        kind: Kind::Image,
        output: "out.png",
    },
    Input {
        label: "render",
        args: &["render", "se.json", "-o", "out.png"],
        file: "n.exr",
        kind: Kind::Exr,
        output: "out.png",
    },
    Input {
        label: "fit",
        args: &["fit", "sm.json", "--target", "t.png", "-o", "out"],
        file: "m.ply",
        kind: Kind::Mesh,
        output: "out",
    },
    Input {
        label: "render",
        args: &["render", "s.json", "-o", "out.png"],
        file: "s.json",
        kind: Kind::Json,
        output: "out.png",
    },
    Input {
        label: "render",
        args: &["render", "sa.json", "-o", "out.png"],
        file: "a.exr",
        kind: Kind::Exr,
        output: "out.png",
    },
    Input {
        label: "render",
        args: &["render", "st.json", "-o", "out.png"],
        file: "c.png",
        kind: Kind::Image,
        output: "out.png",
    },
    Input {
        label: "fit",
        args: &["fit", "s.json", "--target", "t.png", "-o", "out"],
        file: "s.json",
        kind: Kind::Json,
        output: "out",
    },
    Input {
        label: "fit",
        args: &["fit", "s.json", "--target", "t.png", "-o", "out"],
        file: "t.png",
        kind: Kind::Image,
        output: "out",
    },
    Input {
        label: "fit",
        args: &[
            "fit", "s.json", "--target", "t.png", "--mask", "m.png", "-o", "out",
        ],
        file: "m.png",
        kind: Kind::Image,
        output: "out",
    },
    Input {
        label: "fit",
        args: &["fit", "sa.json", "--target", "t.png", "-o", "out"],
        file: "a.exr",
        kind: Kind::Exr,
        output: "out",
    },
    Input {
        label: "fit --resume",
        args: &[
            "fit", "s.json", "--target", "t.png", "-o", "run", "--resume",
        ],
        file: "run/checkpoint.json",
        kind: Kind::Json,
        output: "run",
    },
    Input {
        label: "fit --shots",
        args: &["fit", "s.json", "--shots", "shots.json", "-o", "out"],
        file: "shots.json",
        kind: Kind::Json,
        output: "out",
    },
    Input {
        label: "fit --shots",
        args: &["fit", "s.json", "--shots", "shots.json", "-o", "out"],
        file: "p1.png",
        kind: Kind::Image,
        output: "out",
    },
    Input {
        label: "fit --shots",
        args: &["fit", "s.json", "--shots", "shots.json", "-o", "out"],
        file: "m1.png",
        kind: Kind::Image,
        output: "out",
    },
    Input {
        label: "fit --shots --hold-out",
        args: &[
            "fit",
            "s.json",
            "--shots",
            "shots.json",
            "-o",
            "out",
            "--hold-out",
            "b",
        ],
        file: "p2.png",
        kind: Kind::Image,
        output: "out",
    },
    Input {
        label: "fit --shots --resume",
        args: &[
            "fit",
            "s.json",
            "--shots",
            "shots.json",
            "-o",
            "setrun",
            "--resume",
        ],
        file: "setrun/checkpoint.json",
        kind: Kind::Json,
        output: "setrun",
    },
    Input {
        label: "pipeline",
        args: &["pipeline", "s.json", "--target", "t.png", "-o", "out"],
        file: "s.json",
        kind: Kind::Json,
        output: "out",
    },
    Input {
        label: "pipeline",
        args: &["pipeline", "s.json", "--target", "t.png", "-o", "out"],
        file: "t.png",
        kind: Kind::Image,
        output: "out",
    },
    Input {
        label: "pipeline",
        args: &[
            "pipeline", "s.json", "--target", "t.png", "--mask", "m.png", "-o", "out",
        ],
        file: "m.png",
        kind: Kind::Image,
        output: "out",
    },
    Input {
        label: "pipeline",
        args: &[
            "pipeline", "s.json", "--target", "t.png", "--font", "f.ttf", "-o", "out",
        ],
        file: "f.ttf",
        kind: Kind::Font,
        output: "out",
    },
    Input {
        label: "diagnose",
        args: &["diagnose", "run", "-o", "out"],
        file: "run/result.json",
        kind: Kind::Json,
        output: "out",
    },
    Input {
        label: "diagnose",
        args: &["diagnose", "run", "-o", "out"],
        file: "run/fitted_scene.json",
        kind: Kind::Json,
        output: "out",
    },
    Input {
        label: "diagnose",
        args: &["diagnose", "run", "--target", "t.png", "-o", "out"],
        file: "t.png",
        kind: Kind::Image,
        output: "out",
    },
    Input {
        label: "diagnose",
        args: &["diagnose", "run", "--mask", "m.png", "-o", "out"],
        file: "m.png",
        kind: Kind::Image,
        output: "out",
    },
    Input {
        label: "diagnose (set)",
        args: &["diagnose", "setrun", "-o", "out"],
        file: "setrun/shots.json",
        kind: Kind::Json,
        output: "out",
    },
    Input {
        label: "report",
        args: &["report", "run", "-q"],
        file: "run/result.json",
        kind: Kind::Json,
        output: "run",
    },
    Input {
        label: "report",
        args: &["report", "run", "-q", "--target", "t.png"],
        file: "t.png",
        kind: Kind::Image,
        output: "run",
    },
    Input {
        label: "report",
        args: &["report", "run", "-q", "--font", "f.ttf"],
        file: "f.ttf",
        kind: Kind::Font,
        output: "run",
    },
    Input {
        label: "import-cameras --colmap",
        args: IMPORT_COLMAP,
        file: "col/cameras.txt",
        kind: Kind::Text,
        output: "cams.json",
    },
    Input {
        label: "import-cameras --colmap",
        args: IMPORT_COLMAP,
        file: "col/images.txt",
        kind: Kind::Text,
        output: "cams.json",
    },
    Input {
        label: "import-cameras --colmap",
        args: IMPORT_COLMAP,
        file: "p2.png",
        kind: Kind::Image,
        output: "cams.json",
    },
    Input {
        label: "import-cameras --opencv",
        args: &[
            "import-cameras",
            "--opencv",
            "p1.yml",
            "--images",
            ".",
            "-o",
            "cams.json",
            "--scene",
            "sp.json",
        ],
        file: "p1.yml",
        kind: Kind::Text,
        output: "cams.json",
    },
    Input {
        label: "import (Blender)",
        args: &["import", "u.blend", "-o", "imp.json"],
        file: "u.blend",
        kind: Kind::Blend,
        output: "imp.json",
    },
    Input {
        label: "import (Mitsuba)",
        args: &["import", "u.xml", "-o", "imp.json"],
        file: "u.xml",
        kind: Kind::Text,
        output: "imp.json",
    },
    Input {
        label: "export --to mitsuba",
        args: &["export", "s.json", "--to", "mitsuba", "-o", "outx"],
        file: "s.json",
        kind: Kind::Json,
        output: "outx",
    },
    Input {
        label: "export --to blender",
        args: &["export", "s.json", "--to", "blender", "-o", "out.blend"],
        file: "s.json",
        kind: Kind::Json,
        output: "out.blend",
    },
];

/// `import-cameras` from the fixture's COLMAP model, checked against its
/// pinhole scene.
const IMPORT_COLMAP: &[&str] = &[
    "import-cameras",
    "--colmap",
    "col",
    "--images",
    ".",
    "-o",
    "cams.json",
    "--scene",
    "sp.json",
];

/// Rows whose command does not read the file yet, with why: each of their
/// cases must still fail, so that the row is taken off this list (and
/// checked like the others) once the command reads it.
const PENDING: &[(&str, &str, &str)] = &[];

/// One hostile stand-in: writes itself at `path` in place of `valid` (the
/// file's real contents); `outside` is a directory beside the case's.
struct StandIn {
    label: &'static str,
    make: fn(path: &Path, valid: &[u8], kind: Kind, outside: &Path),
}

const STAND_INS: &[StandIn] = &[
    StandIn {
        label: "missing",
        make: |_, _, _, _| {},
    },
    StandIn {
        label: "empty",
        make: |p, _, _, _| write(p, b""),
    },
    StandIn {
        label: "truncated",
        make: |p, v, _, _| write(p, &v[..v.len() / 2]),
    },
    StandIn {
        label: "FIFO",
        make: |p, _, _, _| mkfifo(p),
    },
    StandIn {
        label: "/dev/zero",
        make: |p, _, _, _| link("/dev/zero", p),
    },
    StandIn {
        label: "symlink out of the directory",
        make: |p, _, kind, outside| {
            let target = outside.join("elsewhere");
            write(&target, &wrong_format(kind));
            link(&target, p)
        },
    },
    StandIn {
        label: "huge sparse file",
        make: |p, _, _, _| std::fs::File::create(p).unwrap().set_len(20 << 30).unwrap(),
    },
    StandIn {
        label: "wrong format",
        make: |p, _, kind, _| write(p, &wrong_format(kind)),
    },
    StandIn {
        label: "huge declared size",
        make: |p, v, kind, _| write(p, &huge_declared(kind, v)),
    },
];

fn write(p: &Path, bytes: &[u8]) {
    std::fs::write(p, bytes).unwrap()
}

fn link(target: impl AsRef<Path>, p: &Path) {
    std::os::unix::fs::symlink(target, p).unwrap()
}

fn mkfifo(p: &Path) {
    let c = std::ffi::CString::new(p.to_str().unwrap()).unwrap();
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
}

/// Contents of another kind: an image where JSON is expected, JSON where
/// an image or a font is.
fn wrong_format(kind: Kind) -> Vec<u8> {
    match kind {
        Kind::Json | Kind::Text => png_header(4, 4),
        Kind::Image | Kind::Exr | Kind::Font | Kind::Mesh | Kind::Blend => {
            br#"{"not": "this kind of file"}"#.to_vec()
        }
    }
}

/// A tiny file that declares something huge: an image header of
/// 100000x100000, a font of 65535 tables, a JSON file whose sizes are
/// 100000 (or, without any, nested 100000 deep).
fn huge_declared(kind: Kind, valid: &[u8]) -> Vec<u8> {
    match kind {
        Kind::Image | Kind::Exr => png_header(100_000, 100_000),
        Kind::Font => [0u8, 1, 0, 0, 0xff, 0xff, 0, 0, 0, 0, 0, 0].to_vec(),
        // 2^31 faces declared in a few hundred bytes
        Kind::Mesh => b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 2147483648\nproperty list uchar int vertex_indices\nend_header\n"
            .iter()
            .chain(&[0u8; 36])
            .copied()
            .collect(),
        Kind::Text => huge_declared_text(valid),
        // Blender's signature, then a file block declaring 2 GiB
        Kind::Blend => [&b"BLENDER-v304REND"[..], &[0xff, 0xff, 0xff, 0x7f], &[0u8; 40]].concat(),
        Kind::Json => {
            let mut v: Value = serde_json::from_slice(valid).unwrap();
            if set_sizes(&mut v) {
                v.to_string().into_bytes()
            } else {
                format!("{}{}", "[".repeat(100_000), "]".repeat(100_000)).into_bytes()
            }
        }
    }
}

/// A calibration file declaring a huge image (100000 x 100000, refused
/// against the scene's 16 x 12), or, where nothing declares a size
/// (images.txt), a photograph whose camera id overflows.
fn huge_declared_text(valid: &[u8]) -> Vec<u8> {
    let text = String::from_utf8(valid.to_vec()).unwrap();
    if text.contains("PINHOLE 16 12") {
        text.replace("PINHOLE 16 12", "PINHOLE 100000 100000")
    } else if text.contains("image_width") {
        text.replace("image_width: 16", "image_width: 100000")
            .replace("image_height: 12", "image_height: 100000")
    } else {
        "1 1 0 0 0 0 0 5 99999999999999999999999 p1.png\n\n".to_string()
    }
    .into_bytes()
}

/// Sets every `width`, `height` and `population` in `v` to 100000; true
/// when there was one.
fn set_sizes(v: &mut Value) -> bool {
    match v {
        Value::Object(m) => {
            let mut any = false;
            for (k, x) in m.iter_mut() {
                if ["width", "height", "population"].contains(&k.as_str()) && x.is_number() {
                    *x = json!(100_000);
                    any = true;
                } else {
                    any |= set_sizes(x);
                }
            }
            any
        }
        Value::Array(a) => a.iter_mut().fold(false, |any, x| set_sizes(x) | any),
        _ => false,
    }
}

/// The valid inputs every case starts from: a 16x12 scene, its render as
/// target and two photographs, masks, an albedo map, a colour map, normal maps (PNG and
/// OpenEXR), a mesh, a font, a finished
/// fit (`run`) and a finished set fit (`setrun`).
fn fixture() -> tempfile::TempDir {
    let d = tempfile::tempdir().unwrap();
    let p = d.path();
    let mut scene = json(&scenes().join("sphere_floor.json"));
    scene["image"] = json!({"width": 16, "height": 12});
    write(&p.join("s.json"), scene.to_string().as_bytes());
    scene["objects"][0]["material"]["albedo_map"] = json!("a.exr");
    write(&p.join("sa.json"), scene.to_string().as_bytes());
    let map = scenefit::scene::albedo_map::AlbedoMap::uniform(16, 12, 1.0);
    scenefit::scene::albedo_map::write(&p.join("a.exr"), map).unwrap();
    scene["objects"][0]["material"]
        .as_object_mut()
        .unwrap()
        .remove("albedo_map");
    // a colour map in the object's frame (scene/texture/)
    scene["objects"][0]["material"]["color_map"] = json!("c.png");
    write(&p.join("st.json"), scene.to_string().as_bytes());
    image::RgbImage::from_pixel(8, 8, image::Rgb([200, 180, 90]))
        .save(p.join("c.png"))
        .unwrap();
    scene["objects"][0]["material"]
        .as_object_mut()
        .unwrap()
        .remove("color_map");
    // normal maps, PNG and OpenEXR (tangent space: a flat texel)
    for (key, file) in [("sn.json", "n.png"), ("se.json", "n.exr")] {
        let mut s = scene.clone();
        s["objects"][0]["material"]["normal_map"] = json!(file);
        write(&p.join(key), s.to_string().as_bytes());
    }
    image::RgbImage::from_pixel(4, 4, image::Rgb([128, 128, 255]))
        .save(p.join("n.png"))
        .unwrap();
    image::Rgb32FImage::from_pixel(4, 4, image::Rgb([0.5, 0.5, 1.0]))
        .save(p.join("n.exr"))
        .unwrap();
    scene["objects"][0]["shape"] = json!({"type": "mesh", "file": "m.ply"});
    write(&p.join("sm.json"), scene.to_string().as_bytes());
    std::fs::copy(scenes().join("mesh_blob.ply"), p.join("m.ply")).unwrap();
    run_ok(p, &["render", "s.json", "-o", "t.png"]);
    image::GrayImage::from_pixel(16, 12, image::Luma([255]))
        .save(p.join("m.png"))
        .unwrap();
    for f in ["p1.png", "p2.png"] {
        std::fs::copy(p.join("t.png"), p.join(f)).unwrap();
    }
    std::fs::copy(p.join("m.png"), p.join("m1.png")).unwrap();
    let shots = json!({"format": "scenefit-shots/1", "shots": [
        {"name": "a", "target": "p1.png", "mask": "m1.png"},
        {"name": "b", "target": "p2.png"},
    ]});
    write(&p.join("shots.json"), shots.to_string().as_bytes());
    // A pinhole scene and the two photographs' calibrations, for
    // import-cameras: COLMAP's half-pixel centre (8, 6) is OpenCV's (7.5, 5.5).
    let mut pin = json(&p.join("s.json"));
    pin["camera"] = json!({"type": "pinhole", "fx": 20.0, "fy": 20.0, "cx": 7.5, "cy": 5.5,
        "rotation": [3.3, 0.0, 0.0], "translation": [0.0, 0.5, 5.3]});
    write(&p.join("sp.json"), pin.to_string().as_bytes());
    std::fs::create_dir(p.join("col")).unwrap();
    write(
        &p.join("col/cameras.txt"),
        b"# one camera\n1 PINHOLE 16 12 20 20 8 6\n",
    );
    write(
        &p.join("col/images.txt"),
        b"# two photographs\n1 1 0 0 0 0.0 0.5 5.3 1 p1.png\n\n2 1 0 0 0 0.1 0.5 5.3 1 p2.png\n\n",
    );
    let yml = "%YAML:1.0\n---\nimage_width: 16\nimage_height: 12\ncamera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 20., 0., 7.5, 0., 20., 5.5, 0., 0., 1. ]\ndistortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n   data: [ 0., 0., 0., 0., 0. ]\nrvec: !!opencv-matrix\n   rows: 3\n   cols: 1\n   dt: d\n   data: [ 3.3, 0., 0. ]\ntvec: !!opencv-matrix\n   rows: 3\n   cols: 1\n   dt: d\n   data: [ 0., 0.5, 5.3 ]\n";
    write(&p.join("p1.yml"), yml.as_bytes());
    // a Mitsuba scene: only its stand-ins are read
    write(
        &p.join("u.xml"),
        b"<scene version=\"3.0.0\"><emitter type=\"point\"><point name=\"position\" x=\"0\" y=\"2\" z=\"2\"/></emitter></scene>\n",
    );
    // a .blend's signature and a block: only its stand-ins are read
    write(
        &p.join("u.blend"),
        &[&b"BLENDER-v304GLOB"[..], &[0u8; 64]].concat(),
    );
    let font = Path::new("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf");
    let font = std::fs::read(font).unwrap_or_else(|_| huge_declared(Kind::Font, b""));
    write(&p.join("f.ttf"), &font);
    let fit = ["fit", "s.json", "--target", "t.png", "-o", "run"];
    run_ok(p, &[&fit[..], G].concat());
    let set = [
        "fit",
        "s.json",
        "--shots",
        "shots.json",
        "-o",
        "setrun",
        "--rounds",
        "1",
    ];
    run_ok(p, &[&set[..], G].concat());
    d
}

fn run_ok(dir: &Path, args: &[&str]) {
    let o = scenefit(dir, args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
}

/// Copies the fixture into `to`, links as links.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let (src, dst) = (e.path(), to.join(e.file_name()));
        if e.file_type().unwrap().is_dir() {
            copy_tree(&src, &dst);
        } else {
            std::fs::copy(&src, &dst).unwrap();
        }
    }
}

/// Every entry under `dir` but `skip`: its path, and for a file its size
/// and modification time (a link: where it points).
fn snapshot(dir: &Path, skip: &Path) -> Vec<(PathBuf, u64, Option<SystemTime>)> {
    let mut out = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return out;
    };
    for e in entries {
        let e = e.unwrap();
        let p = e.path();
        if p == skip {
            continue;
        }
        let m = std::fs::symlink_metadata(&p).unwrap();
        if m.is_dir() {
            out.push((p.clone(), 0, None));
            out.extend(snapshot(&p, skip));
        } else if m.file_type().is_symlink() {
            out.push((std::fs::read_link(&p).unwrap(), 0, None));
        } else {
            out.push((p, m.len(), m.modified().ok()));
        }
    }
    out.sort();
    out
}

/// Runs `args` in `dir`, killed after `TIME_BOUND`; the exit code (None
/// when killed), stderr, and how long it took.
fn run_bounded(dir: &Path, args: &[&str]) -> (Option<i32>, String, Duration) {
    let start = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_scenefit"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .env_remove("SCENEFIT_FONT")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = std::io::Read::read_to_string(&mut err, &mut s);
        s
    });
    let code = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status.code();
        }
        if start.elapsed() > TIME_BOUND {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    (code, reader.join().unwrap(), start.elapsed())
}

/// Runs one case in a fresh copy of the fixture; what is wrong, if any.
fn case(fixture: &Path, input: &Input, stand_in: &StandIn) -> Result<(), String> {
    let top = tempfile::tempdir().unwrap();
    let (dir, outside) = (top.path().join("case"), top.path().join("outside"));
    copy_tree(fixture, &dir);
    std::fs::create_dir(&outside).unwrap();
    let file = dir.join(input.file);
    let valid = std::fs::read(&file).unwrap();
    std::fs::remove_file(&file).unwrap();
    (stand_in.make)(&file, &valid, input.kind, &outside);
    let output = dir.join(input.output);
    let before = (snapshot(&dir, &output), snapshot(&outside, &output));
    let mut args = input.args.to_vec();
    if args[0] == "fit" || args[0] == "pipeline" {
        args.extend(if args[0] == "fit" {
            G
        } else {
            &["-q", "--no-report"][..]
        });
    }
    let (code, err, took) = run_bounded(&dir, &args);
    let name = Path::new(input.file).file_name().unwrap().to_str().unwrap();
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    if code.is_none() {
        return Err(format!("still running after {took:?}: {err:?}"));
    }
    if !matches!(code, Some(1 | 2)) {
        return Err(format!("exit {code:?}: {err:?}"));
    }
    if err.contains("panicked") || err.contains("RUST_BACKTRACE") {
        return Err(format!("a panic: {err:?}"));
    }
    if lines.len() != 1 || !lines[0].contains(name) {
        return Err(format!("not one line naming {name}: {err:?}"));
    }
    if (snapshot(&dir, &output), snapshot(&outside, &output)) != before {
        return Err(format!("wrote outside {}: {err:?}", input.output));
    }
    Ok(())
}

#[test]
fn every_input_of_every_command_refuses_every_hostile_stand_in() {
    let start = Instant::now();
    let fx = fixture();
    eprintln!("fixture in {:.1} s", start.elapsed().as_secs_f64());
    let mut failures = Vec::new();
    for input in INPUTS {
        let pending = PENDING
            .iter()
            .find(|(l, f, _)| *l == input.label && *f == input.file);
        for stand_in in STAND_INS {
            let t = Instant::now();
            let got = case(fx.path(), input, stand_in);
            let what = format!("{} / {} / {}", input.label, input.file, stand_in.label);
            if t.elapsed() > Duration::from_secs(2) {
                eprintln!("{what}: {:.1} s", t.elapsed().as_secs_f64());
            }
            match (got, pending) {
                (Err(m), None) => failures.push(format!("{what}: {m}")),
                (Ok(()), Some((.., why))) => {
                    failures.push(format!("{what}: passes; take the row off PENDING ({why})"))
                }
                _ => {}
            }
        }
    }
    let n = INPUTS.len() * STAND_INS.len();
    eprintln!("{n} cases in {:.1} s", start.elapsed().as_secs_f64());
    assert!(
        failures.is_empty(),
        "{} of {n} cases failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// The stand-ins are what they say: a FIFO, a link to a device, a sparse
/// file that claims 20 GB but uses no disk, a header that declares a huge
/// image in a few bytes.
#[test]
fn the_stand_ins_are_what_they_claim() {
    use std::os::unix::fs::{FileTypeExt, MetadataExt};
    let d = tempfile::tempdir().unwrap();
    let valid = br#"{"image": {"width": 16, "height": 12}}"#;
    let made = |label: &str| {
        let s = STAND_INS.iter().find(|s| s.label == label).unwrap();
        let p = d.path().join(label.replace('/', "_"));
        (s.make)(&p, valid, Kind::Json, d.path());
        p
    };
    assert!(std::fs::metadata(made("FIFO"))
        .unwrap()
        .file_type()
        .is_fifo());
    let zero = std::fs::metadata(made("/dev/zero")).unwrap();
    assert!(zero.file_type().is_char_device());
    let sparse = std::fs::metadata(made("huge sparse file")).unwrap();
    assert_eq!(sparse.len(), 20 << 30);
    assert!(sparse.blocks() < 1024, "{} blocks", sparse.blocks());
    let huge: Value =
        serde_json::from_slice(&std::fs::read(made("huge declared size")).unwrap()).unwrap();
    assert_eq!(huge["image"]["width"], 100_000);
    let png = png_header(100_000, 100_000);
    let dims = image::ImageReader::new(std::io::Cursor::new(&png))
        .with_guessed_format()
        .unwrap()
        .into_dimensions()
        .unwrap();
    assert_eq!(dims, (100_000, 100_000));
    let link = std::fs::read_link(made("symlink out of the directory")).unwrap();
    assert_eq!(link, d.path().join("elsewhere"));
}

/// A worker's output is read through the same opener: a FIFO (no writer)
/// or a link to /dev/zero left where the image should be fails the render
/// at once (exit 1, one line saying what the file is), well within
/// `--render-timeout`, instead of hanging or reading without end.
#[test]
fn a_worker_output_that_is_a_fifo_or_a_device_fails_at_once() {
    if Command::new("python3").arg("--version").output().is_err() {
        assert_ne!(
            std::env::var("CI").as_deref(),
            Ok("true"),
            "python3 is needed"
        );
        eprintln!("skipped: no python3");
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let mut scene = json(&scenes().join("sphere_floor.json"));
    scene["image"] = json!({"width": 16, "height": 12});
    write(&d.path().join("s.json"), scene.to_string().as_bytes());
    let faulty = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/plugins/faulty.py");
    for (mode, says) in [("fifo", "a FIFO"), ("devzero", "a device")] {
        let worker = format!(
            "worker:python3 {} --worker --fault {mode}",
            faulty.display()
        );
        let args = [
            "render",
            "s.json",
            "-o",
            "out.png",
            "--renderer",
            &worker,
            "--render-timeout",
            "30",
        ];
        let (code, err, took) = run_bounded(d.path(), &args);
        assert_eq!(code, Some(1), "{mode}: {err}");
        assert_eq!(err.lines().count(), 1, "{mode}: {err}");
        assert!(
            err.contains(says) && err.contains("expected a regular file"),
            "{mode}: {err}"
        );
        assert!(took < Duration::from_secs(15), "{mode}: {took:?}");
        assert!(!d.path().join("out.png").exists());
    }
}
