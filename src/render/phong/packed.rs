//! The cached ray hits laid out for fast shading: structure of arrays in
//! `f32`, grouped by object so that a material is constant over a run of
//! hits, with each hit's shadow test against its one possible blocking
//! sphere reduced to four numbers. What does not fit that form (several
//! possible blockers, quads, turning lights) stays on a short list tested
//! the general way.

use super::bounce::Bounce;
use super::geometry::Occluder;
use super::paths::{Paths, Shadow, Vertex, NO_PARENT};

/// A run of hits on one object.
pub struct Group {
    pub object: u32,
    pub start: usize,
    pub end: usize,
}

/// Shadowing of every hit by one light.
pub struct LightPack {
    /// Fixed visibility: 1 lit, 0 always dark.
    pub vis: Vec<f32>,
    /// The blocking sphere as seen from the hit: q = centre - hit, and
    /// qc = |q|^2 - r^2 (+inf: nothing to test).
    pub qx: Vec<f32>,
    pub qy: Vec<f32>,
    pub qz: Vec<f32>,
    pub qc: Vec<f32>,
    /// (packed index, trace index) of hits tested the general way.
    pub complex: Vec<(u32, u32)>,
}

impl LightPack {
    /// The shadowing by light `l` of the hits in packed `order`.
    fn of(paths: &Paths, order: &[u32], lights: usize, l: usize) -> LightPack {
        let n = order.len();
        let mut p = LightPack {
            vis: vec![1.0; n],
            qx: vec![0.0; n],
            qy: vec![0.0; n],
            qz: vec![0.0; n],
            qc: vec![f32::INFINITY; n],
            complex: Vec::new(),
        };
        for (k, &i) in order.iter().enumerate() {
            match paths.shadow[i as usize * lights + l] {
                Shadow::Lit => {}
                Shadow::Dark => p.vis[k] = 0.0,
                Shadow::Test { start, len } => {
                    let occ = &paths.occluders[start as usize..(start + len) as usize];
                    match occ {
                        [Occluder::Cone {
                            axis,
                            cos_max,
                            center_dist,
                            ..
                        }] => {
                            let q = *axis * *center_dist;
                            p.qx[k] = q.x as f32;
                            p.qy[k] = q.y as f32;
                            p.qz[k] = q.z as f32;
                            p.qc[k] = (center_dist * center_dist * cos_max * cos_max) as f32;
                        }
                        _ => p.complex.push((k as u32, i)),
                    }
                }
            }
        }
        p
    }
}

pub struct Packed {
    pub n: usize,
    pub groups: Vec<Group>,
    /// Packed index of each trace-order vertex.
    pub packed_of: Vec<u32>,
    pub px: Vec<f32>,
    pub py: Vec<f32>,
    pub pz: Vec<f32>,
    pub nx: Vec<f32>,
    pub ny: Vec<f32>,
    pub nz: Vec<f32>,
    pub vx: Vec<f32>,
    pub vy: Vec<f32>,
    pub vz: Vec<f32>,
    pub lights: Vec<LightPack>,
    /// When every hit is a camera hit and pixels have one sample: the pixel
    /// of each packed hit (no weights to propagate).
    pub direct_pixel: Option<Vec<u32>>,
    /// The one-bounce kernel, built on first use (`effects.rs`).
    bounce: std::sync::OnceLock<Bounce>,
    /// For each group, the primitives of other objects (which alone can
    /// shadow a convex object's hits), built on first use.
    others: std::sync::OnceLock<Vec<Vec<u32>>>,
}

impl Packed {
    ///
    /// On Ctrl-C it stops between passes and returns no hits at all: on a
    /// large image packing takes seconds, and a cancelled render is never
    /// shaded (mod.rs).
    pub fn new(paths: &Paths, lights: usize) -> Packed {
        let all = paths.verts.len();
        Packed::pack(paths, lights, all, crate::exec::cancel::is_cancelled)
            .or_else(|| Packed::pack(paths, lights, 0, || false))
            .expect("an empty packing is never cut short")
    }

    /// Packs the first `n` hits of `paths`; None once `cancelled` says so.
    fn pack(paths: &Paths, lights: usize, n: usize, cancelled: fn() -> bool) -> Option<Packed> {
        let mut order: Vec<u32> = (0..n as u32).collect();
        order.sort_by_key(|&i| paths.verts[i as usize].object); // stable: keeps trace order within an object
        if cancelled() {
            return None;
        }
        let mut packed_of = vec![0u32; n];
        for (k, &i) in order.iter().enumerate() {
            packed_of[i as usize] = k as u32;
        }
        let mut groups: Vec<Group> = Vec::new();
        for (k, &i) in order.iter().enumerate() {
            let obj = paths.verts[i as usize].object;
            match groups.last_mut() {
                Some(g) if g.object == obj => g.end = k + 1,
                _ => groups.push(Group {
                    object: obj,
                    start: k,
                    end: k + 1,
                }),
            }
        }
        let v = &paths.verts;
        let mut packs = Vec::with_capacity(lights);
        for l in 0..lights {
            if cancelled() {
                return None;
            }
            packs.push(LightPack::of(paths, &order, lights, l));
        }
        let direct = paths.samples_per_pixel == 1 && v.iter().all(|x| x.parent == NO_PARENT);
        let coords: [fn(&Vertex) -> f64; 9] = [
            |x| x.p.x,
            |x| x.p.y,
            |x| x.p.z,
            |x| x.n.x,
            |x| x.n.y,
            |x| x.n.z,
            |x| x.v.x,
            |x| x.v.y,
            |x| x.v.z,
        ];
        let mut cols = Vec::with_capacity(coords.len());
        for f in coords {
            if cancelled() {
                return None;
            }
            cols.push(order.iter().map(|&i| f(&v[i as usize]) as f32).collect());
        }
        let [px, py, pz, nx, ny, nz, vx, vy, vz]: [Vec<f32>; 9] =
            cols.try_into().expect("one column per coordinate");
        Some(Packed {
            n,
            groups,
            bounce: std::sync::OnceLock::new(),
            others: std::sync::OnceLock::new(),
            px,
            py,
            pz,
            nx,
            ny,
            nz,
            vx,
            vy,
            vz,
            direct_pixel: direct.then(|| order.iter().map(|&i| v[i as usize].pixel).collect()),
            packed_of,
            lights: packs,
        })
    }

    /// The one-bounce kernel of these hits.
    pub fn bounce(&self) -> &Bounce {
        self.bounce.get_or_init(|| {
            Bounce::new(
                [&self.px, &self.py, &self.pz],
                [&self.nx, &self.ny, &self.nz],
            )
        })
    }

    /// For each group, the primitives of `geo` that may shadow its object:
    /// those of other objects, and its own if it is a mesh (not convex).
    pub fn others(&self, geo: &super::geometry::Geometry) -> &[Vec<u32>] {
        self.others.get_or_init(|| {
            self.groups
                .iter()
                .map(|g| {
                    (0..geo.prims.len() as u32)
                        .filter(|&i| geo.may_shadow(i as usize, g.object))
                        .collect()
                })
                .collect()
        })
    }
}
