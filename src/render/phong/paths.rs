//! The part of a render that does not change between candidates: where
//! camera rays hit (and, through mirrors and glass, where their reflected and
//! refracted rays hit), and for each hit and light which surfaces could cast
//! a shadow on it. Built once per run when only lights and materials are
//! free; built per candidate when a free parameter moves geometry.

use super::camera::CameraRays;
use super::geometry::{Geometry, Hit, Intersect, Occluder, TriPoint, EPS};
use crate::math::V3;
use crate::scene::field::{LightField, MaterialField};
use crate::scene::{Field, LightKind, ParamSpace, Scene};
use rayon::prelude::*;

pub const NO_PARENT: u32 = u32::MAX;

/// How a vertex was reached from its parent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Via {
    Camera,
    Reflect,
    Transmit,
}

/// One surface point seen by a camera ray or a ray it spawned.
#[derive(Clone, Copy, Debug)]
pub struct Vertex {
    pub pixel: u32,
    pub object: u32,
    pub parent: u32,
    pub via: Via,
    pub p: V3,
    /// Unit normal, turned towards the incoming ray.
    pub n: V3,
    /// Unit direction back along the incoming ray.
    pub v: V3,
    /// On a mesh: the triangle and barycentrics hit.
    pub tri: Option<TriPoint>,
}

/// Shadowing of one vertex by one light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shadow {
    /// Nothing can block it.
    Lit,
    /// Always blocked (a light that does not move).
    Dark,
    /// Test these primitives: `occluders[start..start+len]`.
    Test { start: u32, len: u32 },
}

/// Everything a candidate's shading needs besides its lights and materials.
pub struct Paths {
    pub width: u32,
    pub height: u32,
    pub samples_per_pixel: u32,
    pub verts: Vec<Vertex>,
    /// `verts.len() * lights` entries, vertex-major.
    pub shadow: Vec<Shadow>,
    pub occluders: Vec<Occluder>,
    pub geometry: Geometry,
    /// The rays traced to build these paths.
    pub rays: Rays,
}

/// Rays traced while the paths were built, counted as a tracer without
/// shortcuts would cast them: camera rays, the reflected and refracted
/// rays they spawn, and one shadow ray per hit and fixed light that faces
/// the hit (however it was answered: a sphere test, a hull face, a walk).
/// Shadow rays towards a moving light are cast when a candidate is shaded
/// and are not counted here.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Rays {
    pub camera: u64,
    pub secondary: u64,
    pub shadow: u64,
}

impl Rays {
    fn add(&mut self, o: Rays) {
        self.camera += o.camera;
        self.secondary += o.secondary;
        self.shadow += o.shadow;
    }
}

/// What may change about each light between candidates.
#[derive(Clone, Copy, Debug)]
enum LightRange {
    Fixed,
    /// Position anywhere in the box [lo, hi].
    Moving(V3, V3),
    /// Direction free: anything may block it.
    Turning,
}

/// What may vary about the scene, from the free parameters.
pub struct Variation {
    lights: Vec<LightRange>,
    /// Objects whose reflection or transmission may become non-zero.
    reflective: Vec<bool>,
    transmissive: Vec<bool>,
}

impl Variation {
    pub fn new(scene: &Scene, space: &ParamSpace) -> Variation {
        let mut lights = vec![LightRange::Fixed; scene.lights.len()];
        let mut reflective: Vec<bool> = scene
            .objects
            .iter()
            .map(|o| o.material.reflection > 0.0)
            .collect();
        let mut transmissive: Vec<bool> = scene
            .objects
            .iter()
            .map(|o| o.material.transmission > 0.0)
            .collect();
        for s in &space.specs {
            match s.field {
                Field::Light(i, LightField::Position) => {
                    lights[i] = LightRange::Moving(
                        V3::new(s.min[0], s.min[1], s.min[2]),
                        V3::new(s.max[0], s.max[1], s.max[2]),
                    )
                }
                Field::Light(i, LightField::Direction | LightField::Distance) => {
                    lights[i] = LightRange::Turning
                }
                Field::Material(i, MaterialField::Reflection) => reflective[i] |= s.max[0] > 0.0,
                Field::Material(i, MaterialField::Transmission) => {
                    transmissive[i] |= s.max[0] > 0.0
                }
                _ => {}
            }
        }
        Variation {
            lights,
            reflective,
            transmissive,
        }
    }
}

impl Paths {
    /// Traces the camera rays of `scene`: rows in parallel when `parallel`
    /// (the one build of a session), in one sequence otherwise (a build per
    /// candidate, whose batch already fills the threads).
    pub fn build(scene: &Scene, var: &Variation, parallel: bool) -> Paths {
        let geometry = Geometry::new(scene);
        let cam = CameraRays::new(&scene.camera, scene.image);
        // Most camera rays of a small object miss it: test each primitive
        // only inside the rectangle its image lies in.
        let rects = geometry.screen_rects(&cam);
        let (w, h) = (scene.image.width, scene.image.height);
        let aa = scene.render.antialias.max(1);
        let trace_rows = |rows: std::ops::Range<u32>| {
            let mut t = Tracer {
                scene,
                geometry: &geometry,
                var,
                verts: Vec::new(),
                shadow: Vec::new(),
                occluders: Vec::new(),
                budget: 0,
                rays: Rays::default(),
            };
            // cut short on Ctrl-C: every render then fails (mod.rs)
            for y in rows.take_while(|_| !crate::exec::cancel::is_cancelled()) {
                for x in Geometry::row_span(&rects, y as f64, (y + 1) as f64, w) {
                    for sy in 0..aa {
                        for sx in 0..aa {
                            let fx = x as f64 + (sx as f64 + 0.5) / aa as f64;
                            let fy = y as f64 + (sy as f64 + 0.5) / aa as f64;
                            let (o, d) = cam.ray(fx, fy);
                            t.rays.camera += 1;
                            let Some(hit) = geometry.intersect_camera_ray(o, d, (fx, fy), &rects)
                            else {
                                continue;
                            };
                            t.budget = MAX_VERTICES_PER_RAY;
                            t.record(y * w + x, o, d, hit, NO_PARENT, Via::Camera, 0);
                        }
                    }
                }
            }
            (t.verts, t.shadow, t.occluders, t.rays)
        };
        let parts: Vec<Part> = if parallel {
            (0..h)
                .into_par_iter()
                .map(|y| trace_rows(y..y + 1))
                .collect()
        } else {
            vec![trace_rows(0..h)]
        };
        let mut paths = Paths {
            width: w,
            height: h,
            samples_per_pixel: aa * aa,
            verts: Vec::new(),
            shadow: Vec::new(),
            occluders: Vec::new(),
            geometry,
            rays: Rays::default(),
        };
        paths.join(parts);
        paths
    }
}

impl Paths {
    /// Appends the rows traced apart, in order, renumbering the links
    /// between them. Cut short on Ctrl-C: on a large image the joining
    /// and the packing after it take seconds, and what is left of a
    /// cancelled build is never drawn (mod.rs), so it is left empty.
    fn join(&mut self, parts: Vec<Part>) {
        let cancelled = crate::exec::cancel::is_cancelled;
        for (verts, shadow, occluders, rays) in parts {
            self.rays.add(rays);
            if cancelled() {
                self.verts.clear();
                self.shadow.clear();
                self.occluders.clear();
                return;
            }
            let base_v = self.verts.len() as u32;
            let base_o = self.occluders.len() as u32;
            self.verts.extend(verts.into_iter().map(|mut v| {
                if v.parent != NO_PARENT {
                    v.parent += base_v;
                }
                v
            }));
            self.shadow.extend(shadow.into_iter().map(|s| match s {
                Shadow::Test { start, len } => Shadow::Test {
                    start: start + base_o,
                    len,
                },
                other => other,
            }));
            self.occluders.extend(occluders);
        }
    }
}

/// What a run of rows traced: hits, their shadowing, occluders, rays.
type Part = (Vec<Vertex>, Vec<Shadow>, Vec<Occluder>, Rays);

struct Tracer<'a> {
    scene: &'a Scene,
    geometry: &'a Geometry,
    var: &'a Variation,
    verts: Vec<Vertex>,
    shadow: Vec<Shadow>,
    occluders: Vec<Occluder>,
    /// Hits the current camera ray may still add.
    budget: u32,
    rays: Rays,
}

/// Hits one camera ray's tree may hold. An object that both reflects and
/// transmits doubles the rays at each bounce: 2^max_depth hits unbounded.
/// 256 holds the full tree of the default depth 5 (63) and a single mirror
/// chain of the largest depth, 64.
const MAX_VERTICES_PER_RAY: u32 = 256;

impl Tracer<'_> {
    fn trace(&mut self, pixel: u32, o: V3, d: V3, parent: u32, via: Via, depth: u32) {
        self.rays.secondary += 1;
        if let Some(hit) = self.geometry.intersect(o, d, f64::INFINITY) {
            self.record(pixel, o, d, hit, parent, via, depth);
        }
    }

    /// Keeps `hit` of the ray from `o` along `d`, and traces the rays it spawns.
    #[allow(clippy::too_many_arguments)]
    fn record(&mut self, pixel: u32, o: V3, d: V3, hit: Hit, parent: u32, via: Via, depth: u32) {
        let p = o + d * hit.t;
        let entering = hit.n.dot(d) < 0.0;
        let n = if entering { hit.n } else { -hit.n };
        let face = if hit.face.dot(d) < 0.0 {
            hit.face
        } else {
            -hit.face
        };
        let index = self.verts.len() as u32;
        self.verts.push(Vertex {
            pixel,
            object: hit.object,
            parent,
            via,
            p,
            n,
            v: -d,
            tri: hit.tri,
        });
        for l in 0..self.scene.lights.len() {
            let s = self.classify(p, n, face, (hit.object, hit.tri), l);
            self.shadow.push(s);
        }
        self.budget = self.budget.saturating_sub(1);
        if depth >= self.scene.render.max_depth || self.budget == 0 {
            return;
        }
        let obj = hit.object as usize;
        let cos_i = -n.dot(d);
        let reflected = d + n * (2.0 * cos_i);
        if self.var.reflective[obj] {
            self.trace(
                pixel,
                p + n * EPS * 10.0,
                reflected,
                index,
                Via::Reflect,
                depth + 1,
            );
        }
        if self.var.transmissive[obj] {
            let ior = self.scene.objects[obj].material.ior;
            let eta = if entering { 1.0 / ior } else { ior };
            let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
            let (dir, start) = if k < 0.0 {
                (reflected, p + n * EPS * 10.0) // total internal reflection
            } else {
                (d * eta + n * (eta * cos_i - k.sqrt()), p - n * EPS * 10.0)
            };
            self.trace(
                pixel,
                start,
                dir.normalized(),
                index,
                Via::Transmit,
                depth + 1,
            );
        }
    }

    /// Which primitives could shadow point `p` (normal `n`, face normal
    /// `face`, on `object`, at mesh triangle `tri` if any) from light `l`.
    fn classify(
        &mut self,
        p: V3,
        n: V3,
        face: V3,
        (object, tri): (u32, Option<TriPoint>),
        l: usize,
    ) -> Shadow {
        let light = &self.scene.lights[l];
        let g = self.geometry;
        let others = |i: &usize| g.may_shadow(*i, object);
        let fixed = match (light.kind, self.var.lights[l]) {
            (LightKind::Point, LightRange::Fixed) => {
                let to = V3::from(light.position.unwrap_or_default()) - p;
                let dist = to.length();
                Some((to / dist, dist))
            }
            (LightKind::Directional, LightRange::Fixed) => Some((
                V3::from(light.direction.unwrap_or([0.0, 1.0, 0.0])).normalized(),
                f64::INFINITY,
            )),
            _ => None,
        };
        if let Some((d, dist)) = fixed {
            // A light that does not move: decide once.
            let o = p + n * EPS * 10.0;
            let faces = n.dot(d) > 0.0;
            self.rays.shadow += faces as u64;
            let lit = faces && !g.blocked_by_others(o, d, dist, object, tri);
            return if lit { Shadow::Lit } else { Shadow::Dark };
        }
        let bounds = match self.var.lights[l] {
            LightRange::Moving(lo, hi) => Some((lo, hi)),
            _ => None,
        };
        let start = self.occluders.len() as u32;
        self.occluders.extend(
            (0..g.prims.len())
                .filter(others)
                .filter(|&i| bounds.is_none_or(|(lo, hi)| g.prims[i].may_block(p, lo, hi)))
                .map(|i| g.occluder(i as u32, p, face)),
        );
        let len = self.occluders.len() as u32 - start;
        if len == 0 {
            Shadow::Lit
        } else {
            Shadow::Test { start, len }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pruning that keeps shading fast: in the paper's box, with both
    /// lights free to move anywhere in their bounds, no hit has more than
    /// one surface that could shadow it.
    #[test]
    fn at_most_one_possible_occluder_per_hit_in_the_paper_box() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper_box.json");
        let scene = crate::scene::load(&path).unwrap();
        let space = ParamSpace::from_scene(&scene);
        let paths = Paths::build(&scene, &Variation::new(&scene, &space), true);
        let mut tested = 0;
        for s in &paths.shadow {
            if let Shadow::Test { len, .. } = s {
                assert_eq!(*len, 1);
                tested += 1;
            }
        }
        assert!(
            tested > paths.verts.len() / 2,
            "the sphere can shadow much of the box: {tested}"
        );
    }

    fn example(file: &str) -> Scene {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes")
            .join(file);
        crate::scene::load(&path).unwrap()
    }

    /// Testing each primitive only inside its image's rectangle finds the
    /// same first hit for every camera ray as testing them all: spheres,
    /// a floor plane, a box's quads, perspective and orthographic cameras,
    /// and a sphere the pinhole sits beside (its bounding cube partly
    /// behind the camera, so it is never ruled out).
    #[test]
    fn culled_camera_rays_hit_what_every_primitive_would() {
        let mut beside = example("sphere_floor.json");
        let cam = V3::from(beside.camera.eye());
        let c = cam + V3::new(0.6, 0.0, 0.0);
        beside.objects[0]
            .shape
            .field_mut("center")
            .unwrap()
            .copy_from_slice(&[c.x, c.y, c.z]);
        for scene in [
            example("sphere_floor.json"),
            example("paper_box.json"),
            example("diligent_ball.json"),
            beside,
        ] {
            let geometry = Geometry::new(&scene);
            let cam = CameraRays::new(&scene.camera, scene.image);
            let rects = geometry.screen_rects(&cam);
            let (w, h) = (scene.image.width, scene.image.height);
            let mut hits = 0;
            for y in 0..h {
                let span = Geometry::row_span(&rects, y as f64, (y + 1) as f64, w);
                for x in 0..w {
                    let at = (x as f64 + 0.5, y as f64 + 0.5);
                    let (o, d) = cam.ray(at.0, at.1);
                    let all = geometry.intersect(o, d, f64::INFINITY);
                    let culled = geometry.intersect_camera_ray(o, d, at, &rects);
                    assert_eq!(
                        all.map(|h| (h.t, h.object)),
                        culled.map(|h| (h.t, h.object))
                    );
                    assert!(
                        all.is_none() || span.contains(&x),
                        "pixel ({x}, {y}) outside its row's span"
                    );
                    hits += all.is_some() as usize;
                }
            }
            assert!(hits > 0);
        }
    }

    /// The rays counted are the rays cast: in a scene with a floor (every
    /// pixel's ray meets something) and fixed lights, one camera ray per
    /// pixel and sample, and one shadow ray per hit and light facing it;
    /// in the same order or in parallel rows alike.
    #[test]
    fn the_rays_counted_are_the_rays_cast() {
        let mut scene = example("sphere_floor.json");
        scene.render.antialias = 2;
        let var = Variation::new(&scene, &ParamSpace::default());
        let paths = Paths::build(&scene, &var, false);
        let (w, h) = (scene.image.width as u64, scene.image.height as u64);
        assert_eq!(paths.rays.camera, w * h * 4);
        let facing: usize = paths
            .verts
            .iter()
            .map(|v| {
                let facing = |l: &crate::scene::Light| match l.kind {
                    LightKind::Point => (V3::from(l.position.unwrap()) - v.p).dot(v.n) > 0.0,
                    LightKind::Directional => V3::from(l.direction.unwrap()).dot(v.n) > 0.0,
                };
                scene.lights.iter().filter(|l| facing(l)).count()
            })
            .sum();
        assert!(facing > 0);
        assert_eq!(paths.rays.shadow, facing as u64);
        assert_eq!(paths.rays, Paths::build(&scene, &var, true).rays);
    }

    /// The sequential build (one per candidate) and the parallel one (once
    /// per session) hold the same hits in the same order.
    #[test]
    fn sequential_and_parallel_builds_agree() {
        let scene = example("paper_box.json");
        let var = Variation::new(&scene, &ParamSpace::from_scene(&scene));
        let (a, b) = (
            Paths::build(&scene, &var, true),
            Paths::build(&scene, &var, false),
        );
        assert_eq!(a.verts.len(), b.verts.len());
        for (u, v) in a.verts.iter().zip(&b.verts) {
            assert_eq!(
                (u.pixel, u.object, u.parent, u.p.x, u.n.y),
                (v.pixel, v.object, v.parent, v.p.x, v.n.y)
            );
        }
        assert_eq!(a.shadow, b.shadow);
    }
}
