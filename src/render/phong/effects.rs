//! The built-in tracer's optional effects, each a separate pass that runs
//! only when its scene field is present (docs/scene-format.md "Effects"),
//! so that scenes without them shade through the fast kernel unchanged:
//! a distance falloff d^-p, soft shadows of an area light, a general
//! specular pass (Schlick Fresnel, a second lobe) and a one-bounce
//! inter-reflection estimate from virtual point lights (Keller, "Instant
//! Radiosity", SIGGRAPH 1997), without visibility.

use super::geometry::{Geometry, Intersect, Prim};
use super::packed::Packed;
use crate::math::V3;

/// Shadow rays per hit towards an area light.
const AREA_SAMPLES: usize = 16;

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
    let disk32 = disk.map(|(x, y)| (x as f32, y as f32));
    let c = V3::new(light[0] as f64, light[1] as f64, light[2] as f64);
    let p_exp = power as f64;
    // d^-p, without a power for the usual exponents.
    let fall = |d: f64| match power {
        0.0 => 1.0,
        2.0 => 1.0 / (d * d),
        _ => d.powf(-p_exp),
    };
    // A directional light's rays are the same for every hit.
    let rays: Vec<V3> = if point {
        Vec::new()
    } else {
        let (a, b) = basis(c);
        disk.iter()
            .map(|&(dx, dy)| (c + (a * dx + b * dy) * radius).normalized())
            .collect()
    };
    // The point light's disk lies in this box: a primitive that cannot
    // block any segment from a hit to it is not tested at that hit.
    let reach = V3::new(radius, radius, radius);
    let (lo, hi) = (c - reach, c + reach);
    let mut near: Vec<u32> = Vec::new();
    for (grp, others) in pk.groups.iter().zip(pk.others(geo)) {
        let blocked = |prims: &[u32], o: V3, w: V3, dist: f64| {
            prims
                .iter()
                .any(|&j| geo.prims[j as usize].hits_before(o, w, dist))
        };
        for (i, ei) in e.iter_mut().enumerate().take(grp.end).skip(grp.start) {
            let (p, n) = (at(pk, i), normal(pk, i));
            let origin = p + n * 1e-6;
            let mut sum = 0.0;
            if point {
                near.clear();
                near.extend(
                    others
                        .iter()
                        .filter(|&&j| may_shadow(geo, j, p, c, radius, (lo, hi))),
                );
                let (a, b) = basis((c - p).normalized());
                if near.is_empty() {
                    let f = |v: V3| [v.x as f32, v.y as f32, v.z as f32];
                    let to_c = f(c - p);
                    sum =
                        unshadowed(to_c, f(n), f(a * radius), f(b * radius), &disk32, power) as f64;
                    *ei = (sum / AREA_SAMPLES as f64) as f32;
                    continue;
                }
                for &(dx, dy) in &disk {
                    let to = c + (a * dx + b * dy) * radius - p;
                    let d = to.length();
                    let w = to * (1.0 / d);
                    let cos = n.dot(w);
                    if cos > 0.0 && !blocked(&near, origin, w, d) {
                        sum += cos * fall(d);
                    }
                }
            } else {
                for &w in &rays {
                    let cos = n.dot(w);
                    if cos > 0.0 && !blocked(others, origin, w, f64::INFINITY) {
                        sum += cos;
                    }
                }
            }
            *ei = (sum / AREA_SAMPLES as f64) as f32;
        }
    }
}

/// Whether primitive `j` could block a segment from `p` to the point
/// light's disk (within `radius` of `c`, inside `bounds`). A sphere is
/// seen from `p` within a cone and the disk within another: it can block
/// only where they overlap. Other primitives: the box test.
fn may_shadow(geo: &Geometry, j: u32, p: V3, c: V3, radius: f64, bounds: (V3, V3)) -> bool {
    let prim = &geo.prims[j as usize];
    let Prim::Sphere { c: centre, r2 } = *prim else {
        return prim.may_block(p, bounds.0, bounds.1);
    };
    let (to_s, to_l) = (centre - p, c - p);
    let (ds2, dl) = (to_s.dot(to_s), to_l.length());
    if ds2 <= r2 || dl <= radius {
        return true;
    }
    let ds = ds2.sqrt();
    let half_s = (r2 / ds2).sqrt().asin();
    let half_l = (radius / dl).asin();
    let between = (to_s.dot(to_l) / (ds * dl)).clamp(-1.0, 1.0).acos();
    between <= half_s + half_l + 1e-6
}

/// The sum over the disk's points q = c + dx a + dy b (offsets from the
/// hit) of cos * d^-p where cos > 0, nothing blocking: the common case,
/// in single precision in a loop the compiler vectorises.
fn unshadowed(
    to_c: [f32; 3],
    n: [f32; 3],
    a: [f32; 3],
    b: [f32; 3],
    disk: &[(f32, f32); AREA_SAMPLES],
    power: f32,
) -> f32 {
    let mut d2 = [0f32; AREA_SAMPLES];
    let mut cos_d = [0f32; AREA_SAMPLES];
    for (k, &(dx, dy)) in disk.iter().enumerate() {
        let t = [0, 1, 2].map(|j| to_c[j] + a[j] * dx + b[j] * dy);
        d2[k] = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
        cos_d[k] = n[0] * t[0] + n[1] * t[1] + n[2] * t[2];
    }
    let mut sum = 0f32;
    for k in 0..AREA_SAMPLES {
        let inv = 1.0 / d2[k].sqrt();
        let fall = match power {
            0.0 => 1.0,
            2.0 => inv * inv,
            _ => d2[k].powf(-0.5 * power),
        };
        sum += if cos_d[k] > 0.0 {
            cos_d[k] * inv * fall
        } else {
            0.0
        };
    }
    sum
}

/// The unit vector from hit `i` towards a light at `light` (a point light)
/// or along `light` (a directional one, already unit).
#[inline(always)]
fn to_light(pk: &Packed, i: usize, point: bool, light: [f32; 3]) -> (f32, f32, f32) {
    if !point {
        return (light[0], light[1], light[2]);
    }
    let (tx, ty, tz) = (
        light[0] - pk.px[i],
        light[1] - pk.py[i],
        light[2] - pk.pz[i],
    );
    let inv = 1.0 / (tx * tx + ty * ty + tz * tz).sqrt();
    (tx * inv, ty * inv, tz * inv)
}

/// Adds one light's diffuse term over `range` with Burley's grazing factor
/// (Physically Based Shading at Disney, 2012; F_D90 held constant): `k` ×
/// E × (1 + (f90 − 1)(1 − N.L)⁵)(1 + (f90 − 1)(1 − N.V)⁵). The factor is 1
/// at normal incidence, so `color` keeps its meaning; below 1 towards the
/// terminator and the silhouette a smooth dielectric's diffuse fades (the
/// light crosses its surface twice), above 1 a rough surface's brightens.
#[allow(clippy::too_many_arguments)]
pub fn grazing_diffuse(
    pk: &Packed,
    range: std::ops::Range<usize>,
    f90: f32,
    point: bool,
    light: [f32; 3],
    k: [f32; 3],
    e: &[f32],
    r: &mut [f32],
    g: &mut [f32],
    b: &mut [f32],
) {
    let grazing = |c: f32| 1.0 + (f90 - 1.0) * (1.0 - c.clamp(0.0, 1.0)).powi(5);
    for i in range {
        if e[i] <= 0.0 {
            continue;
        }
        let (lx, ly, lz) = to_light(pk, i, point, light);
        let (nx, ny, nz) = (pk.nx[i], pk.ny[i], pk.nz[i]);
        let nl = nx * lx + ny * ly + nz * lz;
        let nv = nx * pk.vx[i] + ny * pk.vy[i] + nz * pk.vz[i];
        let d = e[i] * grazing(nl) * grazing(nv);
        r[i] += d * k[0];
        g[i] += d * k[1];
        b[i] += d * k[2];
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
        let (lx, ly, lz) = to_light(pk, i, point, light);
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
    if pk.n == 0 {
        return;
    }
    let kernel = pk.bounce();
    let src: Vec<[f32; 3]> = kernel.vpl.iter().map(|&j| [r[j], g[j], b[j]]).collect();
    let scale = k / src.len() as f32;
    for grp in &pk.groups {
        let a = diffuse_by_object[grp.object as usize];
        if a == [0.0; 3] {
            continue;
        }
        for i in grp.start..grp.end {
            let seen = &kernel.terms[kernel.offsets[i] as usize..kernel.offsets[i + 1] as usize];
            let mut acc = [0f32; 3];
            for &(s, f) in seen {
                let c = src[s as usize];
                acc[0] += f * c[0];
                acc[1] += f * c[1];
                acc[2] += f * c[2];
            }
            r[i] += scale * a[0] * acc[0];
            g[i] += scale * a[1] * acc[1];
            b[i] += scale * a[2] * acc[2];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::paths::{Paths, Variation};
    use super::*;
    use crate::scene::ParamSpace;

    /// Every shadow ray of every hit against every other object's
    /// primitives, in double precision: what `soft_shadows` must equal.
    fn reference(pk: &Packed, geo: &Geometry, point: bool, c: V3, radius: f64) -> Vec<f32> {
        let disk = disk();
        let mut e = vec![0f32; pk.n];
        for grp in &pk.groups {
            for (i, ei) in e.iter_mut().enumerate().take(grp.end).skip(grp.start) {
                let (p, n) = (at(pk, i), normal(pk, i));
                let (a, b) = basis(if point { (c - p).normalized() } else { c });
                let mut sum = 0.0;
                for &(dx, dy) in &disk {
                    let q = c + (a * dx + b * dy) * radius;
                    let (w, dist) = if point {
                        ((q - p).normalized(), (q - p).length())
                    } else {
                        (q.normalized(), f64::INFINITY)
                    };
                    let blocked = (0..geo.prims.len()).any(|j| {
                        geo.may_shadow(j, grp.object)
                            && geo.prims[j].hits_before(p + n * 1e-6, w, dist)
                    });
                    if n.dot(w) > 0.0 && !blocked {
                        let fall = if point { dist.powi(-2) } else { 1.0 };
                        sum += n.dot(w) * fall;
                    }
                }
                *ei = (sum / AREA_SAMPLES as f64) as f32;
            }
        }
        e
    }

    #[test]
    fn soft_shadows_equal_every_ray_traced() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/sphere_floor.json");
        let mut scene = crate::scene::load(std::path::Path::new(path)).unwrap();
        scene.image.width = 48;
        scene.image.height = 36;
        let paths = Paths::build(
            &scene,
            &Variation::new(&scene, &ParamSpace::default()),
            true,
        );
        let pk = Packed::new(&paths, scene.lights.len());
        // A light over the ball (its shadow on the floor), one low beside
        // it (a long shadow), and a sun; small and large disks.
        let lights = [
            (true, [0.3f32, 3.0, 0.5]),
            (true, [2.5, 0.8, 0.4]),
            (false, [0.4, 0.8, 0.3]),
        ];
        for (point, at) in lights {
            let c = V3::new(at[0] as f64, at[1] as f64, at[2] as f64);
            let c = if point { c } else { c.normalized() };
            let light = [c.x as f32, c.y as f32, c.z as f32];
            for radius in [0.05, 0.6] {
                let mut e = vec![1f32; pk.n];
                soft_shadows(&pk, &paths.geometry, point, light, radius, 2.0, &mut e);
                let want = reference(&pk, &paths.geometry, point, c, radius);
                let shadowed = want.iter().filter(|&&x| x == 0.0).count();
                assert!(shadowed > 0, "the case casts no shadow");
                for (i, (got, want)) in e.iter().zip(&want).enumerate() {
                    assert!(
                        (got - want).abs() <= 1e-4 * want.abs().max(1e-3),
                        "light {at:?} radius {radius} hit {i}: {got} against {want}"
                    );
                }
            }
        }
    }
}
