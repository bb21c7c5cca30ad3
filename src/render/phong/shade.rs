//! Shading of the cached ray hits for one candidate: the Phong-Blinn model
//! stated in docs/renderers.md, in linear radiance, then sRGB-encoded.
//!
//! L = kd*c*A + sum over lights (V * E * (kd*c/pi + ks*(n+8)/(8 pi) * max(0, N.H)^n))
//!   + kr * L(reflected) + kt * L(refracted)
//! with E = I*color*cos(theta)/d^2 (point, inverse square), I*color*cos(theta)
//! (point, no falloff) or E*color*cos(theta) (directional); V the hard-shadow
//! visibility.

use super::paths::{Paths, Shadow, Via, NO_PARENT};
use crate::math::V3;
use crate::render::srgb::Encoder;
use crate::scene::{Falloff, LightKind, Scene};
use std::f64::consts::PI;

/// Specular terms below this fraction of their peak are skipped.
const SPEC_CUTOFF: f64 = 1e-5;

struct Mat {
    diffuse: V3,
    ambient: V3,
    spec: f64,
    shininess: f64,
    /// Below this N.H the specular lobe is negligible.
    min_cos: f64,
    reflection: f64,
    transmission: f64,
}

struct Lamp {
    point: bool,
    inverse_square: bool,
    /// Position (point) or unit direction towards the light.
    at: V3,
    power: V3,
}

/// Renders `scene` from its cached `paths` into 8-bit sRGB RGB bytes.
pub fn shade(paths: &Paths, scene: &Scene, enc: &Encoder, out: &mut [u8]) {
    let ambient = V3::from(scene.ambient);
    let mats: Vec<Mat> = scene
        .objects
        .iter()
        .map(|o| {
            let m = &o.material;
            let albedo = V3::from(m.color) * m.diffuse;
            Mat {
                diffuse: albedo / PI,
                ambient: albedo.mul_elem(ambient),
                spec: m.specular * (m.shininess + 8.0) / (8.0 * PI),
                shininess: m.shininess,
                min_cos: SPEC_CUTOFF.powf(1.0 / m.shininess),
                reflection: m.reflection,
                transmission: m.transmission,
            }
        })
        .collect();
    let lamps: Vec<Lamp> = scene
        .lights
        .iter()
        .map(|l| Lamp {
            point: l.kind == LightKind::Point,
            inverse_square: l.falloff == Falloff::InverseSquare,
            at: match l.kind {
                LightKind::Point => V3::from(l.position.unwrap_or_default()),
                LightKind::Directional => V3::from(l.direction.unwrap_or([0.0, 1.0, 0.0])).normalized(),
            },
            power: V3::from(l.color) * l.intensity,
        })
        .collect();
    let nl = lamps.len();
    let npix = (paths.width * paths.height) as usize;
    let mut acc = vec![V3::ZERO; npix];
    let mut weight = vec![0.0f64; paths.verts.len()];
    let sample_weight = 1.0 / paths.samples_per_pixel as f64;
    let g = &paths.geometry;
    for (vi, vert) in paths.verts.iter().enumerate() {
        let w = if vert.parent == NO_PARENT {
            sample_weight
        } else {
            let parent = &paths.verts[vert.parent as usize];
            let pm = &mats[parent.object as usize];
            weight[vert.parent as usize]
                * match vert.via {
                    Via::Reflect => pm.reflection,
                    Via::Transmit => pm.transmission,
                    Via::Camera => 1.0,
                }
        };
        weight[vi] = w;
        if w == 0.0 {
            continue;
        }
        let m = &mats[vert.object as usize];
        let mut l_out = m.ambient;
        let shadows = &paths.shadow[vi * nl..vi * nl + nl];
        for (lamp, shadow) in lamps.iter().zip(shadows) {
            if *shadow == Shadow::Dark {
                continue;
            }
            let (dir, dist, falloff) = if lamp.point {
                let to = lamp.at - vert.p;
                let d2 = to.dot(to);
                let d = d2.sqrt();
                let inv = 1.0 / d;
                (to * inv, d, if lamp.inverse_square { inv * inv } else { 1.0 })
            } else {
                (lamp.at, f64::INFINITY, 1.0)
            };
            let cos = vert.n.dot(dir);
            if cos <= 0.0 {
                continue;
            }
            if let Shadow::Test { start, len } = *shadow {
                let cand = &paths.occluders[start as usize..(start + len) as usize];
                if g.occluded(vert.p + vert.n * 1e-6, dir, dist, cand) {
                    continue;
                }
            }
            let e = cos * falloff;
            let mut brdf = m.diffuse;
            if m.spec > 0.0 {
                let h = (dir + vert.v).normalized();
                let nh = vert.n.dot(h);
                if nh > m.min_cos {
                    let s = m.spec * nh.powf(m.shininess);
                    brdf += V3::new(s, s, s);
                }
            }
            l_out += brdf.mul_elem(lamp.power) * e;
        }
        acc[vert.pixel as usize] += l_out * w;
    }
    // Mirror and glass contributions were added per vertex; encode.
    for (px, c) in acc.iter().enumerate() {
        out[3 * px] = enc.encode(c.x as f32);
        out[3 * px + 1] = enc.encode(c.y as f32);
        out[3 * px + 2] = enc.encode(c.z as f32);
    }
}
