//! Tests of the hybrid search (SHADE handing over to Levenberg–Marquardt)
//! on synthetic residual problems, no renderer needed:
//! - a parametric "image": three coloured Gaussian blobs (12 parameters)
//!   sampled on a 64x48 grid and rounded to 8-bit levels, scored like a
//!   fit (sum of the three channels' mean deviations in percent);
//! - Rosenbrock written as residuals;
//! - the same blobs from one point with no global phase, where a purely
//!   local method fails.
//!
//! They check that the hybrid reaches the target on every seed with fewer
//! evaluations than SHADE, that a seed fixes the run, that a checkpoint
//! taken mid-local-phase continues identically, and that the reported
//! standard errors match the spread of fits to noisy images.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use scenefit::optimize::*;

const WIDTH: usize = 64;
const HEIGHT: usize = 48;

/// A problem: residuals (render − target) of a unit-cube point.
trait Problem {
    fn residuals(&self, u: &[f64]) -> Vec<f32>;
    /// The fit's score of a residual vector.
    fn fitness(&self, r: &[f32]) -> f64;
}

/// Three Gaussian blobs, each strongest in one channel, on a grey floor.
/// Parameters per blob: centre x, centre y, width, amplitude.
struct Blobs {
    target: Vec<f32>,
    /// Whether the render is rounded to 8-bit levels like the target.
    rounded: bool,
}

impl Blobs {
    fn render(u: &[f64]) -> Vec<f64> {
        let mut image = vec![0.1; WIDTH * HEIGHT * 3];
        for blob in 0..3 {
            let p = &u[4 * blob..4 * blob + 4];
            let (cx, cy) = (p[0] * WIDTH as f64, p[1] * HEIGHT as f64);
            let sigma = 4.0 + 10.0 * p[2];
            let amplitude = 0.2 + 0.7 * p[3];
            for y in 0..HEIGHT {
                for x in 0..WIDTH {
                    let d2 = (x as f64 - cx).powi(2) + (y as f64 - cy).powi(2);
                    let value = amplitude * (-d2 / (2.0 * sigma * sigma)).exp();
                    for c in 0..3 {
                        let mix = if c == blob { 0.6 } else { 0.15 };
                        image[(y * WIDTH + x) * 3 + c] += mix * value;
                    }
                }
            }
        }
        image
    }

    fn quantise(value: f64) -> f32 {
        (255.0 * value).round().clamp(0.0, 255.0) as f32
    }

    fn new(truth: &[f64]) -> Blobs {
        Blobs {
            target: Blobs::render(truth)
                .into_iter()
                .map(Blobs::quantise)
                .collect(),
            rounded: true,
        }
    }

    /// The target with Gaussian noise of `sigma` levels added before
    /// rounding, as a camera would. The render is not rounded: rounding
    /// makes the deviation a step function of the parameters on the scale
    /// of the standard errors, and where a fit stops would then measure the
    /// rounding, not the noise the standard errors describe.
    fn noisy(truth: &[f64], sigma: f64, seed: u64) -> Blobs {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let target = Blobs::render(truth)
            .into_iter()
            .map(|v| {
                let noise = sigma * gaussian(&mut rng) / 255.0;
                Blobs::quantise(v + noise)
            })
            .collect();
        Blobs {
            target,
            rounded: false,
        }
    }
}

fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    use rand::Rng;
    let u1: f64 = 1.0 - rng.gen::<f64>();
    let u2: f64 = rng.gen::<f64>();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

impl Problem for Blobs {
    fn residuals(&self, u: &[f64]) -> Vec<f32> {
        Blobs::render(u)
            .into_iter()
            .zip(&self.target)
            .map(|(v, &t)| {
                if self.rounded {
                    Blobs::quantise(v) - t
                } else {
                    (255.0 * v) as f32 - t
                }
            })
            .collect()
    }

    fn fitness(&self, r: &[f32]) -> f64 {
        let sum: f64 = r.iter().map(|v| f64::from(v.abs())).sum();
        100.0 / 255.0 * sum / (WIDTH * HEIGHT) as f64
    }
}

/// Rosenbrock as residuals `10 (x_{k+1} − x_k²)` and `1 − x_k`, with `x`
/// in [-2, 2]; the minimum 0 is at x = 1 (u = 0.75). Residuals are given
/// in "levels" of 1/100 (a unit residual is 100 levels, as a full-range
/// change of an image value is 255), which is the scale the search's
/// difference steps are tuned for; the fitness is Σ|r| in plain units.
struct Rosenbrock {
    dim: usize,
}

impl Problem for Rosenbrock {
    fn residuals(&self, u: &[f64]) -> Vec<f32> {
        let x: Vec<f64> = u.iter().map(|&u| -2.0 + 4.0 * u).collect();
        let mut r = Vec::new();
        for k in 0..self.dim - 1 {
            r.push((LEVELS * 10.0 * (x[k + 1] - x[k] * x[k])) as f32);
            r.push((LEVELS * (1.0 - x[k])) as f32);
        }
        r
    }

    fn fitness(&self, r: &[f32]) -> f64 {
        r.iter().map(|v| f64::from(v.abs())).sum::<f64>() / LEVELS
    }
}

/// Levels per unit of a Rosenbrock residual.
const LEVELS: f64 = 100.0;

fn evaluate(problem: &dyn Problem, request: &Request) -> Vec<Evaluation> {
    request
        .points
        .iter()
        .map(|u| {
            let r = problem.residuals(u);
            Evaluation {
                fitness: problem.fitness(&r),
                residuals: request.residuals.then_some(r),
            }
        })
        .collect()
}

/// Runs until the best fitness is at or below `target`, the search has
/// converged, or `budget` evaluations are used; returns the evaluations
/// spent when the target was reached.
fn run(search: &mut Searcher, problem: &dyn Problem, target: f64, budget: usize) -> Option<usize> {
    while search.evaluations() < budget {
        let request = search.ask();
        search.tell(&evaluate(problem, &request));
        if search.best().1 <= target {
            return Some(search.evaluations());
        }
        if search.converged() {
            return None;
        }
    }
    None
}

fn config(strategy: Strategy, seed: u64) -> DeConfig {
    DeConfig {
        population: 40,
        strategy,
        seed,
        ..DeConfig::default()
    }
}

fn blob_truth() -> Vec<f64> {
    vec![
        0.3, 0.35, 0.4, 0.7, // red blob
        0.65, 0.6, 0.3, 0.5, // green blob
        0.45, 0.7, 0.6, 0.9, // blue blob
    ]
}

/// 0.05 % summed deviation: nearly every 8-bit value exact.
const BLOB_TARGET: f64 = 0.05;

#[test]
fn hybrid_reaches_the_blob_target_on_every_seed_with_fewer_evaluations_than_shade() {
    let problem = Blobs::new(&blob_truth());
    let mut hybrid_total = 0;
    let mut shade_total = 0;
    for seed in 1..=8 {
        let mut shade = Searcher::new(12, &config(Strategy::Shade, seed), Start::Uniform);
        let shade_evals = run(&mut shade, &problem, BLOB_TARGET, 120_000);
        let mut hybrid = Searcher::new(12, &config(Strategy::Hybrid, seed), Start::Uniform);
        let hybrid_evals = run(&mut hybrid, &problem, BLOB_TARGET, 120_000);
        eprintln!("seed {seed}: shade {shade_evals:?}, hybrid {hybrid_evals:?}");
        let hybrid_evals = hybrid_evals.unwrap_or_else(|| {
            panic!(
                "hybrid missed the target on seed {seed}: best {}",
                hybrid.best().1
            )
        });
        hybrid_total += hybrid_evals;
        shade_total += shade_evals.unwrap_or(120_000);
    }
    assert!(
        hybrid_total < shade_total,
        "hybrid used {hybrid_total} evaluations over the seeds, SHADE {shade_total}"
    );
}

#[test]
fn hybrid_solves_rosenbrock_residuals_on_every_seed_with_fewer_evaluations() {
    let problem = Rosenbrock { dim: 6 };
    let mut hybrid_total = 0;
    let mut shade_total = 0;
    for seed in 1..=8 {
        let mut shade = Searcher::new(6, &config(Strategy::Shade, seed), Start::Uniform);
        let shade_evals = run(&mut shade, &problem, 1e-4, 200_000);
        let mut hybrid = Searcher::new(6, &config(Strategy::Hybrid, seed), Start::Uniform);
        let hybrid_evals = run(&mut hybrid, &problem, 1e-4, 200_000);
        eprintln!("seed {seed}: shade {shade_evals:?}, hybrid {hybrid_evals:?}");
        hybrid_total += hybrid_evals.expect("hybrid reaches the Rosenbrock target");
        shade_total += shade_evals.unwrap_or(200_000);
    }
    assert!(
        hybrid_total < shade_total,
        "hybrid used {hybrid_total} evaluations over the seeds, SHADE {shade_total}"
    );
}

#[test]
fn a_local_method_alone_fails_on_the_blobs_where_the_hybrid_succeeds() {
    // A population of one repeated point has no spread, so the hybrid
    // hands over at once: a pure Levenberg–Marquardt run from that point.
    let problem = Blobs::new(&blob_truth());
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut failures = 0;
    for _ in 0..4 {
        use rand::Rng;
        let center: Vec<f64> = (0..12).map(|_| rng.gen::<f64>()).collect();
        let start = Start::Around {
            center: &center,
            radius: 0.0,
        };
        let mut local = Searcher::new(12, &config(Strategy::Hybrid, 1), start);
        // A settling run draws no fresh population once this one is
        // stuck, so it stays a local method alone.
        local.settle();
        if run(&mut local, &problem, BLOB_TARGET, 120_000).is_none() {
            failures += 1;
        }
    }
    assert!(
        failures > 0,
        "every local run succeeded: the test problem is too easy"
    );
}

#[test]
fn a_stuck_population_is_followed_by_fresh_ones_that_find_the_target() {
    // The starts of the test above, where a local method alone fails: the
    // default hybrid, once its collapsed population is stuck, draws fresh
    // populations over the whole cube (the restarts) and reaches the
    // target from every one.
    let problem = Blobs::new(&blob_truth());
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for i in 0..4 {
        use rand::Rng;
        let center: Vec<f64> = (0..12).map(|_| rng.gen::<f64>()).collect();
        let start = Start::Around {
            center: &center,
            radius: 0.0,
        };
        let mut search = Searcher::new(12, &config(Strategy::Hybrid, 1), start);
        let reached = run(&mut search, &problem, BLOB_TARGET, 120_000);
        assert!(reached.is_some(), "start {i}: the target was not reached");
    }
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn same_seed_gives_the_same_run_and_a_checkpoint_mid_local_phase_continues_identically() {
    let problem = Blobs::new(&blob_truth());
    // One periodic coordinate (as a hue's), which the checkpoint must keep.
    let mut periods = vec![0.0; 12];
    periods[3] = 2.0 / 3.0;
    let mut first = Searcher::new(12, &config(Strategy::Hybrid, 5), Start::Uniform);
    first.set_periods(periods.clone());
    // Run into the local phase, then a few steps further.
    let mut local_steps = 0;
    while local_steps < 3 {
        let request = first.ask();
        first.tell(&evaluate(&problem, &request));
        if request.residuals {
            local_steps += 1;
        }
        assert!(!first.converged(), "converged before the checkpoint");
    }
    let text = serde_json::to_string(&first).expect("serialise");
    let state: serde_json::Value = serde_json::from_str(&text).expect("json");
    let bits_of = |v: &serde_json::Value| v[3].as_u64();
    assert_eq!(
        bits_of(&state["hybrid"]["periods"]),
        Some((2.0f64 / 3.0).to_bits()),
        "the checkpoint keeps the periods"
    );
    let mut resumed: Searcher = serde_json::from_str(&text).expect("deserialise");
    let mut second = Searcher::new(12, &config(Strategy::Hybrid, 5), Start::Uniform);
    second.set_periods(periods);
    for search in [&mut first, &mut resumed, &mut second] {
        run(search, &problem, 0.0, 60_000);
    }
    for other in [&resumed, &second] {
        assert_eq!(bits(first.best().0), bits(other.best().0));
        assert_eq!(first.best().1.to_bits(), other.best().1.to_bits());
        assert_eq!(first.evaluations(), other.evaluations());
        assert_eq!(first.generation(), other.generation());
    }
}

#[test]
fn standard_errors_match_the_spread_of_fits_to_noisy_images() {
    let truth = blob_truth();
    let fits = 16;
    let mut fitted = Vec::new();
    let mut reported = [0.0; 12];
    for noise_seed in 0..fits {
        let problem = Blobs::noisy(&truth, 4.0, 100 + noise_seed);
        // Start at the truth: the test is about the local fit's statistics.
        let start = Start::Around {
            center: &truth,
            radius: 0.0,
        };
        let mut search = Searcher::new(12, &config(Strategy::Hybrid, 1), start);
        run(&mut search, &problem, 0.0, 20_000);
        eprintln!(
            "fit {noise_seed}: {} evaluations, fitness {}",
            search.evaluations(),
            search.best().1
        );
        let id = search
            .identifiability()
            .expect("standard errors after the local phase");
        for (sum, e) in reported.iter_mut().zip(&id.std_error) {
            *sum += e / fits as f64;
        }
        fitted.push(search.best().0.to_vec());
    }
    let mut worst = (0, 1.0f64);
    for j in 0..12 {
        let mean = fitted.iter().map(|x| x[j]).sum::<f64>() / fits as f64;
        let var = fitted.iter().map(|x| (x[j] - mean).powi(2)).sum::<f64>() / (fits - 1) as f64;
        let ratio = reported[j] / var.sqrt();
        eprintln!(
            "coordinate {j}: spread {:.2e}, reported {:.2e}, ratio {ratio:.2}",
            var.sqrt(),
            reported[j]
        );
        if (ratio.ln()).abs() > worst.1.ln().abs() {
            worst = (j, ratio);
        }
    }
    assert!(
        (0.5..=2.0).contains(&worst.1),
        "coordinate {}: reported standard error / spread of fits = {:.2}",
        worst.0,
        worst.1
    );
}

#[test]
fn hybrid_is_a_strategy_name_and_de_never_runs_it() {
    assert_eq!("hybrid".parse::<Strategy>(), Ok(Strategy::Hybrid));
    let de = De::new(3, config(Strategy::Hybrid, 1));
    assert_eq!(de.config().strategy, Strategy::Shade);
    let searcher = Searcher::new(3, &config(Strategy::Hybrid, 1), Start::Uniform);
    assert_eq!(searcher.strategy(), Strategy::Hybrid);
    let searcher = Searcher::new(3, &config(Strategy::Jde, 1), Start::Uniform);
    assert_eq!(searcher.strategy(), Strategy::Jde);
}

#[test]
fn a_damaged_hybrid_state_is_refused_on_loading() {
    let problem = Blobs::new(&blob_truth());
    let mut search = Searcher::new(12, &config(Strategy::Hybrid, 2), Start::Uniform);
    while !search.ask().residuals {
        let request = search.ask();
        search.tell(&evaluate(&problem, &request));
    }
    let mut value = serde_json::to_value(&search).expect("serialise");
    value["hybrid"]["best"] = serde_json::json!([1, 2]);
    let error = serde_json::from_value::<Searcher>(value).expect_err("damaged state");
    assert!(error.to_string().contains("dimension 12"), "{error}");
}

#[test]
fn a_finished_local_run_hands_its_point_back_to_the_global_phase() {
    // Noisy, so that no run fits exactly: a population whose local run
    // ends at a deviation of 0 is done, and is redrawn for a second
    // opinion (a restart) instead of taking the point back.
    let problem = Blobs::noisy(&blob_truth(), 4.0, 7);
    let mut search = Searcher::new(12, &config(Strategy::Hybrid, 3), Start::Uniform);
    let mut was_local = false;
    let mut at_handover = f64::INFINITY;
    // Until the first local run has ended and SHADE asks again.
    loop {
        let request = search.ask();
        if was_local && !request.residuals {
            break;
        }
        if request.residuals && !was_local {
            at_handover = search.best().1;
        }
        was_local |= request.residuals;
        search.tell(&evaluate(&problem, &request));
        assert!(
            !search.converged(),
            "converged while the population can move"
        );
        assert!(search.evaluations() < 60_000, "never went back to SHADE");
    }
    let (population, fitness) = search.population().expect("global phase again");
    assert!(
        fitness.iter().any(|f| f.is_finite()),
        "the population was redrawn (a restart), not handed the point"
    );
    let (best, best_fitness) = search.best();
    assert!(best_fitness < at_handover, "the local run found nothing");
    let held = population
        .iter()
        .zip(fitness)
        .any(|(x, &f)| bits(x) == bits(best) && f.to_bits() == best_fitness.to_bits());
    assert!(held, "the local run's best point is not in the population");
}

#[test]
fn a_settling_hybrid_ends_near_the_minimum_without_spending_its_budget() {
    // As a diagnosis refit runs: warm, around a point near the truth.
    let problem = Blobs::new(&blob_truth());
    let center: Vec<f64> = blob_truth().iter().map(|v| v + 0.03).collect();
    let start = Start::Around {
        center: &center,
        radius: 0.2,
    };
    let budget = 40_000;
    for seed in 1..=3 {
        let mut settling = Searcher::new(12, &config(Strategy::Hybrid, seed), start);
        settling.settle();
        run(&mut settling, &problem, 0.0, budget);
        let mut full = Searcher::new(12, &config(Strategy::Hybrid, seed), start);
        run(&mut full, &problem, 0.0, budget);
        eprintln!(
            "seed {seed}: settled after {} evaluations at {:.5}, the full budget {} at {:.5}",
            settling.evaluations(),
            settling.best().1,
            full.evaluations(),
            full.best().1
        );
        assert!(settling.converged(), "seed {seed}: never settled");
        assert!(
            settling.evaluations() * 4 <= budget,
            "seed {seed}: settled after {} of {budget} evaluations",
            settling.evaluations(),
        );
        assert!(
            settling.best().1 <= (2.0 * full.best().1).max(BLOB_TARGET),
            "seed {seed}: settled at {}, the full budget reached {}",
            settling.best().1,
            full.best().1
        );
    }
}
