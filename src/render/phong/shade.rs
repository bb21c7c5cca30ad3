//! Shading of the cached ray hits for one candidate: the Phong-Blinn model
//! stated in docs/renderers.md, in linear radiance, then sRGB-encoded.
//!
//! ```text
//! L = kd*c*A + sum over lights  V * E * (kd*c/pi + ks*(n+8)/(8 pi) * max(0, N.H)^n)
//!   + kr * L(reflected) + kt * L(refracted)
//! ```
//! with E = I*color*cos(theta)/d^2 (point, inverse square), I*color*cos(theta)
//! (point, no falloff) or E*color*cos(theta) (directional), and V the
//! hard-shadow visibility.
//!
//! Optional effects (docs/scene-format.md "Effects"), each off unless its
//! field is present, so the fast path stays as it was: a point light's
//! `falloff_power` p (E ~ 1/d^p), a light's `radius` (soft shadows from
//! several shadow rays, `effects.rs`), the material's `fresnel` F0 (the
//! lobe scaled by Schlick's F(H.V)/F0) and second lobe (`specular2`,
//! `shininess2`), the diffuse term's grazing factor `diffuse_f90`
//! (Burley's), the material's `albedo_map` (the diffuse and ambient
//! terms of a camera ray's first hit times the map at its pixel; what
//! mirrors, glass and the one-bounce estimate see is not mapped), the
//! texture maps in the object's frame (`texture.rs`: the diffuse and
//! ambient terms times `color_map`, the specular ones times
//! `specular_map`, the lobes' exponent from `shininess_map`; the
//! one-bounce estimate sees the scalar colour), and the scene's
//! `indirect_light` (a one-bounce estimate).
//!
//! The per-light pass over all hits is written as plain loops over arrays
//! so that the compiler vectorises it; on CPUs with AVX2 a copy compiled for
//! it is chosen at run time.

use super::geometry::Geometry;
use super::packed::{LightPack, Packed};
use super::paths::{Paths, Via, NO_PARENT};
use super::texture::HitMaps;
use crate::math::V3;
use crate::render::srgb::encode_slice;
use crate::render::RenderFailure;
use crate::scene::albedo_map::{self, AlbedoMap};
use crate::scene::{Falloff, LightKind, Scene};
use std::f64::consts::PI;
use std::sync::Arc;

/// Each object's albedo map, if it has one.
pub type Maps = Vec<Option<Arc<AlbedoMap>>>;

/// The albedo maps of `scene`'s objects (read once per process).
pub fn albedo_maps(scene: &Scene) -> Result<Maps, RenderFailure> {
    scene
        .objects
        .iter()
        .map(|o| match &o.material.albedo_map {
            Some(p) => albedo_map::get(std::path::Path::new(p))
                .map(Some)
                .map_err(|e| RenderFailure::new(format!("phong: {e}"))),
            None => Ok(None),
        })
        .collect()
}

/// Specular terms below this fraction of their peak are skipped.
const SPEC_CUTOFF: f64 = 1e-5;

struct Mat {
    diffuse: [f32; 3],
    ambient: [f32; 3],
    spec: f32,
    shininess: f32,
    /// Below this N.H the specular lobe is negligible.
    min_cos: f32,
    reflection: f64,
    transmission: f64,
    /// Schlick F0, when the specular lobe has Fresnel.
    fresnel: Option<f32>,
    /// The second lobe, normalised like the first, and its exponent.
    spec2: f32,
    shininess2: f32,
    /// Burley's F_D90 of the diffuse term, when not 1.
    f90: Option<f32>,
}

impl Mat {
    /// True when the specular pass needs H.V per hit.
    fn general_specular(&self) -> bool {
        self.fresnel.is_some() || self.spec2 > 0.0
    }
}

/// A light for one candidate.
struct Lamp {
    point: bool,
    inverse_square: bool,
    /// Position (point) or unit direction towards the light.
    at: [f32; 3],
    power: [f32; 3],
    /// Exponent of a point light's distance falloff, when not 2 or 0.
    falloff_power: Option<f32>,
    /// Area light radius (point: metres; directional: angular radius, rad).
    radius: f64,
}

/// Per-thread working arrays, kept between renders: allocating them anew
/// each time costs page faults that showed up as a fifth of a fit's time.
#[derive(Default)]
struct Scratch {
    r: Vec<f32>,
    g: Vec<f32>,
    b: Vec<f32>,
    e: Vec<f32>,
    nh: Vec<f32>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

/// Renders `scene` from its cached hits into 8-bit sRGB RGB bytes.
pub fn shade(
    paths: &Paths,
    packed: &Packed,
    scene: &Scene,
    maps: &Maps,
    tex: Option<&HitMaps>,
    out: &mut [u8],
) {
    SCRATCH.with(|cell| {
        let mut guard = cell.borrow_mut();
        let Scratch { r, g, b, e, nh } = &mut *guard;
        for v in [&mut *r, &mut *g, &mut *b, &mut *e, &mut *nh] {
            v.clear();
            v.resize(packed.n, 0.0);
        }
        shade_into(paths, packed, scene, (maps, tex), out, r, g, b, e, nh);
    })
}

#[allow(clippy::too_many_arguments)]
fn shade_into(
    paths: &Paths,
    packed: &Packed,
    scene: &Scene,
    (maps, tex): (&Maps, Option<&HitMaps>),
    out: &mut [u8],
    r: &mut [f32],
    g: &mut [f32],
    b: &mut [f32],
    e: &mut [f32],
    nh: &mut [f32],
) {
    let mats = materials(scene);
    fill_ambient(packed, &mats, r, g, b);
    // With albedo maps the specular terms are kept apart, so that only the
    // diffuse ones are mapped.
    let n = packed.n;
    let apart = maps.iter().any(Option::is_some) || tex.is_some();
    let mut specular = apart.then(|| (vec![0f32; n], vec![0f32; n], vec![0f32; n]));
    for (l, light) in scene.lights.iter().enumerate() {
        let lamp = lamp(light);
        if lamp.power == [0.0; 3] || cancelled() {
            continue;
        }
        light_visibility(paths, packed, l, &lamp, e, nh);
        if cancelled() {
            return;
        }
        let lit = (&lamp, &*e, &*nh);
        add_light(packed, &mats, lit, (scene, tex), r, g, b, specular.as_mut());
    }
    if let Some((mut sr, mut sg, mut sb)) = specular {
        apply_maps(paths, packed, maps, r, g, b);
        if let Some(t) = tex {
            t.apply_color(r, g, b);
            t.apply_specular(&mut sr, &mut sg, &mut sb);
        }
        for i in 0..n {
            r[i] += sr[i];
            g[i] += sg[i];
            b[i] += sb[i];
        }
    }
    if cancelled() {
        return;
    }
    if let Some(k) = scene.indirect_light.filter(|&k| k > 0.0) {
        let albedo: Vec<[f32; 3]> = mats.iter().map(|m| m.diffuse).collect();
        super::effects::one_bounce(packed, &albedo, k as f32, r, g, b);
    }
    if cancelled() {
        return;
    }
    match &packed.direct_pixel {
        Some(pixel) => encode_direct(packed.n, pixel, r, g, b, out),
        None => encode_paths(paths, packed, &mats, r, g, b, out),
    }
}

/// Whether Ctrl-C was pressed (`exec::cancel`). Checked between the
/// passes over every pixel, each a fraction of a render: a shading cut
/// short leaves the image unfinished, and the render then fails (mod.rs).
#[inline(always)]
fn cancelled() -> bool {
    crate::exec::cancel::is_cancelled()
}

/// Every hit starts from its material's ambient term.
#[inline(always)]
fn fill_ambient(packed: &Packed, mats: &[Mat], r: &mut [f32], g: &mut [f32], b: &mut [f32]) {
    for grp in &packed.groups {
        let a = mats[grp.object as usize].ambient;
        r[grp.start..grp.end].fill(a[0]);
        g[grp.start..grp.end].fill(a[1]);
        b[grp.start..grp.end].fill(a[2]);
    }
}

/// `e` = the light's irradiance factor per hit (shadows and falloff
/// included), `nh` = N.H for the specular lobe.
#[inline(always)]
fn light_visibility(
    paths: &Paths,
    packed: &Packed,
    l: usize,
    lamp: &Lamp,
    e: &mut [f32],
    nh: &mut [f32],
) {
    irradiance(packed, &packed.lights[l], lamp, e, nh);
    if lamp.radius > 0.0 {
        super::effects::soft_shadows(
            packed,
            &paths.geometry,
            lamp.point,
            lamp.at,
            lamp.radius,
            lamp.falloff_power
                .unwrap_or(if lamp.inverse_square { 2.0 } else { 0.0 }),
            e,
        );
    } else {
        complex_shadows(paths, &paths.geometry, l, &packed.lights[l], lamp, e);
        if let Some(p) = lamp.falloff_power {
            super::effects::falloff(packed, lamp.at, p, e);
        }
    }
}

/// Multiplies the diffuse and ambient terms of every camera ray's first
/// hit on a mapped object by the map at the ray's pixel.
fn apply_maps(
    paths: &Paths,
    packed: &Packed,
    maps: &Maps,
    r: &mut [f32],
    g: &mut [f32],
    b: &mut [f32],
) {
    let pixel_of: Vec<u32> = match &packed.direct_pixel {
        Some(p) => p.clone(),
        None => {
            let mut v = vec![NO_PARENT; packed.n];
            for (vi, vert) in paths.verts.iter().enumerate() {
                if vert.parent == NO_PARENT {
                    v[packed.packed_of[vi] as usize] = vert.pixel;
                }
            }
            v
        }
    };
    for grp in &packed.groups {
        let Some(map) = &maps[grp.object as usize] else {
            continue;
        };
        for i in grp.start..grp.end {
            if pixel_of[i] == NO_PARENT {
                continue;
            }
            let a = map.at(pixel_of[i] as usize);
            r[i] *= a[0];
            g[i] *= a[1];
            b[i] *= a[2];
        }
    }
}

/// Adds one light's diffuse and specular contributions, material by
/// material: the specular ones into `apart` when albedo maps keep them
/// apart, else with the diffuse ones. Each value gets its diffuse term
/// before its specular one, as the shading equation adds them.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn add_light(
    packed: &Packed,
    mats: &[Mat],
    (lamp, e, nh): (&Lamp, &[f32], &[f32]),
    (scene, tex): (&Scene, Option<&HitMaps>),
    r: &mut [f32],
    g: &mut [f32],
    b: &mut [f32],
    mut apart: Option<&mut Channels>,
) {
    for grp in &packed.groups {
        let m = &mats[grp.object as usize];
        let range = grp.start..grp.end;
        let k = [
            m.diffuse[0] * lamp.power[0],
            m.diffuse[1] * lamp.power[1],
            m.diffuse[2] * lamp.power[2],
        ];
        if let Some(f90) = m.f90 {
            let (point, at) = (lamp.point, lamp.at);
            super::effects::grazing_diffuse(packed, range.clone(), f90, point, at, k, e, r, g, b);
        } else {
            let at = range.clone();
            let (rr, rg, rb) = (&mut r[at.clone()], &mut g[at.clone()], &mut b[at.clone()]);
            accumulate(&e[at], k, rr, rg, rb);
        }
        let (r, g, b) = match apart.as_deref_mut() {
            Some((sr, sg, sb)) => (&mut sr[..], &mut sg[..], &mut sb[..]),
            None => (&mut *r, &mut *g, &mut *b),
        };
        if let Some(shin) = tex
            .filter(|t| t.maps_shininess(grp.object))
            .and_then(|t| t.shininess.as_deref())
        {
            let mat = &scene.objects[grp.object as usize].material;
            let light = (lamp.point, lamp.at, lamp.power);
            super::texture::specular_per_hit(packed, range, mat, shin, light, e, r, g, b);
        } else if m.general_specular() {
            let lobes = super::effects::Lobes {
                spec: m.spec,
                shininess: m.shininess,
                spec2: m.spec2,
                shininess2: m.shininess2,
                fresnel: m.fresnel,
            };
            let (point, at, power) = (lamp.point, lamp.at, lamp.power);
            super::effects::specular(packed, range, &lobes, point, at, power, e, r, g, b);
        } else if m.spec > 0.0 {
            for i in range {
                if e[i] > 0.0 && nh[i] > m.min_cos {
                    let s = m.spec * nh[i].powf(m.shininess) * e[i];
                    r[i] += s * lamp.power[0];
                    g[i] += s * lamp.power[1];
                    b[i] += s * lamp.power[2];
                }
            }
        }
    }
}

/// Three channels of per-value sums.
type Channels = (Vec<f32>, Vec<f32>, Vec<f32>);

/// One hit per pixel: encode in hit order (vectorised), then place the bytes.
#[inline(always)]
fn encode_direct(n: usize, pixel: &[u32], r: &[f32], g: &[f32], b: &[f32], out: &mut [u8]) {
    let mut codes = vec![0u8; 3 * n];
    let (cr, rest) = codes.split_at_mut(n);
    let (cg, cb) = rest.split_at_mut(n);
    encode_slice(r, cr);
    encode_slice(g, cg);
    encode_slice(b, cb);
    for i in 0..n {
        let px = pixel[i] as usize * 3;
        out[px] = cr[i];
        out[px + 1] = cg[i];
        out[px + 2] = cb[i];
    }
}

/// Mirror and glass paths: weights flow from each hit to the hits its
/// mirror and glass rays made; parents come before children in trace order.
#[inline(always)]
fn encode_paths(
    paths: &Paths,
    packed: &Packed,
    mats: &[Mat],
    r: &[f32],
    g: &[f32],
    b: &[f32],
    out: &mut [u8],
) {
    let npix = (paths.width * paths.height) as usize;
    let mut acc = vec![0f32; 3 * npix];
    let mut weight = vec![0f64; paths.verts.len()];
    let sample_weight = 1.0 / paths.samples_per_pixel as f64;
    for (vi, vert) in paths.verts.iter().enumerate() {
        let w = if vert.parent == NO_PARENT {
            sample_weight
        } else {
            let pm = &mats[paths.verts[vert.parent as usize].object as usize];
            weight[vert.parent as usize]
                * match vert.via {
                    Via::Reflect => pm.reflection,
                    Via::Transmit => pm.transmission,
                    Via::Camera => 1.0,
                }
        };
        weight[vi] = w;
        let k = packed.packed_of[vi] as usize;
        let px = vert.pixel as usize * 3;
        acc[px] += r[k] * w as f32;
        acc[px + 1] += g[k] * w as f32;
        acc[px + 2] += b[k] * w as f32;
    }
    encode_slice(&acc, out);
}

fn materials(scene: &Scene) -> Vec<Mat> {
    let ambient = V3::from(scene.ambient);
    scene
        .objects
        .iter()
        .map(|o| {
            let m = &o.material;
            let albedo = V3::from(m.color) * m.diffuse;
            let d = albedo / PI;
            let a = albedo.mul_elem(ambient);
            Mat {
                diffuse: [d.x as f32, d.y as f32, d.z as f32],
                ambient: [a.x as f32, a.y as f32, a.z as f32],
                spec: (m.specular * (m.shininess + 8.0) / (8.0 * PI)) as f32,
                shininess: m.shininess as f32,
                min_cos: SPEC_CUTOFF.powf(1.0 / m.shininess) as f32,
                reflection: m.reflection,
                transmission: m.transmission,
                fresnel: m.fresnel.map(|f| f as f32),
                spec2: m.specular2.map_or(0.0, |k| {
                    k * (m.shininess2.unwrap_or(m.shininess) + 8.0) / (8.0 * PI)
                }) as f32,
                shininess2: m.shininess2.unwrap_or(m.shininess) as f32,
                f90: m.diffuse_f90.filter(|&f| f != 1.0).map(|f| f as f32),
            }
        })
        .collect()
}

fn lamp(l: &crate::scene::Light) -> Lamp {
    let at = match l.kind {
        LightKind::Point => V3::from(l.position.unwrap_or_default()),
        LightKind::Directional => V3::from(l.direction.unwrap_or([0.0, 1.0, 0.0])).normalized(),
    };
    let p = V3::from(l.color) * l.intensity;
    Lamp {
        point: l.kind == LightKind::Point,
        // An explicit exponent replaces the named falloff: the kernel then
        // runs without falloff and `effects::falloff` applies d^-p.
        inverse_square: l.falloff == Falloff::InverseSquare && l.falloff_power.is_none(),
        at: [at.x as f32, at.y as f32, at.z as f32],
        power: [p.x as f32, p.y as f32, p.z as f32],
        falloff_power: l
            .falloff_power
            .filter(|_| l.kind == LightKind::Point)
            .map(|p| p as f32),
        radius: l.radius,
    }
}

/// For every hit: e = V * cos(theta) * falloff, and N.H for the specular lobe.
fn irradiance(pk: &Packed, lp: &LightPack, lamp: &Lamp, e: &mut [f32], nh: &mut [f32]) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2, checked just above.
            unsafe { irradiance_avx2(pk, lp, lamp, e, nh) };
            return;
        }
    }
    irradiance_kernel(pk, lp, lamp, e, nh);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn irradiance_avx2(pk: &Packed, lp: &LightPack, lamp: &Lamp, e: &mut [f32], nh: &mut [f32]) {
    irradiance_kernel(pk, lp, lamp, e, nh);
}

#[inline(always)]
fn irradiance_kernel(pk: &Packed, lp: &LightPack, lamp: &Lamp, e: &mut [f32], nh: &mut [f32]) {
    let n = pk.n;
    let (px, py, pz) = (&pk.px[..n], &pk.py[..n], &pk.pz[..n]);
    let (nx, ny, nz) = (&pk.nx[..n], &pk.ny[..n], &pk.nz[..n]);
    let (vx, vy, vz) = (&pk.vx[..n], &pk.vy[..n], &pk.vz[..n]);
    let (qx, qy, qz, qc, vis) = (
        &lp.qx[..n],
        &lp.qy[..n],
        &lp.qz[..n],
        &lp.qc[..n],
        &lp.vis[..n],
    );
    let (e, nh) = (&mut e[..n], &mut nh[..n]);
    let [lx, ly, lz] = lamp.at;
    let inverse_square = lamp.inverse_square;
    if lamp.point {
        for i in 0..n {
            let (tx, ty, tz) = (lx - px[i], ly - py[i], lz - pz[i]);
            let d2 = tx * tx + ty * ty + tz * tz;
            let d = d2.sqrt();
            let inv = 1.0 / d;
            let (dx, dy, dz) = (tx * inv, ty * inv, tz * inv);
            let cos = (nx[i] * dx + ny[i] * dy + nz[i] * dz).max(0.0);
            // The sphere blocks when the ray meets it in front of the light.
            let b = qx[i] * dx + qy[i] * dy + qz[i] * dz;
            let disc = b * b - qc[i];
            let blocked = b > 0.0 && disc > 0.0 && b - disc.max(0.0).sqrt() < d;
            let fall = if inverse_square { inv * inv } else { 1.0 };
            e[i] = if blocked { 0.0 } else { cos * fall * vis[i] };
            let (hx, hy, hz) = (dx + vx[i], dy + vy[i], dz + vz[i]);
            let h2 = hx * hx + hy * hy + hz * hz;
            nh[i] = (nx[i] * hx + ny[i] * hy + nz[i] * hz) / h2.sqrt();
        }
    } else {
        let (dx, dy, dz) = (lx, ly, lz);
        for i in 0..n {
            let cos = (nx[i] * dx + ny[i] * dy + nz[i] * dz).max(0.0);
            let b = qx[i] * dx + qy[i] * dy + qz[i] * dz;
            let disc = b * b - qc[i];
            let blocked = b > 0.0 && disc > 0.0;
            e[i] = if blocked { 0.0 } else { cos * vis[i] };
            let (hx, hy, hz) = (dx + vx[i], dy + vy[i], dz + vz[i]);
            let h2 = hx * hx + hy * hy + hz * hz;
            nh[i] = (nx[i] * hx + ny[i] * hy + nz[i] * hz) / h2.sqrt();
        }
    }
}

/// Hits with several possible blockers, or blockers other than spheres:
/// the general shadow-ray test.
fn complex_shadows(
    paths: &Paths,
    geo: &Geometry,
    l: usize,
    lp: &LightPack,
    lamp: &Lamp,
    e: &mut [f32],
) {
    let nl = paths.shadow.len() / paths.verts.len().max(1);
    let at = V3::new(lamp.at[0] as f64, lamp.at[1] as f64, lamp.at[2] as f64);
    for &(k, i) in &lp.complex {
        let k = k as usize;
        if e[k] == 0.0 {
            continue;
        }
        let vert = &paths.verts[i as usize];
        let (dir, dist) = if lamp.point {
            let to = at - vert.p;
            let d = to.length();
            (to * (1.0 / d), d)
        } else {
            (at, f64::INFINITY)
        };
        if let super::paths::Shadow::Test { start, len } = paths.shadow[i as usize * nl + l] {
            let occ = &paths.occluders[start as usize..(start + len) as usize];
            if geo.occluded(vert.p + vert.n * 1e-6, dir, dist, occ) {
                e[k] = 0.0;
            }
        }
    }
}

#[inline(always)]
fn accumulate(e: &[f32], k: [f32; 3], r: &mut [f32], g: &mut [f32], b: &mut [f32]) {
    let n = e.len();
    let (r, g, b) = (&mut r[..n], &mut g[..n], &mut b[..n]);
    for i in 0..n {
        r[i] += e[i] * k[0];
        g[i] += e[i] * k[1];
        b[i] += e[i] * k[2];
    }
}
