//! Stage 2 by output space mapping (Bandler's space mapping, in the form of
//! Bakr, Madsen and Søndergaard, "An Introduction to the Space Mapping
//! Technique"): the stage-2 renderer is the fine model, the stage-1
//! renderer the coarse one. At the current point x_k the fine model renders
//! once, and the surrogate
//!
//! ```text
//! s(x) = coarse(x) + (fine(x_k) − coarse(x_k))      per pixel and channel
//! ```
//!
//! matches the fine render exactly at x_k. Its deviation from the target T
//! is minimised with cheap coarse renders inside a trust region around x_k;
//! the fine model renders the surrogate's optimum, and the step is accepted
//! when the fine deviation fell. The region (a box of half-width r in the
//! unit cube of the original bounds) doubles after a step that did what the
//! surrogate predicted and halves after one that did not.
//!
//! Minimising |T − (coarse(x) + D)| is fitting the coarse model to the
//! corrected target T − D, so each iteration is an ordinary in-memory fit
//! (`fit::run_in_memory`, the hybrid strategy). T − D is clamped to
//! 0..255 to be an image; as renders are 0..255 too, the clamp adds the
//! same constant to the deviation of every candidate and moves no optimum.
//!
//! Writes into stage2/: `spacemap.json` after every iteration (what
//! `--resume` continues from), `spacemap_current.png` (the fine render at
//! the current point, so a resumed run does not render it again),
//! `trace.tsv` (one line per iteration, renders = fine renders),
//! `best_gNNNN.bmp` per iteration, and at the end `fitted_scene.json`,
//! `best.png` and `result.json` (with `method` and `iterations`).

use super::trace::Trace;
use crate::error::{Error, Result};
use crate::fit::{self, render_seed, FitConfig, FitResult, FitTarget};
use crate::metric::{deviation, Deviation};
use crate::optimize::{DeConfig, Strategy};
use crate::raster::Image;
use crate::render::{render_one, Renderer};
use crate::rundir::{
    snapshot_name, Mode, RunDir, BEST, FITTED_SCENE, RESULT, SPACEMAP_CURRENT, SPACEMAP_STATE,
};
use crate::scene::{ParamSpace, Scene};
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// How the mapped stage 2 runs.
#[derive(Clone, Debug)]
pub struct MappedConfig {
    /// Fine renders at most, the first one included.
    pub fine_renders: usize,
    /// The first trust-region half-width (unit cube of the original bounds).
    pub radius: f64,
    /// Each surrogate fit: population and generations of the hybrid search.
    pub surrogate_population: usize,
    pub surrogate_generations: usize,
    /// Coarse renders at once.
    pub coarse_jobs: usize,
    /// Start of each surrogate fit: within this radius (unit cube of the
    /// trust region) of x_k, which is individual 0.
    pub start_radius: f64,
    /// The run's seed: fine renders and surrogate fits draw from it.
    pub seed: u64,
    pub mode: Mode,
    pub interrupt: Option<Arc<AtomicBool>>,
}

/// The smallest trust region: below it the step is in the noise.
const MIN_RADIUS: f64 = 1.0 / 512.0;
/// The largest: half the unit cube each way is the whole cube.
const MAX_RADIUS: f64 = 0.5;
/// Iterations in a row with less than the noise floor's improvement.
const STALLS_TO_STOP: usize = 2;

/// One iteration, for result.json and the report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Iteration {
    /// The fine deviation (average %) at the iteration's trial point (the
    /// current point's when the surrogate proposed no move).
    pub deviation: f64,
    /// The surrogate's deviation at its optimum: what it predicted.
    pub surrogate_deviation: f64,
    /// The trust region's half-width the iteration searched.
    pub radius: f64,
    pub accepted: bool,
    /// Fine renders so far, this iteration's included.
    pub fine_renders: usize,
    /// Coarse renders of this iteration's surrogate fit.
    pub coarse_renders: usize,
}

/// spacemap.json: where a mapped stage 2 stands.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct State {
    /// What the run started from (seed and renderers, and the handover
    /// point): a resumed run with other inputs is refused.
    start: serde_json::Value,
    start_point: Vec<f64>,
    /// The current point, in the original bounds' unit cube.
    point: Vec<f64>,
    /// The fine deviation at the current point.
    current: Deviation,
    radius: f64,
    noise_floor: f64,
    fine_renders: usize,
    coarse_renders: usize,
    stalls: usize,
    seconds: f64,
    iterations: Vec<Iteration>,
    /// Set when a stop rule has fired.
    stop_reason: Option<String>,
}

/// stage2/result.json of a mapped stage 2: result.json's keys, then
/// `method`, `iterations` and the stage's coarse renders.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MappedResult {
    #[serde(flatten)]
    pub result: FitResult,
    pub method: String,
    pub noise_floor: f64,
    pub coarse_renders: usize,
    pub iterations: Vec<Iteration>,
}

/// What the stage returns to the pipeline.
pub struct Mapped {
    pub result: FitResult,
    pub scene: Scene,
}

/// What every part of the stage reads.
struct Ctx<'a> {
    start: &'a Scene,
    space: ParamSpace,
    target: &'a FitTarget,
    coarse: &'a dyn Renderer,
    fine: &'a dyn Renderer,
    config: &'a MappedConfig,
    dir: &'a RunDir,
    /// The sampler seed of every fine render but the noise floor's.
    seed: u64,
}

/// Runs the mapped stage 2 from `start` (the stage-1 fitted scene, which
/// holds the original free list and bounds), writing into `dir`.
/// `handover` is the fine render of `start` already made (seeded 0), used
/// as the second render of the noise floor's estimate.
#[allow(clippy::too_many_arguments)]
pub fn run(
    start: &Scene,
    target: &FitTarget,
    coarse: &dyn Renderer,
    fine: &dyn Renderer,
    config: &MappedConfig,
    handover: Option<&Image>,
    dir: &RunDir,
    observer: &mut dyn FnMut(&Iteration),
) -> Result<Mapped> {
    let started = Instant::now();
    let cx = Ctx {
        start,
        space: ParamSpace::from_scene(start),
        target,
        coarse,
        fine,
        config,
        dir,
        seed: render_seed(config.seed, 0),
    };
    let identity = serde_json::json!({
        "seed": config.seed,
        "fine": fine.name(),
        "coarse": coarse.name(),
    });
    let (mut state, mut fine_now) = match resume(&cx, &identity)? {
        Some(r) => r,
        None => begin(&cx, identity, handover)?,
    };
    let seconds_before = state.seconds;
    while state.stop_reason.is_none() {
        if config
            .interrupt
            .as_ref()
            .is_some_and(|f| f.load(Ordering::Relaxed))
        {
            return Err(Error::Run(format!(
                "interrupted; the state in {} resumes the run (--resume)",
                dir.path().display()
            )));
        }
        let k = state.iterations.len() + 1;
        let (iteration, accepted_img) = step(&cx, &mut state, &fine_now, k)?;
        if let Some(img) = accepted_img {
            fine_now = img;
        }
        state.seconds = seconds_before + started.elapsed().as_secs_f64();
        state.stop_reason = stop_reason(&state, config);
        state.iterations.push(iteration.clone());
        Trace::append(dir)?.line(k, state.fine_renders, state.seconds, &state.current)?;
        dir.write_image(&snapshot_name(k), &fine_now)?;
        save(dir, &state, &fine_now)?;
        observer(&iteration);
    }
    let scene = cx.space.scene_at(start, &state.point);
    finish(dir, state, scene, fine_now, fine, target, config)
}

/// The saved state and current fine render of a resumed stage, or None
/// when there is nothing to resume.
fn resume(cx: &Ctx, identity: &serde_json::Value) -> Result<Option<(State, Image)>> {
    let dir = cx.dir;
    if !(cx.config.mode == Mode::Resume && dir.file(SPACEMAP_STATE).is_file()) {
        return Ok(None);
    }
    let mut s: State = dir.read_json(SPACEMAP_STATE, "a scenefit space-mapping state")?;
    // A resumed stage 1 gives its values back through the unit cube, so
    // they may differ in the last bits.
    let start_point = cx.space.unit_of(cx.start);
    let same_start = s.start_point.len() == start_point.len()
        && s.start_point
            .iter()
            .zip(&start_point)
            .all(|(a, b)| (a - b).abs() < 1e-9);
    if s.start != *identity || !same_start {
        return Err(Error::Usage(format!(
            "{}: the stage-2 state was written for other inputs (stage-1 values, seed or renderers); use --overwrite to start again",
            dir.file(SPACEMAP_STATE).display()
        )));
    }
    let img = dir.read_image(SPACEMAP_CURRENT)?;
    // A larger render budget continues a stage that stopped on it.
    s.stop_reason = stop_reason(&s, cx.config);
    Ok(Some((s, img)))
}

/// The first state: the fine render at the start, and the noise floor
/// from it and a second render with another seed (the handover's).
fn begin(
    cx: &Ctx,
    identity: serde_json::Value,
    handover: Option<&Image>,
) -> Result<(State, Image)> {
    let (start, fine, target) = (cx.start, cx.fine, cx.target);
    let img = render_fine(fine, start, cx.seed, "the handover point")?;
    let current = dev(target, &img)?;
    let other = match handover {
        Some(h) => h.clone(),
        None => render_fine(
            fine,
            start,
            render_seed(cx.config.seed, 1),
            "the handover point",
        )?,
    };
    let noise_floor = (dev(target, &other)?.average - current.average).abs();
    let start_point = cx.space.unit_of(start);
    let s = State {
        start: identity,
        start_point: start_point.clone(),
        point: start_point,
        current,
        radius: cx.config.radius.clamp(MIN_RADIUS, MAX_RADIUS),
        noise_floor,
        fine_renders: if handover.is_some() { 1 } else { 2 },
        coarse_renders: 0,
        stalls: 0,
        seconds: 0.0,
        iterations: Vec::new(),
        stop_reason: None,
    };
    Trace::create(cx.dir)?.line(0, s.fine_renders, 0.0, &s.current)?;
    cx.dir.write_image(&snapshot_name(0), &img)?;
    save(cx.dir, &s, &img)?;
    Ok((s, img))
}

/// One iteration: the surrogate's optimum in the trust region, its fine
/// render, and the state moved (or not) and its region resized. Returns
/// the iteration and, when the step was accepted, the new fine render.
fn step(
    cx: &Ctx,
    state: &mut State,
    fine_now: &Image,
    k: usize,
) -> Result<(Iteration, Option<Image>)> {
    let current_scene = cx.space.scene_at(cx.start, &state.point);
    let coarse_now = render_one(cx.coarse, &current_scene, 0)?;
    let (trial, coarse_renders) = surrogate_step(
        cx.start,
        &current_scene,
        cx.target,
        cx.coarse,
        fine_now,
        &coarse_now,
        state.radius,
        cx.config,
        k,
    )?;
    let predicted = state.current.average - trial.surrogate.average;
    state.coarse_renders += coarse_renders;
    let moved = trial.point != state.point && predicted > 0.0;
    let (accepted, fine_dev, fine_img) = if moved {
        let trial_scene = cx.space.scene_at(cx.start, &trial.point);
        state.fine_renders += 1;
        match render_fine(cx.fine, &trial_scene, cx.seed, "a trial point") {
            Ok(img) => {
                let d = dev(cx.target, &img)?;
                (d.average < state.current.average, d, Some(img))
            }
            // A failed render is a failed step: the region shrinks.
            Err(_) => (false, state.current, None),
        }
    } else {
        (false, state.current, None)
    };
    let actual = state.current.average - fine_dev.average;
    let iteration = Iteration {
        deviation: fine_dev.average,
        surrogate_deviation: trial.surrogate.average,
        radius: state.radius,
        accepted,
        fine_renders: state.fine_renders,
        coarse_renders,
    };
    // The trust region: the ratio of actual to predicted reduction.
    let ratio = if predicted > 0.0 {
        actual / predicted
    } else {
        0.0
    };
    if !accepted || ratio < 0.25 {
        state.radius /= 2.0;
    } else if ratio > 0.75 {
        state.radius = (state.radius * 2.0).min(MAX_RADIUS);
    }
    if actual.max(0.0) <= state.noise_floor {
        state.stalls += 1;
    } else {
        state.stalls = 0;
    }
    if !accepted {
        return Ok((iteration, None));
    }
    state.point = trial.point;
    state.current = fine_dev;
    Ok((iteration, fine_img))
}

/// Why the iteration loop stops now, if it does.
fn stop_reason(s: &State, config: &MappedConfig) -> Option<String> {
    if s.stalls >= STALLS_TO_STOP {
        Some(format!(
            "fine deviation improved by less than the noise floor ({:.4} %) for {STALLS_TO_STOP} iterations",
            s.noise_floor
        ))
    } else if s.radius < MIN_RADIUS {
        Some("trust region below its smallest radius".into())
    } else if s.fine_renders >= config.fine_renders {
        Some(format!(
            "fine render budget used up ({})",
            config.fine_renders
        ))
    } else {
        None
    }
}

/// The surrogate's optimum in the trust region.
struct Trial {
    point: Vec<f64>,
    surrogate: Deviation,
}

/// Fits the coarse model to the corrected target within the trust region
/// around the current point; returns the optimum (unit cube of the
/// original bounds) and the coarse renders it took.
#[allow(clippy::too_many_arguments)]
fn surrogate_step(
    start: &Scene,
    current: &Scene,
    target: &FitTarget,
    coarse: &dyn Renderer,
    fine_now: &Image,
    coarse_now: &Image,
    radius: f64,
    config: &MappedConfig,
    k: usize,
) -> Result<(Trial, usize)> {
    let corrected = FitTarget {
        image: corrected_target(&target.image, fine_now, coarse_now),
        levels: None,
        mask: target.mask.clone(),
        path: None,
        encoding: None,
    };
    // The trust region as bounds: x_k ± radius × original span, clamped
    // to the original bounds (a hue box across red keeps the full circle).
    let (region, _) = super::handover::narrow(current, radius, &[])?;
    let fit_config = FitConfig {
        de: DeConfig {
            population: config.surrogate_population,
            strategy: Strategy::Hybrid,
            seed: config.seed.wrapping_add(k as u64),
            ..DeConfig::default()
        },
        generations: config.surrogate_generations,
        jobs: config.coarse_jobs,
        start_radius: Some(config.start_radius),
        interrupt: config.interrupt.clone(),
        ..FitConfig::default()
    };
    let outcome = fit::run_in_memory(&region, &corrected, coarse, &fit_config, &mut ())?;
    let space = ParamSpace::from_scene(start);
    let point = space.unit_of(&outcome.scene);
    // The fit's best is never worse than x_k (individual 0), but a point
    // that only differs by rounding is no move.
    let surrogate = surrogate_deviation(target, &outcome.image, fine_now, coarse_now);
    let now = surrogate_deviation(target, coarse_now, fine_now, coarse_now);
    let (point, surrogate) = if surrogate.average < now.average {
        (point, surrogate)
    } else {
        (space.unit_of(current), now)
    };
    Ok((Trial { point, surrogate }, outcome.result.evaluations))
}

/// T − (fine − coarse), clamped to 0..255.
pub fn corrected_target(target: &Image, fine: &Image, coarse: &Image) -> Image {
    let mut out = target.clone();
    for ((o, f), c) in out
        .as_mut()
        .iter_mut()
        .zip(fine.as_raw())
        .zip(coarse.as_raw())
    {
        let v = *o as i32 - (*f as i32 - *c as i32);
        *o = v.clamp(0, 255) as u8;
    }
    out
}

/// The deviation of the surrogate coarse + (fine − coarse_k) from the
/// target, unclamped (as the deviation of an image, over the mask).
pub fn surrogate_deviation(
    target: &FitTarget,
    coarse: &Image,
    fine_k: &Image,
    coarse_k: &Image,
) -> Deviation {
    let (t, c, f, ck) = (
        target.image.as_raw(),
        coarse.as_raw(),
        fine_k.as_raw(),
        coarse_k.as_raw(),
    );
    let at = |i: usize| {
        let s = c[i] as i64 + f[i] as i64 - ck[i] as i64;
        (t[i] as i64 - s).unsigned_abs()
    };
    let mut sums = [0u64; 3];
    let count = match &target.mask {
        None => {
            for i in 0..t.len() {
                sums[i % 3] += at(i);
            }
            t.len() / 3
        }
        Some(m) => {
            for &p in m.pixels() {
                for (ch, sum) in sums.iter_mut().enumerate() {
                    *sum += at(p as usize * 3 + ch);
                }
            }
            m.pixels().len()
        }
    };
    let scale = 100.0 / (255.0 * count.max(1) as f64);
    let (r, g, b) = (
        sums[0] as f64 * scale,
        sums[1] as f64 * scale,
        sums[2] as f64 * scale,
    );
    Deviation {
        r,
        g,
        b,
        average: (r + g + b) / 3.0,
    }
}

fn render_fine(fine: &dyn Renderer, scene: &Scene, seed: u64, what: &str) -> Result<Image> {
    render_one(fine, scene, seed).map_err(|e| match e {
        Error::Run(m) => Error::Run(format!("stage 2, {what}: {m}")),
        other => other,
    })
}

fn dev(target: &FitTarget, img: &Image) -> Result<Deviation> {
    if img.dimensions() != target.image.dimensions() {
        return Err(Error::Run(format!(
            "stage 2: the fine renderer drew {}x{}, the target is {}x{}",
            img.width(),
            img.height(),
            target.image.width(),
            target.image.height()
        )));
    }
    Ok(deviation(&target.image, img, target.mask.as_ref()))
}

fn save(dir: &RunDir, state: &State, current: &Image) -> Result<()> {
    // The image first: a state file always has its render beside it.
    dir.write_image(SPACEMAP_CURRENT, current)?;
    dir.write_json(SPACEMAP_STATE, state)
}

/// fitted_scene.json, best.png, then result.json (its presence means the
/// stage finished).
fn finish(
    dir: &RunDir,
    state: State,
    scene: Scene,
    image: Image,
    fine: &dyn Renderer,
    target: &FitTarget,
    config: &MappedConfig,
) -> Result<Mapped> {
    let space = ParamSpace::from_scene(&scene);
    let result = FitResult {
        renderer: fine.name(),
        strategy: "mapped".into(),
        seed: config.seed,
        params: space.json_values(&scene),
        deviation: state.current,
        evaluations: state.fine_renders,
        generations: state.iterations.len(),
        wall_seconds: state.seconds,
        stop_reason: state.stop_reason.clone().unwrap_or_default(),
        target: target.path.as_ref().map(|p| p.display().to_string()),
        target_encoding: target.encoding,
        failed_renders: 0,
        identifiability: None,
        deviation_precise: None,
        shots: None,
        alternatives: Vec::new(),
        held_out: Vec::new(),
    };
    result.check_finite()?;
    dir.write_json(FITTED_SCENE, &scene)?;
    dir.write_image(BEST, &image)?;
    dir.write_json(
        RESULT,
        &MappedResult {
            result: result.clone(),
            method: "mapped".into(),
            noise_floor: state.noise_floor,
            coarse_renders: state.coarse_renders,
            iterations: state.iterations,
        },
    )?;
    Ok(Mapped { result, scene })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(v: &[u8]) -> Image {
        Image::from_raw(v.len() as u32 / 3, 1, v.to_vec()).unwrap()
    }

    /// `image` as a fit's target, made in memory.
    fn target_of(image: &Image) -> FitTarget {
        FitTarget {
            levels: None,
            image: image.clone(),
            mask: None,
            path: None,
            encoding: None,
        }
    }

    #[test]
    fn corrected_target_subtracts_the_fine_coarse_gap_and_clamps() {
        let t = img(&[100, 5, 250, 0, 0, 0]);
        let f = img(&[120, 20, 200, 0, 0, 0]);
        let c = img(&[100, 0, 240, 0, 0, 0]);
        // gap 20, 20, -40: 80, -15 -> 0, 290 -> 255
        assert_eq!(
            corrected_target(&t, &f, &c).as_raw(),
            &vec![80, 0, 255, 0, 0, 0]
        );
    }

    #[test]
    fn surrogate_at_the_current_point_is_the_fine_render() {
        let t = img(&[100, 50, 200, 10, 20, 30]);
        let f = img(&[90, 60, 190, 15, 20, 35]);
        let c = img(&[10, 200, 0, 255, 0, 7]);
        let target = target_of(&t);
        let s = surrogate_deviation(&target, &c, &f, &c);
        assert_eq!(s, deviation(&t, &f, None));
    }

    #[test]
    fn clamping_the_corrected_target_moves_every_candidate_alike() {
        // The deviation of a coarse render from the clamped corrected
        // target differs from the surrogate's by one constant.
        let t = img(&[10, 250, 128, 0, 255, 3]);
        let f = img(&[60, 200, 128, 30, 200, 3]);
        let ck = img(&[10, 255, 100, 0, 255, 0]);
        let target = target_of(&t);
        let corrected = corrected_target(&t, &f, &ck);
        let gaps: Vec<f64> = [[0u8; 6], [255; 6], [7, 99, 200, 13, 0, 255]]
            .iter()
            .map(|c| {
                let c = img(c);
                surrogate_deviation(&target, &c, &f, &ck).average
                    - deviation(&corrected, &c, None).average
            })
            .collect();
        assert!((gaps[0] - gaps[1]).abs() < 1e-9 && (gaps[0] - gaps[2]).abs() < 1e-9);
        assert!(gaps[0] > 0.0, "the clamp did cut here");
    }
}
