//! The built-in tracer's optional effects, each a separate pass that runs
//! only when its scene field is present (docs/scene-format.md "Effects"),
//! so that scenes without them shade through the fast kernel unchanged:
//! a distance falloff d^-p, soft shadows of an area light, a general
//! specular pass (Schlick Fresnel, a second lobe) and a one-bounce
//! inter-reflection estimate from virtual point lights (Keller, "Instant
//! Radiosity", SIGGRAPH 1997), without visibility.

use super::geometry::Geometry;
use super::packed::Packed;
use crate::math::V3;

/// Shadow rays per hit towards an area light.
const AREA_SAMPLES: usize = 16;
/// Virtual point lights of the one-bounce estimate.
const BOUNCE_LIGHTS: usize = 64;
/// Keeps the one-bounce kernel finite where two hits nearly touch (m^2).
const BOUNCE_EPS: f32 = 0.01;

fn at(pk: &Packed, i: usize) -> V3 {
    V3::new(pk.px[i] as f64, pk.py[i] as f64, pk.pz[i] as f64)
}

fn normal(pk: &Packed, i: usize) -> V3 {
    V3::new(pk.nx[i] as f64, pk.ny[i] as f64, pk.nz[i] as f64)
}

/// Multiplies each lit hit's irradiance by d^-p, d its distance to the light.
pub fn falloff(pk: &Packed, light: [f32; 3], p: f32, e: &mut [f32]) {
    for (i, ei) in e.iter_mut().enumerate().take(pk.n) {
        if *ei > 0.0 {
            let (dx, dy, dz) = (
                light[0] - pk.px[i],
                light[1] - pk.py[i],
                light[2] - pk.pz[i],
            );
            *ei *= (dx * dx + dy * dy + dz * dz).powf(-0.5 * p);
        }
    }
}

/// Points of a unit disk spread evenly (Vogel's spiral): the same for every
/// hit and render, so the fit sees no sampling noise.
fn disk() -> [(f64, f64); AREA_SAMPLES] {
    let mut d = [(0.0, 0.0); AREA_SAMPLES];
    for (k, s) in d.iter_mut().enumerate() {
        let r = ((k as f64 + 0.5) / AREA_SAMPLES as f64).sqrt();
        let a = k as f64 * 2.399_963_229_728_653;
        *s = (r * a.cos(), r * a.sin());
    }
    d
}

/// Two unit vectors perpendicular to unit `w` and to each other.
fn basis(w: V3) -> (V3, V3) {
    let t = if w.x.abs() < 0.9 {
        V3::new(1.0, 0.0, 0.0)
    } else {
        V3::new(0.0, 1.0, 0.0)
    };
    let a = w.cross(t).normalized();
    (a, w.cross(a))
}

/// Irradiance factor from an area light: the mean over shadow rays to points
/// of the light's disk facing the hit (point light: a sphere of `radius`
/// metres; directional: a cone of `radius` radians) of cos * d^-p * V.
/// Replaces `e` for every hit.
pub fn soft_shadows(
    pk: &Packed,
    geo: &Geometry,
    point: bool,
    light: [f32; 3],
    radius: f64,
    power: f32,
    e: &mut [f32],
) {
    let disk = disk();
    let c = V3::new(light[0] as f64, light[1] as f64, light[2] as f64);
    let p_exp = power as f64;
    for (i, ei) in e.iter_mut().enumerate().take(pk.n) {
        let (p, n) = (at(pk, i), normal(pk, i));
        let axis = if point { (c - p).normalized() } else { c };
        let (a, b) = basis(axis);
        let origin = p + n * 1e-6;
        let mut sum = 0.0;
        for &(dx, dy) in &disk {
            let off = (a * dx + b * dy) * radius;
            let (w, dist, fall) = if point {
                let to = c + off - p;
                let d = to.length();
                (to * (1.0 / d), d, d.powf(-p_exp))
            } else {
                ((c + off).normalized(), f64::INFINITY, 1.0)
            };
            let cos = n.dot(w);
            if cos <= 0.0 || geo.intersect(origin, w, dist).is_some() {
                continue;
            }
            sum += cos * fall;
        }
        *ei = (sum / AREA_SAMPLES as f64) as f32;
    }
}

/// A material's specular lobes, normalised as in `shade.rs`.
pub struct Lobes {
    pub spec: f32,
    pub shininess: f32,
    pub spec2: f32,
    pub shininess2: f32,
    pub fresnel: Option<f32>,
}

/// Adds the specular lobes of one light over `range`, with Schlick's
/// F(H.V)/F0 when the material has Fresnel (1 at normal incidence, so that
/// `specular` keeps its meaning).
#[allow(clippy::too_many_arguments)]
pub fn specular(
    pk: &Packed,
    range: std::ops::Range<usize>,
    lobes: &Lobes,
    point: bool,
    light: [f32; 3],
    power: [f32; 3],
    e: &[f32],
    r: &mut [f32],
    g: &mut [f32],
    b: &mut [f32],
) {
    for i in range {
        if e[i] <= 0.0 {
            continue;
        }
        let (mut lx, mut ly, mut lz) = (light[0], light[1], light[2]);
        if point {
            let (tx, ty, tz) = (lx - pk.px[i], ly - pk.py[i], lz - pk.pz[i]);
            let inv = 1.0 / (tx * tx + ty * ty + tz * tz).sqrt();
            (lx, ly, lz) = (tx * inv, ty * inv, tz * inv);
        }
        let (vx, vy, vz) = (pk.vx[i], pk.vy[i], pk.vz[i]);
        let (hx, hy, hz) = (lx + vx, ly + vy, lz + vz);
        let hl = (hx * hx + hy * hy + hz * hz).sqrt();
        if hl <= 1e-12 {
            continue;
        }
        let nh = (pk.nx[i] * hx + pk.ny[i] * hy + pk.nz[i] * hz) / hl;
        if nh <= 0.0 {
            continue;
        }
        let mut s = lobes.spec * nh.powf(lobes.shininess);
        if lobes.spec2 > 0.0 {
            s += lobes.spec2 * nh.powf(lobes.shininess2);
        }
        if let Some(f0) = lobes.fresnel {
            let hv = ((lx * vx + ly * vy + lz * vz + 1.0) / hl).clamp(0.0, 1.0);
            s *= (f0 + (1.0 - f0) * (1.0 - hv).powi(5)) / f0;
        }
        s *= e[i];
        r[i] += s * power[0];
        g[i] += s * power[1];
        b[i] += s * power[2];
    }
}

/// Adds one bounce of light: a spread of hits act as virtual point lights
/// of the radiance they send to the camera, and every hit receives
/// `k * albedo/pi * mean_j L_j cos_i cos_j / (d^2 + eps)`. No visibility: the
/// estimate is for convex objects on a ground, where it matters most.
pub fn one_bounce(
    pk: &Packed,
    diffuse_by_object: &[[f32; 3]],
    k: f32,
    r: &mut [f32],
    g: &mut [f32],
    b: &mut [f32],
) {
    let n = pk.n;
    if n == 0 {
        return;
    }
    let stride = (n / BOUNCE_LIGHTS).max(1);
    let vpl: Vec<usize> = (stride / 2..n)
        .step_by(stride)
        .take(BOUNCE_LIGHTS)
        .collect();
    let src: Vec<[f32; 9]> = vpl
        .iter()
        .map(|&j| {
            [
                pk.px[j], pk.py[j], pk.pz[j], pk.nx[j], pk.ny[j], pk.nz[j], r[j], g[j], b[j],
            ]
        })
        .collect();
    let scale = k / src.len() as f32;
    for grp in &pk.groups {
        let a = diffuse_by_object[grp.object as usize];
        if a == [0.0; 3] {
            continue;
        }
        for i in grp.start..grp.end {
            let (px, py, pz) = (pk.px[i], pk.py[i], pk.pz[i]);
            let (nx, ny, nz) = (pk.nx[i], pk.ny[i], pk.nz[i]);
            let mut acc = [0f32; 3];
            for s in &src {
                let (wx, wy, wz) = (s[0] - px, s[1] - py, s[2] - pz);
                let ci = nx * wx + ny * wy + nz * wz;
                let cj = -(s[3] * wx + s[4] * wy + s[5] * wz);
                if ci <= 0.0 || cj <= 0.0 {
                    continue;
                }
                let d2 = wx * wx + wy * wy + wz * wz;
                let f = ci * cj / (d2 * (d2 + BOUNCE_EPS));
                acc[0] += f * s[6];
                acc[1] += f * s[7];
                acc[2] += f * s[8];
            }
            r[i] += scale * a[0] * acc[0];
            g[i] += scale * a[1] * acc[1];
            b[i] += scale * a[2] * acc[2];
        }
    }
}
