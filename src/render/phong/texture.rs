//! Textures in the object's frame, as the built-in tracer draws them
//! (`scene::texture`, docs/scene-format.md "Textures"): for every hit on
//! a mapped object, its texture coordinates (the shape's parametrisation
//! at the hit carried back into the object's frame, or a mesh triangle's
//! interpolated ones) and the maps' bilinear values there. Shading then
//! multiplies the diffuse and ambient terms by the colour map, the
//! specular terms by the specular map, and evaluates the lobes with the
//! shininess map's exponent (`shade.rs`). A scene without maps builds
//! nothing here, so its render is unchanged.

use super::effects::Lobes;
use super::packed::Packed;
use super::paths::Paths;
use crate::math::V3;
use crate::render::RenderFailure;
use crate::scene::mesh::{self, Mesh};
use crate::scene::texture::{self, uv, MapKind, Texels, TextureRef};
use crate::scene::transform::Affine;
use crate::scene::{Object, Scene, Shape};
use std::f64::consts::PI;
use std::sync::Arc;

/// One object's map of one kind: its texels and settings.
pub(super) struct Map {
    texels: Arc<Texels>,
    scale: [f64; 2],
    range: [f32; 2],
}

impl Map {
    pub(super) fn load(t: &TextureRef, kind: MapKind) -> Result<Map, RenderFailure> {
        let texels = texture::get(std::path::Path::new(t.file()), t.encoding(kind))
            .map_err(|e| RenderFailure::new(format!("phong: {}: {e}", t.file())))?;
        let [lo, hi] = t.range();
        Ok(Map {
            texels,
            scale: t.scale(),
            range: [lo as f32, hi as f32],
        })
    }

    /// The value at texture coordinates `uv`, RGB, after `range`.
    pub(super) fn at(&self, uv: [f64; 2]) -> [f32; 3] {
        let [lo, hi] = self.range;
        let v = self
            .texels
            .sample(uv[0] * self.scale[0], uv[1] * self.scale[1]);
        v.map(|x| lo + x * (hi - lo))
    }
}

/// Per hit (packed order): the maps' values; None where no object has
/// that kind of map. Hits on objects without it hold the neutral value
/// (colour and specular 1; shininess the material's own).
#[derive(Default)]
pub struct HitMaps {
    pub color: Option<Vec<[f32; 3]>>,
    pub specular: Option<Vec<f32>>,
    pub shininess: Option<Vec<f32>>,
    /// Per object: true when it has a shininess map.
    pub shininess_of: Vec<bool>,
}

impl HitMaps {
    /// The maps' values at every hit of `paths`; None when no object of
    /// `scene` has a map (nothing is built).
    pub fn new(
        paths: &Paths,
        packed: &Packed,
        scene: &Scene,
    ) -> Result<Option<HitMaps>, RenderFailure> {
        if !scene.objects.iter().any(|o| o.material.has_maps()) {
            return Ok(None);
        }
        let load = |kind: MapKind| -> Result<Vec<Option<Map>>, RenderFailure> {
            scene
                .objects
                .iter()
                .map(|o| o.material.map(kind).map(|t| Map::load(t, kind)).transpose())
                .collect()
        };
        let (color, spec, shin) = (
            load(MapKind::Color)?,
            load(MapKind::Specular)?,
            load(MapKind::Shininess)?,
        );
        let any = |m: &[Option<Map>]| m.iter().any(Option::is_some);
        let n = packed.n;
        let mut out = HitMaps {
            color: any(&color).then(|| vec![[1.0; 3]; n]),
            specular: any(&spec).then(|| vec![1.0; n]),
            shininess: any(&shin).then(|| {
                let mut v = vec![0.0; n];
                for g in &packed.groups {
                    let s = scene.objects[g.object as usize].material.shininess as f32;
                    v[g.start..g.end].fill(s);
                }
                v
            }),
            shininess_of: shin.iter().map(Option::is_some).collect(),
        };
        let frames: Vec<Option<Frame>> = scene.objects.iter().map(Frame::of).collect();
        let meshes = object_meshes(scene);
        for (vi, vert) in paths.verts.iter().enumerate() {
            let o = vert.object as usize;
            if color[o].is_none() && spec[o].is_none() && shin[o].is_none() {
                continue;
            }
            let Some(uv) = hit_uv(
                &scene.objects[o],
                frames[o].as_ref(),
                meshes[o].as_deref(),
                vert,
            ) else {
                continue;
            };
            let k = packed.packed_of[vi] as usize;
            if let (Some(m), Some(c)) = (&color[o], out.color.as_mut()) {
                c[k] = m.at(uv);
            }
            if let (Some(m), Some(s)) = (&spec[o], out.specular.as_mut()) {
                s[k] = m.at(uv)[0];
            }
            if let (Some(m), Some(s)) = (&shin[o], out.shininess.as_mut()) {
                s[k] = m.at(uv)[0];
            }
        }
        Ok(Some(out))
    }

    /// Multiplies the diffuse and ambient terms (`r`, `g`, `b`, the
    /// specular ones kept apart) by the colour map.
    pub fn apply_color(&self, r: &mut [f32], g: &mut [f32], b: &mut [f32]) {
        let Some(c) = &self.color else { return };
        for (i, c) in c.iter().enumerate() {
            r[i] *= c[0];
            g[i] *= c[1];
            b[i] *= c[2];
        }
    }

    /// Multiplies the specular terms by the specular map.
    pub fn apply_specular(&self, r: &mut [f32], g: &mut [f32], b: &mut [f32]) {
        let Some(s) = &self.specular else { return };
        for (i, &s) in s.iter().enumerate() {
            r[i] *= s;
            g[i] *= s;
            b[i] *= s;
        }
    }

    /// True when the hits of `object` take their exponent from a map.
    pub fn maps_shininess(&self, object: u32) -> bool {
        self.shininess_of
            .get(object as usize)
            .copied()
            .unwrap_or(false)
    }
}

/// Adds one light's specular lobes over `range` with each hit's own
/// exponent from the shininess map (normalised as the scalar is:
/// ks (n + 8) / (8 pi)); a second lobe without its own exponent follows
/// the map too.
#[allow(clippy::too_many_arguments)]
pub fn specular_per_hit(
    packed: &Packed,
    range: std::ops::Range<usize>,
    m: &crate::scene::Material,
    shininess: &[f32],
    (point, at, power): (bool, [f32; 3], [f32; 3]),
    e: &[f32],
    r: &mut [f32],
    g: &mut [f32],
    b: &mut [f32],
) {
    let norm = |k: f64, n: f64| (k * (n + 8.0) / (8.0 * PI)) as f32;
    for i in range {
        if e[i] <= 0.0 {
            continue;
        }
        let n = shininess[i] as f64;
        let n2 = m.shininess2.unwrap_or(n);
        let lobes = Lobes {
            spec: norm(m.specular, n),
            shininess: n as f32,
            spec2: m.specular2.map_or(0.0, |k| norm(k, n2)),
            shininess2: n2 as f32,
            fresnel: m.fresnel.map(|f| f as f32),
        };
        super::effects::specular(packed, i..i + 1, &lobes, point, at, power, e, r, g, b);
    }
}

/// World to object frame of an object with a transform.
pub(super) struct Frame {
    rows: [V3; 3],
    t: V3,
}

impl Frame {
    pub(super) fn of(o: &Object) -> Option<Frame> {
        let a = Affine::new(o.transform.as_ref()?);
        let c = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|e| a.vector(V3::from(e)));
        let det = c[0].dot(c[1].cross(c[2]));
        (det != 0.0 && det.is_finite()).then(|| Frame {
            rows: [
                c[1].cross(c[2]) / det,
                c[2].cross(c[0]) / det,
                c[0].cross(c[1]) / det,
            ],
            t: a.point(V3::new(0.0, 0.0, 0.0)),
        })
    }

    pub(super) fn point(&self, p: V3) -> V3 {
        let q = p - self.t;
        V3::new(
            self.rows[0].dot(q),
            self.rows[1].dot(q),
            self.rows[2].dot(q),
        )
    }
}

/// The texture coordinates of a hit on `object`: a primitive's from the
/// hit point in the object's frame; a mesh's from the triangle and
/// barycentrics the hit was found at.
pub(super) fn hit_uv(
    object: &Object,
    frame: Option<&Frame>,
    mesh: Option<&Mesh>,
    vert: &super::paths::Vertex,
) -> Option<[f64; 2]> {
    let Shape::Mesh { .. } = &object.shape else {
        let p = frame.map_or(vert.p, |f| f.point(vert.p));
        return object.shape.uv(p);
    };
    let at = vert.tri?;
    uv::mesh_uv(mesh?, at.tri as usize, at.u, at.v)
}

/// Each object's mesh (None for a primitive), looked up once per render,
/// not per hit.
pub(super) fn object_meshes(scene: &Scene) -> Vec<Option<Arc<Mesh>>> {
    (scene.objects.iter())
        .map(|o| match &o.shape {
            Shape::Mesh { file } => mesh::get(std::path::Path::new(file)).ok(),
            _ => None,
        })
        .collect()
}
