//! Photographs are not renders: 16-bit and float files, linear values,
//! TIFF and OpenEXR, saturated pixels and 16-bit masks. The images are made
//! here from a render of an example scene, written with the image crate.

mod common;

use common::{json, scenefit, scenes, stderr};
use image::{DynamicImage, ImageBuffer, Rgb};
use scenefit::fit::FitTarget;
use scenefit::metric::Mask;
use scenefit::raster::encoding::linear_from_srgb;
use scenefit::raster::{io::read_photo, Encoding, Image};
use std::path::{Path, PathBuf};

/// One 8-bit level in percent of the deviation's scale.
const ONE_LEVEL: f64 = 100.0 / 255.0;

fn scene() -> PathBuf {
    scenes().join("sphere_floor.json")
}

/// The example scene rendered to DIR/t.png (8-bit sRGB) and read back.
fn render(dir: &Path) -> Image {
    let out = scenefit(dir, &["render", scene().to_str().unwrap(), "-o", "t.png"]);
    assert!(out.status.success(), "render: {}", stderr(&out));
    image::open(dir.join("t.png")).unwrap().to_rgb8()
}

/// `img` as 16-bit sRGB with a sub-level offset per pixel (at most ±0.4
/// level), so the file says more than its 8-bit rounding.
fn sixteen_bit(img: &Image) -> ImageBuffer<Rgb<u16>, Vec<u16>> {
    let raw = img
        .as_raw()
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let wobble = [-100i32, 0, 100][i % 3];
            (v as i32 * 257 + wobble).clamp(0, 65534) as u16
        })
        .collect();
    ImageBuffer::from_raw(img.width(), img.height(), raw).unwrap()
}

/// `img` as linear floats.
fn linear(img: &Image) -> Vec<f32> {
    img.as_raw()
        .iter()
        .map(|&v| linear_from_srgb(v as f32 / 255.0))
        .collect()
}

fn max_level_difference(a: &Image, b: &Image) -> u8 {
    assert_eq!(a.dimensions(), b.dimensions());
    a.as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| x.abs_diff(*y))
        .max()
        .unwrap()
}

fn fit(dir: &Path, target: &str, out: &str, extra: &[&str]) -> std::process::Output {
    let s = scene();
    let mut args = vec![
        "fit",
        s.to_str().unwrap(),
        "--target",
        target,
        "-o",
        out,
        "--generations",
        "2",
        "--population",
        "8",
        "--seed",
        "3",
    ];
    args.extend_from_slice(extra);
    scenefit(dir, &args)
}

/// Exit 2 with one line mentioning every needle, no panic.
fn assert_user_error(out: &std::process::Output, needles: &[&str]) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(2), "exit code; stderr: {err}");
    assert!(!err.contains("panicked"), "no panic: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "one line: {err}");
    for n in needles {
        assert!(err.contains(n), "stderr should mention {n:?}: {err}");
    }
}

#[test]
fn sixteen_bit_target_fits_like_its_eight_bit_version() {
    let d = tempfile::tempdir().unwrap();
    let img = render(d.path());
    sixteen_bit(&img).save(d.path().join("t16.png")).unwrap();
    let p = read_photo(
        &d.path().join("t16.png"),
        "--target",
        img.dimensions(),
        None,
    )
    .unwrap();
    assert_eq!((p.bits, p.encoding), (16, Encoding::Srgb));
    assert_eq!(
        max_level_difference(&p.image, &img),
        0,
        "rounds to the 8-bit render"
    );

    for (target, out) in [("t.png", "r8"), ("t16.png", "r16")] {
        let o = fit(d.path(), target, out, &["-q"]);
        assert!(o.status.success(), "{target}: {}", stderr(&o));
    }
    let (r8, r16) = (
        json(&d.path().join("r8/result.json")),
        json(&d.path().join("r16/result.json")),
    );
    let avg = |r: &serde_json::Value, k: &str| r[k]["average"].as_f64().unwrap();
    assert!(
        r8.get("deviation_precise").is_none(),
        "8-bit sRGB has no precise deviation"
    );
    assert!((avg(&r8, "deviation") - avg(&r16, "deviation")).abs() < ONE_LEVEL);
    let precise = avg(&r16, "deviation_precise");
    assert!(
        (precise - avg(&r16, "deviation")).abs() < ONE_LEVEL,
        "precise {precise} vs {}",
        avg(&r16, "deviation")
    );
}

#[test]
fn linear_sixteen_bit_png_and_exr_read_as_the_srgb_image() {
    let d = tempfile::tempdir().unwrap();
    let img = render(d.path());
    let (w, h) = img.dimensions();
    let lin = linear(&img);
    let png: ImageBuffer<Rgb<u16>, Vec<u16>> = ImageBuffer::from_raw(
        w,
        h,
        lin.iter().map(|&v| (v * 65535.0).round() as u16).collect(),
    )
    .unwrap();
    png.save(d.path().join("lin16.png")).unwrap();
    let exr: ImageBuffer<Rgb<f32>, Vec<f32>> = ImageBuffer::from_raw(w, h, lin).unwrap();
    DynamicImage::ImageRgb32F(exr)
        .save(d.path().join("t.exr"))
        .unwrap();

    let p = read_photo(
        &d.path().join("lin16.png"),
        "--target",
        (w, h),
        Some(Encoding::Linear),
    )
    .unwrap();
    assert_eq!((p.bits, p.encoding), (16, Encoding::Linear));
    assert!(max_level_difference(&p.image, &img) <= 1);
    // Read as sRGB (the default for PNG) it is much darker: the encoding matters.
    let wrong = read_photo(&d.path().join("lin16.png"), "--target", (w, h), None).unwrap();
    assert!(max_level_difference(&wrong.image, &img) > 20);

    let e = read_photo(&d.path().join("t.exr"), "--target", (w, h), None).unwrap();
    assert_eq!(
        (e.bits, e.encoding),
        (32, Encoding::Linear),
        "OpenEXR defaults to linear"
    );
    assert!(max_level_difference(&e.image, &img) <= 1);
    assert!(e.saturated.is_empty(), "float has no maximum");

    // The command line fits an EXR and reports the precise deviation.
    let o = fit(d.path(), "t.exr", "run", &["-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r = json(&d.path().join("run/result.json"));
    assert!(r["deviation_precise"]["average"].as_f64().is_some(), "{r}");
    // --encoding linear makes the 16-bit PNG fit like the EXR.
    let o = fit(
        d.path(),
        "lin16.png",
        "run2",
        &["-q", "--encoding", "linear"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let r2 = json(&d.path().join("run2/result.json"));
    let avg = |r: &serde_json::Value| r["deviation"]["average"].as_f64().unwrap();
    assert!(
        (avg(&r) - avg(&r2)).abs() < ONE_LEVEL,
        "{} vs {}",
        avg(&r),
        avg(&r2)
    );
    // The encoding is recorded, and `diagnose` reads the target as the fit
    // did: its starting deviation is the fit's, not the sRGB misreading's.
    assert_eq!(r2["target_encoding"], "linear", "{r2}");
    assert_eq!(r["target_encoding"], "linear", "OpenEXR: {r}");
    let o = scenefit(
        d.path(),
        &[
            "diagnose",
            "run2",
            "-o",
            "diag",
            "--generations",
            "2",
            "--population",
            "8",
            "--max-effects",
            "1",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let dj = json(&d.path().join("diag/diagnosis.json"));
    let before = dj["deviation_before"]["average"].as_f64().unwrap();
    assert!(
        (before - avg(&r2)).abs() < 1e-9,
        "diagnose started at {before}, the fit ended at {}",
        avg(&r2)
    );
}

#[test]
fn tiff_targets_of_eight_and_sixteen_bits() {
    let d = tempfile::tempdir().unwrap();
    let img = render(d.path());
    img.save(d.path().join("t8.tif")).unwrap();
    sixteen_bit(&img).save(d.path().join("t16.tiff")).unwrap();
    for (name, bits) in [("t8.tif", 8), ("t16.tiff", 16)] {
        let p = read_photo(&d.path().join(name), "--target", img.dimensions(), None).unwrap();
        assert_eq!((p.bits, p.encoding), (bits, Encoding::Srgb), "{name}");
        assert_eq!(max_level_difference(&p.image, &img), 0, "{name}");
        assert_eq!(p.is_plain(), bits == 8);
    }
    let o = fit(d.path(), "t16.tiff", "run", &["-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn saturated_pixels_leave_the_mask() {
    let d = tempfile::tempdir().unwrap();
    let img = render(d.path());
    let (w, h) = img.dimensions();
    let mut t = sixteen_bit(&img);
    // 37 clipped pixels: a run along row 10, one channel at the maximum.
    for x in 0..37 {
        t.get_pixel_mut(x, 10).0[x as usize % 3] = u16::MAX;
    }
    t.save(d.path().join("sat.png")).unwrap();
    let path = d.path().join("sat.png");
    let (target, note) = FitTarget::from_photo(&path, "--target", None, None, (w, h)).unwrap();
    let mask = target.mask.expect("saturation makes a mask");
    assert_eq!(mask.pixels().len(), (w * h) as usize - 37);
    assert!(mask
        .pixels()
        .iter()
        .all(|&p| !(10 * w..10 * w + 37).contains(&p)));
    assert!(note.unwrap().contains("37 saturated pixels"));

    // With a mask covering the left half only the clipped pixels in it go.
    let m = image::GrayImage::from_fn(w, h, |x, _| image::Luma([if x < 20 { 255 } else { 0 }]));
    m.save(d.path().join("left.png")).unwrap();
    let left = d.path().join("left.png");
    let (target, _) =
        FitTarget::from_photo(&path, "--target", Some((&left, "--mask")), None, (w, h)).unwrap();
    assert_eq!(target.mask.unwrap().pixels().len(), (20 * h) as usize - 20);

    // The command line says it once, and not with --quiet.
    let o = fit(d.path(), "sat.png", "run", &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let said: Vec<String> = stderr(&o)
        .lines()
        .filter(|l| l.contains("saturated"))
        .map(String::from)
        .collect();
    assert_eq!(said.len(), 1, "{said:?}");
    assert!(
        said[0].contains("37 saturated pixels") && said[0].contains("sat.png"),
        "{said:?}"
    );
    let o = fit(d.path(), "sat.png", "run_q", &["-q"]);
    assert!(
        o.status.success() && !stderr(&o).contains("saturated"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn every_counted_pixel_saturated_is_a_user_error() {
    let d = tempfile::tempdir().unwrap();
    let img = render(d.path());
    let white = Image::from_pixel(img.width(), img.height(), Rgb([255, 255, 255]));
    white.save(d.path().join("white.png")).unwrap();
    let o = fit(d.path(), "white.png", "run", &["-q"]);
    assert_user_error(&o, &["white.png", "--target", "saturated"]);
}

#[test]
fn sixteen_bit_mask_counts_above_half() {
    let d = tempfile::tempdir().unwrap();
    let img = render(d.path());
    let (w, h) = img.dimensions();
    // Columns: < 10 full, 10..20 just above half, 20..30 just below, rest 0.
    let m: ImageBuffer<image::Luma<u16>, Vec<u16>> = ImageBuffer::from_fn(w, h, |x, _| {
        image::Luma([match x {
            0..10 => 65535,
            10..20 => 32768,
            20..30 => 32767,
            _ => 0,
        }])
    });
    m.save(d.path().join("m16.png")).unwrap();
    let mask = Mask::load(&d.path().join("m16.png"), w, h).unwrap();
    assert_eq!(mask.pixels().len(), (20 * h) as usize);
    assert!(mask.pixels().iter().all(|&p| p % w < 20));
    let o = fit(d.path(), "t.png", "run", &["-q", "--mask", "m16.png"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn bogus_encoding_names_the_flag() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("t.png"), b"unused").unwrap();
    let o = fit(d.path(), "t.png", "run", &["--encoding", "bogus"]);
    assert_user_error(&o, &["--encoding", "bogus", "srgb or linear"]);
}

#[test]
fn truncated_exr_names_the_file() {
    let d = tempfile::tempdir().unwrap();
    let img = render(d.path());
    let (w, h) = img.dimensions();
    let exr: ImageBuffer<Rgb<f32>, Vec<f32>> = ImageBuffer::from_raw(w, h, linear(&img)).unwrap();
    DynamicImage::ImageRgb32F(exr)
        .save(d.path().join("t.exr"))
        .unwrap();
    let bytes = std::fs::read(d.path().join("t.exr")).unwrap();
    std::fs::write(d.path().join("cut.exr"), &bytes[..bytes.len() / 2]).unwrap();
    let o = fit(d.path(), "cut.exr", "run", &["-q"]);
    assert_user_error(&o, &["cut.exr", "--target"]);
    assert!(!d.path().join("run/result.json").exists());
}
