//! A tangent-space normal map for the tests (docs/scene-format.md,
//! "Textures": OpenGL convention, +Y up, linear): the normals of the
//! height field h(u, v) = a sin(2 pi u) sin(2 pi v) over one repeat,
//! written as a 16-bit PNG so that the texels hold the vectors closely.

use std::f64::consts::PI;
use std::path::Path;

/// Writes the bump map (`n` x `n` texels, slope amplitude `a`: the
/// steepest tilt is atan(2 pi a)) to `path`.
pub fn write(path: &Path, n: u32, a: f64) {
    let img = image::ImageBuffer::<image::Rgb<u16>, Vec<u16>>::from_fn(n, n, |i, j| {
        // texel centres: u right, v up (row 0 at the top)
        let u = (i as f64 + 0.5) / n as f64;
        let v = 1.0 - (j as f64 + 0.5) / n as f64;
        let hu = a * 2.0 * PI * (2.0 * PI * u).cos() * (2.0 * PI * v).sin();
        let hv = a * 2.0 * PI * (2.0 * PI * u).sin() * (2.0 * PI * v).cos();
        let len = (hu * hu + hv * hv + 1.0).sqrt();
        let c = |x: f64| ((x / len * 0.5 + 0.5) * 65535.0).round() as u16;
        image::Rgb([c(-hu), c(-hv), c(1.0)])
    });
    img.save(path).unwrap();
}
