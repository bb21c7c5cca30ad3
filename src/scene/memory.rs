//! How much memory a fit will need, checked against what the machine has
//! before the run starts, so that a too-large `--population` or image is a
//! clear error instead of the kernel's OOM killer hours later.
//!
//! The model, from the peak resident size (`/usr/bin/time -v`) of
//! `scenefit fit scenes/sphere_floor.json` with the built-in tracer at
//! 160x120 and 480x360, population 40 and 80, jobs 1, 2 and 8:
//!
//!   bytes = 16 MiB + pixels x (200 + 3 x population + 18 x jobs)
//!           + 256 x population
//!
//! 200 B/pixel is the tracer's per-pixel paths and the target (measured
//! 182), 3 B/pixel each individual's 8-bit image, 18 B/pixel each render
//! job's buffers, 256 B each individual's vectors. Other backends hold no
//! more per pixel than the built-in tracer.

use crate::error::{Error, Result};

const BASE: f64 = 16.0 * 1024.0 * 1024.0;
const PER_PIXEL: f64 = 200.0;
const PER_PIXEL_INDIVIDUAL: f64 = 3.0;
const PER_PIXEL_JOB: f64 = 18.0;
const PER_INDIVIDUAL: f64 = 256.0;

/// The estimated peak memory of a fit, bytes.
pub fn estimate(width: u32, height: u32, population: usize, jobs: usize) -> f64 {
    let px = width as f64 * height as f64;
    BASE + px * (PER_PIXEL + PER_PIXEL_INDIVIDUAL * population as f64 + PER_PIXEL_JOB * jobs as f64)
        + PER_INDIVIDUAL * population as f64
}

/// Memory available now (`MemAvailable` of /proc/meminfo), bytes; None
/// where that cannot be read (then nothing is checked).
pub fn available() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// A population to check, and the option that set it.
pub struct Population<'a> {
    /// The option, e.g. `--population` or `--stage2-population`.
    pub option: &'a str,
    pub size: usize,
    /// How many images each candidate is drawn as (photographs of a set).
    pub copies: usize,
}

/// Refuses a fit of a `width` x `height` scene (read from `scene_file`)
/// with this population and number of jobs when it would need more than
/// the `avail` bytes the machine has (see [`available`]; None: unknown,
/// nothing checked). The error names what to lower: the population when
/// it is the larger share (by the option that set it), else the scene's
/// image size.
pub fn check_fit(
    avail: Option<f64>,
    scene_file: &str,
    (width, height): (u32, u32),
    pop: Population,
    jobs: usize,
) -> Result<()> {
    let Some(avail) = avail else { return Ok(()) };
    let Population {
        option,
        size: population,
        copies,
    } = pop;
    let candidates = population * copies.max(1);
    let need = estimate(width, height, candidates, jobs);
    if need <= avail {
        return Ok(());
    }
    let gib = |b: f64| b / (1024.0 * 1024.0 * 1024.0);
    let px = width as f64 * height as f64;
    let per_individual = px * PER_PIXEL_INDIVIDUAL + PER_INDIVIDUAL;
    let fixed = estimate(width, height, 0, jobs);
    if candidates as f64 * per_individual >= fixed {
        let fits = ((avail - fixed) / per_individual / copies.max(1) as f64)
            .floor()
            .max(0.0);
        let each = if copies > 1 {
            format!(" (each candidate drawn for {copies} photographs)")
        } else {
            String::new()
        };
        return Err(Error::Usage(format!(
            "{option} {population}: a fit of {width}x{height} pixels{each} would need about {:.1} GiB, {:.1} GiB is available; expected a population up to {fits}",
            gib(need),
            gib(avail)
        )));
    }
    Err(Error::invalid(
        scene_file,
        "image.width",
        format!(
            "a fit of {width}x{height} pixels with population {population} would need about {:.1} GiB, {:.1} GiB is available; expected a smaller image",
            gib(need),
            gib(avail)
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

    fn pop(size: usize) -> Population<'static> {
        Population {
            option: "--population",
            size,
            copies: 1,
        }
    }

    #[test]
    fn a_paper_sized_fit_passes() {
        assert!(check_fit(Some(1.0 * GIB), "s.json", (640, 480), pop(80), 2).is_ok());
    }

    /// The message of a check that must fail with 8 GiB available.
    fn refusal(width: u32, height: u32, population: usize) -> String {
        check_fit(
            Some(8.0 * GIB),
            "s.json",
            (width, height),
            pop(population),
            2,
        )
        .unwrap_err()
        .to_string()
    }

    #[test]
    fn a_huge_population_names_the_option() {
        let e = refusal(64, 48, 1_000_000_000);
        assert!(e.starts_with("--population 1000000000:"), "{e}");
    }

    #[test]
    fn the_option_that_set_the_population_is_named() {
        let p = Population {
            option: "--stage2-population",
            size: 1_000_000_000,
            copies: 1,
        };
        let e = check_fit(Some(8.0 * GIB), "s.json", (64, 48), p, 2).unwrap_err();
        assert!(
            e.to_string().starts_with("--stage2-population 1000000000:"),
            "{e}"
        );
        // A set draws each candidate once per photograph: the population
        // that fits is smaller by that factor.
        let set = |copies| Population {
            option: "--population",
            size: 100_000_000,
            copies,
        };
        let one = check_fit(Some(8.0 * GIB), "s.json", (64, 48), set(1), 2).unwrap_err();
        let many = check_fit(Some(8.0 * GIB), "s.json", (64, 48), set(24), 2).unwrap_err();
        let fits = |e: &crate::error::Error| -> f64 {
            let m = e.to_string();
            m.rsplit(' ').next().unwrap().parse().unwrap()
        };
        assert!(many.to_string().contains("24 photographs"), "{many}");
        assert!(
            (fits(&one) / fits(&many) - 24.0).abs() < 0.01,
            "{one} / {many}"
        );
    }

    #[test]
    fn the_largest_image_names_the_scene_key() {
        let e = refusal(16384, 16384, 10);
        assert!(e.starts_with("s.json: image.width:"), "{e}");
    }

    #[test]
    fn estimate_grows_with_every_input() {
        let base = estimate(100, 100, 10, 1);
        assert!(estimate(200, 100, 10, 1) > base);
        assert!(estimate(100, 100, 20, 1) > base);
        assert!(estimate(100, 100, 10, 2) > base);
    }
}
