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
    /// How many images of each candidate are held at once (photographs of
    /// a set, refits side by side).
    pub copies: usize,
}

impl Population<'_> {
    /// One image and no search: `render`.
    pub const SINGLE: Population<'static> = Population {
        option: "--population",
        size: 1,
        copies: 1,
    };

    /// The option that sets the renders at once beside this population's:
    /// `--jobs`, `--stage1-jobs`, ...
    fn jobs_option(&self) -> String {
        match self.option.strip_suffix("population") {
            Some(prefix) if prefix.starts_with("--") => format!("{prefix}jobs"),
            _ => "--jobs".into(),
        }
    }
}

/// Refuses a fit of a `width` x `height` scene (read from `scene_file`)
/// with this population and number of jobs when it would need more than
/// the `avail` bytes the machine has (see [`available`]; None: unknown,
/// nothing checked). The one check of every command that renders (render,
/// fit, a set fit, pipeline, diagnose, demo, a resume), made before
/// anything of that size is allocated. The error names what to lower: the
/// largest share of the estimate, as the option that set it (population,
/// jobs) or the scene's image size.
pub fn check_fit(
    avail: Option<f64>,
    scene_file: &str,
    (width, height): (u32, u32),
    pop: Population,
    jobs: usize,
) -> Result<()> {
    let Some(avail) = avail else { return Ok(()) };
    let copies = pop.copies.max(1);
    let candidates = pop.size.saturating_mul(copies);
    let need = estimate(width, height, candidates, jobs);
    if need <= avail {
        return Ok(());
    }
    let gib = |b: f64| b / (1024.0 * 1024.0 * 1024.0);
    let px = width as f64 * height as f64;
    let image = estimate(width, height, 0, 0);
    let per_individual = px * PER_PIXEL_INDIVIDUAL + PER_INDIVIDUAL;
    let population = candidates as f64 * per_individual;
    let renders = px * PER_PIXEL_JOB * jobs as f64;
    let needs = format!(
        "would need about {:.1} GiB, {:.1} GiB is available",
        gib(need),
        gib(avail)
    );
    // What fits of one share with the others as they are.
    let fits = |share: f64, each: f64| ((avail - (need - share)) / each).floor().max(0.0);
    // Lowering an option helps only if the smallest value it can take
    // fits; otherwise the image itself is what must shrink.
    let most_jobs = fits(renders, px * PER_PIXEL_JOB);
    if renders > population && renders > image && most_jobs >= 1.0 {
        let (option, most) = (pop.jobs_option(), most_jobs);
        return Err(Error::Usage(format!(
            "{option} {jobs}: {jobs} renders at once of {width}x{height} pixels {needs}; expected {option} up to {most}"
        )));
    }
    let most_population = (fits(population, per_individual) / copies as f64).floor();
    if population >= image && most_population >= crate::optimize::MIN_POPULATION as f64 {
        let most = most_population;
        let each = if copies > 1 {
            format!(" ({copies} images of each candidate at once)")
        } else {
            String::new()
        };
        return Err(Error::Usage(format!(
            "{} {}: a fit of {width}x{height} pixels{each} {needs}; expected a population up to {most}",
            pop.option, pop.size
        )));
    }
    Err(Error::invalid(
        scene_file,
        "image.width",
        format!(
            "{width}x{height} pixels{} {needs}; expected a smaller image",
            if pop.size > 1 {
                format!(" with population {}", pop.size)
            } else {
                String::new()
            }
        ),
    ))
}

/// [`check_fit`] against the memory available now.
pub fn check(scene_file: &str, size: (u32, u32), pop: Population, jobs: usize) -> Result<()> {
    check_fit(available(), scene_file, size, pop, jobs)
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
        assert!(many.to_string().contains("24 images of each"), "{many}");
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

    /// An image so large that even the smallest population does not fit
    /// is blamed on the image, never answered with "a population up to 0".
    #[test]
    fn an_image_too_large_for_any_population_names_the_scene_key() {
        let e = check_fit(Some(18.0 * GIB), "s.json", (16384, 16384), pop(80), 2)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("s.json: image.width:"), "{e}");
        assert!(!e.contains("up to 0"), "{e}");
    }

    #[test]
    fn huge_jobs_name_the_jobs_option() {
        let e = check_fit(Some(8.0 * GIB), "s.json", (128, 96), pop(80), 1_000_000_000)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("--jobs 1000000000:"), "{e}");
        let p = Population {
            option: "--stage2-population",
            size: 8,
            copies: 1,
        };
        let e = check_fit(Some(8.0 * GIB), "s.json", (128, 96), p, 1_000_000_000).unwrap_err();
        assert!(
            e.to_string().starts_with("--stage2-jobs 1000000000:"),
            "{e}"
        );
    }

    #[test]
    fn a_single_render_of_a_huge_image_names_the_scene_key() {
        let e = check_fit(
            Some(8.0 * GIB),
            "s.json",
            (16384, 16384),
            Population::SINGLE,
            1,
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("s.json: image.width:"), "{e}");
        assert!(check_fit(
            Some(8.0 * GIB),
            "s.json",
            (4096, 4096),
            Population::SINGLE,
            2
        )
        .is_ok());
    }

    #[test]
    fn estimate_grows_with_every_input() {
        let base = estimate(100, 100, 10, 1);
        assert!(estimate(200, 100, 10, 1) > base);
        assert!(estimate(100, 100, 20, 1) > base);
        assert!(estimate(100, 100, 10, 2) > base);
    }
}
