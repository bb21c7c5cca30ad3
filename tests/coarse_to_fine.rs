//! The coarse-to-fine local phase on a small synthetic image whose
//! parameters move edges: a disc (centre x, y and radius free) drawn with
//! 2 x 2 samples per pixel and rounded to 8-bit levels, as an anti-aliased
//! render is. Its residuals at a blur are those of `metric::blur`, the
//! view the fit's problem gives the search.
//!
//! - The forward and backward differences of the sharp residuals disagree
//!   value by value (each is a staircase of samples), those of the
//!   blurred residuals agree: what the coarse levels are for.
//! - The hybrid search, told those residuals, goes to the coarsest level
//!   by itself and lands on the disc within a twentieth of a pixel.

use scenefit::metric::{blurred_levels, blurred_residuals};
use scenefit::optimize::*;
use scenefit::raster::Image;

const SIZE: u32 = 48;
/// Unit coordinates to pixels: the centre spans 14..34, the radius 6..12.
const CENTRE_SPAN: f64 = 20.0;
const RADIUS_SPAN: f64 = 6.0;

fn geometry(u: &[f64]) -> (f64, f64, f64) {
    (
        14.0 + CENTRE_SPAN * u[0],
        14.0 + CENTRE_SPAN * u[1],
        6.0 + RADIUS_SPAN * u[2],
    )
}

/// A bright disc on a dark floor, 2 x 2 samples a pixel, 8-bit.
fn render(u: &[f64]) -> Image {
    let (cx, cy, radius) = geometry(u);
    Image::from_fn(SIZE, SIZE, |x, y| {
        let mut inside = 0;
        for (dx, dy) in [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)] {
            let (px, py) = (f64::from(x) + dx - cx, f64::from(y) + dy - cy);
            inside += u8::from(px * px + py * py < radius * radius);
        }
        let v = 30 + 50 * inside;
        image::Rgb([v, v / 2 + 20, 255 - v])
    })
}

fn sharp_residuals(target: &Image, img: &Image) -> Vec<f32> {
    let (t, r) = (target.as_raw(), img.as_raw());
    r.iter()
        .zip(t)
        .map(|(&a, &b)| f32::from(a) - f32::from(b))
        .collect()
}

fn fitness(target: &Image, img: &Image) -> f64 {
    let sum: f64 = sharp_residuals(target, img)
        .iter()
        .map(|v| f64::from(v.abs()))
        .sum();
    100.0 / 255.0 * sum / f64::from(SIZE * SIZE)
}

/// Runs the hybrid for `budget` renders, its residuals at the blur it
/// asks for. Returns the best point and the largest blur asked for.
fn fit(truth: &[f64], budget: usize) -> (Vec<f64>, f64) {
    let target = render(truth);
    let config = DeConfig {
        population: 20,
        strategy: Strategy::Hybrid,
        seed: 7,
        ..DeConfig::default()
    };
    let centre: Vec<f64> = truth.iter().map(|v| v + 0.04).collect();
    let start = Start::Around {
        center: &centre,
        radius: 0.03,
    };
    let mut search = Searcher::new(3, &config, start);
    let mut cached: Option<(u64, Vec<f32>)> = None;
    let mut widest: f64 = 0.0;
    while search.evaluations() < budget && !search.converged() {
        let request = search.ask();
        widest = widest.max(request.blur);
        let evaluations: Vec<Evaluation> = request
            .points
            .iter()
            .map(|u| {
                let img = render(u);
                let residuals = request.residuals.then(|| {
                    if request.blur > 0.0 {
                        let key = request.blur.to_bits();
                        if cached.as_ref().is_none_or(|(k, _)| *k != key) {
                            cached = Some((key, blurred_levels(&target, None, request.blur)));
                        }
                        let t = &cached.as_ref().unwrap().1;
                        blurred_residuals(t, &img, None, request.blur)
                    } else {
                        sharp_residuals(&target, &img)
                    }
                });
                Evaluation {
                    fitness: fitness(&target, &img),
                    residuals,
                }
            })
            .collect();
        search.tell(&evaluations);
    }
    (search.best().0.to_vec(), widest)
}

/// The largest error of the fitted geometry, in pixels.
fn error(fitted: &[f64], truth: &[f64]) -> f64 {
    let (a, b) = (geometry(fitted), geometry(truth));
    [(a.0 - b.0), (a.1 - b.1), (a.2 - b.2)]
        .iter()
        .map(|d| d.abs())
        .fold(0.0, f64::max)
}

#[test]
fn the_search_goes_coarse_on_moving_edges_and_lands_on_them() {
    let truth = [0.413, 0.571, 0.537];
    let (coarse, widest) = fit(&truth, 1500);
    let e = error(&coarse, &truth);
    eprintln!("error: {e:.4} px");
    // The edges' noise made the search go coarse, from the first level.
    assert_eq!(widest, 4.0);
    assert!(e < 0.05, "{e}");
}

/// The cosine between the forward and the backward difference of the
/// residuals along the centre's x at the truth, step `h`, at blur `sigma`
/// (0: sharp): 1 when both see the same slope in every value.
fn agreement(truth: &[f64], h: f64, sigma: f64) -> f64 {
    let target = render(truth);
    let view = |u: &[f64]| -> Vec<f32> {
        let img = render(u);
        if sigma > 0.0 {
            blurred_residuals(&blurred_levels(&target, None, sigma), &img, None, sigma)
        } else {
            sharp_residuals(&target, &img)
        }
    };
    let moved = |d: f64| view(&[truth[0] + d, truth[1], truth[2]]);
    let (r, a, b) = (view(truth), moved(h), moved(-h));
    let (mut ab, mut aa, mut bb) = (0.0, 0.0, 0.0);
    for ((&r, &a), &b) in r.iter().zip(&a).zip(&b) {
        let (x, y) = (f64::from(a - r), f64::from(r - b));
        ab += x * y;
        aa += x * x;
        bb += y * y;
    }
    ab / (aa * bb).sqrt()
}

#[test]
fn blurred_differences_agree_where_sharp_ones_do_not() {
    let truth = [0.413, 0.571, 0.537];
    // Steps of 0.1 to 0.8 px of the centre: at every one the blur of the
    // coarsest level makes the columns agree, and a wider blur agrees
    // more.
    for h in [0.005, 0.01, 0.02, 0.04] {
        let [sharp, fine, coarse] = [0.0, 2.0, 4.0].map(|s| agreement(&truth, h, s));
        eprintln!("h {h}: sharp {sharp:.3}, blur 2: {fine:.3}, blur 4: {coarse:.3}");
        assert!(
            sharp < fine && fine < coarse,
            "h {h}: {sharp} {fine} {coarse}"
        );
        assert!(
            coarse > 0.7 && coarse > sharp + 0.2,
            "h {h}: {sharp} {coarse}"
        );
    }
}
