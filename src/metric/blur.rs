//! The residuals of blurred images: target and render each smoothed by the
//! same Gaussian, then subtracted, for a local search's coarse levels.
//!
//! Why: on an 8-bit anti-aliased image an edge moves in steps of a
//! sample, so a finite difference of a parameter that moves edges is a
//! staircase value by value (docs/results.md, "Why the local phase stalls
//! there"). A blur wider than those steps turns each staircase into a
//! ramp; its minimum is still where the render matches the photograph,
//! so a coarse-to-fine local search (`optimize::pyramid`) descends the
//! smooth problem first and the sharp one last.
//!
//! The blur is a normalised convolution over the pixels that count (a
//! mask's, or all): `G * (w·I) / G * w`, with `w` 1 on a counted pixel and
//! 0 elsewhere, so pixels outside the mask or the image add nothing and a
//! constant image stays that constant. Separable, one thread, a fixed
//! order: the same input gives the same bits.

use super::Mask;
use crate::raster::Image;

/// Kernel half-width in standard deviations: the weight left out is
/// below 3e-3 of the whole.
const REACH: f64 = 3.0;

/// The kernel of a Gaussian of `sigma` pixels, from −radius to radius
/// (unnormalised: the normalised convolution divides by the weights).
fn kernel(sigma: f64) -> Vec<f32> {
    let radius = (REACH * sigma).ceil().max(1.0) as i64;
    (-radius..=radius)
        .map(|i| (-(i * i) as f64 / (2.0 * sigma * sigma)).exp() as f32)
        .collect()
}

/// Convolves `planes` (each `width` x `height`, row-major) with `k` along
/// x (`along_x`) or y, taps outside the image left out.
fn pass(planes: &mut [Vec<f32>], width: usize, height: usize, k: &[f32], along_x: bool) {
    let radius = (k.len() / 2) as i64;
    let (n, stride, lines, line_stride) = if along_x {
        (width, 1, height, width)
    } else {
        (height, width, width, 1)
    };
    let mut line = vec![0f32; n];
    for plane in planes.iter_mut() {
        for l in 0..lines {
            let base = l * line_stride;
            for (i, v) in line.iter_mut().enumerate() {
                *v = plane[base + i * stride];
            }
            for i in 0..n {
                let lo = (i as i64 - radius).max(0) as usize;
                let hi = (i as i64 + radius).min(n as i64 - 1) as usize;
                let mut sum = 0f32;
                for (j, &v) in line.iter().enumerate().take(hi + 1).skip(lo) {
                    sum += k[(j as i64 - i as i64 + radius) as usize] * v;
                }
                plane[base + i * stride] = sum;
            }
        }
    }
}

/// 1 on each pixel of a `width` x `height` image that `mask` counts (all
/// when None), 0 elsewhere.
fn counted(width: usize, height: usize, mask: Option<&Mask>) -> Vec<f32> {
    let mut weight = vec![0f32; width * height];
    match mask {
        None => weight.fill(1.0),
        Some(m) => m.pixels().iter().for_each(|&p| weight[p as usize] = 1.0),
    }
    weight
}

/// The counted weight under the Gaussian of `sigma` pixels at each pixel
/// of a `width` x `height` image (`G * w`): the divisor of every blur
/// under `mask`, the same for each render of one photograph, so a caller
/// blurring many computes it once ([`blurred_residuals_with`]).
pub fn blurred_weight(width: u32, height: u32, mask: Option<&Mask>, sigma: f64) -> Vec<f32> {
    let (width, height) = (width as usize, height as usize);
    let mut planes = vec![counted(width, height, mask)];
    let k = kernel(sigma);
    pass(&mut planes, width, height, &k, true);
    pass(&mut planes, width, height, &k, false);
    planes.pop().unwrap_or_default()
}

/// The blurred 8-bit levels of `image` (3 per pixel, the image's order),
/// averaged over the pixels `mask` counts (all when None): a Gaussian of
/// `sigma` pixels, normalised by the counted weight under it. A pixel with
/// no counted pixel within reach keeps 0.
pub fn blurred_levels(image: &Image, mask: Option<&Mask>, sigma: f64) -> Vec<f32> {
    let weight = blurred_weight(image.width(), image.height(), mask, sigma);
    levels_over(image, mask, sigma, &weight)
}

/// [`blurred_levels`] with the blurred weight given ([`blurred_weight`]
/// of the same size, mask and blur): each plane is blurred on its own,
/// so the values are the same bits.
fn levels_over(image: &Image, mask: Option<&Mask>, sigma: f64, blurred: &[f32]) -> Vec<f32> {
    let (width, height) = (image.width() as usize, image.height() as usize);
    let raw = image.as_raw();
    let weight = counted(width, height, mask);
    let mut planes: Vec<Vec<f32>> = (0..3)
        .map(|c| {
            (0..width * height)
                .map(|p| weight[p] * f32::from(raw[3 * p + c]))
                .collect()
        })
        .collect();
    let k = kernel(sigma);
    pass(&mut planes, width, height, &k, true);
    pass(&mut planes, width, height, &k, false);
    let mut out = vec![0f32; 3 * width * height];
    for p in 0..width * height {
        let w = blurred[p];
        if w > 0.0 {
            for c in 0..3 {
                out[3 * p + c] = planes[c][p] / w;
            }
        }
    }
    out
}

/// Render − target per channel value over `mask` (all pixels when None),
/// both blurred by a Gaussian of `sigma` pixels ([`blurred_levels`]);
/// `target` is the target's blurred levels, computed once. The order is
/// that of [`super::residuals`].
pub fn blurred_residuals(
    target: &[f32],
    render: &Image,
    mask: Option<&Mask>,
    sigma: f64,
) -> Vec<f32> {
    let weight = blurred_weight(render.width(), render.height(), mask, sigma);
    blurred_residuals_with((target, &weight), render, mask, sigma)
}

/// [`blurred_residuals`] with the target's blurred levels and the blurred
/// weight of `mask` given ([`blurred_weight`]), both computed once per
/// photograph and blur rather than per render.
pub fn blurred_residuals_with(
    (target, weight): (&[f32], &[f32]),
    render: &Image,
    mask: Option<&Mask>,
    sigma: f64,
) -> Vec<f32> {
    let r = levels_over(render, mask, sigma, weight);
    debug_assert_eq!(r.len(), target.len());
    match mask {
        None => r.iter().zip(target).map(|(a, b)| a - b).collect(),
        Some(m) => m
            .pixels()
            .iter()
            .flat_map(|&px| {
                let i = px as usize * 3;
                [0, 1, 2].map(|c| r[i + c] - target[i + c])
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_image_stays_that_constant_to_its_borders() {
        let img = Image::from_pixel(13, 7, image::Rgb([40, 128, 250]));
        for sigma in [0.7, 2.0, 4.0] {
            let b = blurred_levels(&img, None, sigma);
            for px in b.chunks_exact(3) {
                assert!((px[0] - 40.0).abs() < 1e-3, "{sigma}: {px:?}");
                assert!((px[1] - 128.0).abs() < 1e-3 && (px[2] - 250.0).abs() < 1e-3);
            }
        }
    }

    #[test]
    fn the_blur_keeps_the_sum_of_a_point_and_spreads_it() {
        // A white dot in the middle of black: the blurred values spread it
        // over its neighbours, keep its total and peak at the dot.
        let mut img = Image::from_pixel(31, 31, image::Rgb([0, 0, 0]));
        img.put_pixel(15, 15, image::Rgb([255, 255, 255]));
        let b = blurred_levels(&img, None, 2.0);
        let red: Vec<f32> = b.iter().step_by(3).copied().collect();
        let total: f32 = red.iter().sum();
        assert!((total - 255.0).abs() < 0.5, "{total}");
        let centre = red[15 * 31 + 15];
        assert!(
            centre < 255.0 / 10.0 && centre > red[15 * 31 + 17],
            "{centre}"
        );
        assert!(red[15 * 31 + 17] > 0.0);
    }

    #[test]
    fn pixels_outside_the_mask_add_nothing() {
        // Left half 100, right half 200; a mask of the left half: every
        // blurred value it counts is 100, however near the boundary.
        let img = Image::from_fn(10, 4, |x, _| {
            let v = if x < 5 { 100 } else { 200 };
            image::Rgb([v, v, v])
        });
        let left: Vec<u32> = (0..40).filter(|p| p % 10 < 5).collect();
        let mask = Mask::from_pixels(10, 4, left);
        let target = blurred_levels(&img, Some(&mask), 3.0);
        let same = blurred_residuals(&target, &img, Some(&mask), 3.0);
        assert_eq!(same.len(), 3 * 20);
        assert!(same.iter().all(|&r| r == 0.0));
        assert!((target[3 * 4] - 100.0).abs() < 1e-3, "{}", target[3 * 4]);
    }

    /// The weight blurred once and reused gives the residuals of the
    /// weight blurred with each render, bit for bit, with a mask and
    /// without.
    #[test]
    fn a_weight_blurred_once_gives_the_same_residuals() {
        let target = Image::from_fn(17, 9, |x, y| {
            image::Rgb([(7 * x) as u8, (20 * y) as u8, 90])
        });
        let render = Image::from_fn(17, 9, |x, y| {
            image::Rgb([(5 * x) as u8, (3 * x * y) as u8, 200])
        });
        let mask = Mask::from_pixels(17, 9, (0..153).filter(|p| p % 4 != 1).collect());
        for mask in [None, Some(&mask)] {
            let levels = blurred_levels(&target, mask, 1.5);
            let weight = blurred_weight(17, 9, mask, 1.5);
            let each = blurred_residuals(&levels, &render, mask, 1.5);
            let once = blurred_residuals_with((&levels, &weight), &render, mask, 1.5);
            assert!(each.iter().any(|&r| r != 0.0));
            assert_eq!(each, once);
        }
    }
}
