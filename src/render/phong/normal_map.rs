//! Normal maps (`material.normal_map`) as the built-in tracer draws them:
//! a tangent-space map in the OpenGL convention (+Y up: green grows
//! along dP/dv), its linear RGB in [0, 1] read as a vector in [-1, 1]^3,
//! renormalised, and turned into the world by the surface's tangent
//! frame at the hit (`scene::texture::tangent`, carried through the
//! object's `transform`): T = dP/du made perpendicular to the shading
//! normal N, B = N x T (the other way where the coordinates are
//! mirrored). A frame with no dP/du (a degenerate triangle, a sphere's
//! pole) falls back to the plane axes of N, never NaN.
//!
//! The perturbed normal replaces the packed (shading) normal only: the
//! traced paths, shadow rays and which side of the surface a hit is on
//! keep the geometric one. Seen from its back, the surface's perturbed
//! normal is turned round as a whole (as Cycles does).

use super::packed::Packed;
use super::paths::{Paths, Vertex};
use super::texture::{hit_uv, Frame, Map};
use crate::math::V3;
use crate::render::RenderFailure;
use crate::scene::mesh::{self, Mesh};
use crate::scene::texture::tangent::{self, Tangents};
use crate::scene::texture::{uv::plane_axes, MapKind};
use crate::scene::transform::Affine;
use crate::scene::{Object, Scene, Shape};
use std::sync::Arc;

/// What one normal-mapped object needs per hit.
struct Mapped {
    map: Map,
    frame: Option<Frame>,
    affine: Option<Affine>,
    mesh: Option<Arc<Mesh>>,
}

impl Mapped {
    fn of(o: &Object) -> Result<Option<Mapped>, RenderFailure> {
        let Some(t) = o.material.map(MapKind::Normal) else {
            return Ok(None);
        };
        let mesh = match &o.shape {
            Shape::Mesh { file } => Some(
                mesh::get(std::path::Path::new(file))
                    .map_err(|e| RenderFailure::new(format!("phong: {e}")))?,
            ),
            _ => None,
        };
        Ok(Some(Mapped {
            map: Map::load(t, MapKind::Normal)?,
            frame: Frame::of(o),
            affine: o.transform.as_ref().map(Affine::new),
            mesh,
        }))
    }

    /// The world tangent frame at `vert` on `o`; None where the hit has
    /// no texture coordinates.
    fn tangents(&self, o: &Object, vert: &Vertex) -> Option<Tangents> {
        let t = match &self.mesh {
            Some(m) => {
                let at = vert.tri?;
                tangent::mesh_tangents(m, at.tri as usize, at.u, at.v)?
            }
            None => {
                let p = self.frame.as_ref().map_or(vert.p, |f| f.point(vert.p));
                o.shape.tangents(p)?
            }
        };
        Some(match &self.affine {
            Some(a) => Tangents {
                du: a.vector(t.du),
                dv: a.vector(t.dv),
                n: a.normal(t.n),
            },
            None => t,
        })
    }
}

/// Replaces the packed normal of every hit on a normal-mapped object of
/// `scene` by the map's; nothing when no object has one.
pub fn perturb(paths: &Paths, packed: &mut Packed, scene: &Scene) -> Result<(), RenderFailure> {
    if scene
        .objects
        .iter()
        .all(|o| o.material.normal_map.is_none())
    {
        return Ok(());
    }
    let mapped = scene
        .objects
        .iter()
        .map(Mapped::of)
        .collect::<Result<Vec<_>, _>>()?;
    for (vi, vert) in paths.verts.iter().enumerate() {
        let o = vert.object as usize;
        let Some(m) = &mapped[o] else { continue };
        let obj = &scene.objects[o];
        let (Some(uv), Some(t)) = (
            hit_uv(obj, m.frame.as_ref(), m.mesh.as_deref(), vert),
            m.tangents(obj, vert),
        ) else {
            continue;
        };
        let n = perturbed(vert.n, &t, m.map.at(uv));
        let k = packed.packed_of[vi] as usize;
        packed.nx[k] = n.x as f32;
        packed.ny[k] = n.y as f32;
        packed.nz[k] = n.z as f32;
    }
    Ok(())
}

/// The shading normal at a hit of unit normal `hit_n` (turned towards
/// the ray) in the world frame `t`, from the map's texel `rgb`.
fn perturbed(hit_n: V3, t: &Tangents, rgb: [f32; 3]) -> V3 {
    let back = hit_n.dot(t.n) < 0.0;
    let n = if back { -hit_n } else { hit_n };
    let (tu, tv) = orthonormal(n, t.du, t.dv);
    let [x, y, z] = rgb.map(|c| 2.0 * c as f64 - 1.0);
    let p = tu * x + tv * y + n * z;
    let len = p.length();
    let p = if len > 1e-12 && len.is_finite() {
        p / len
    } else {
        n
    };
    if back {
        -p
    } else {
        p
    }
}

/// (T, B): dP/du made perpendicular to the unit `n` (Gram-Schmidt), or
/// the plane axes of `n` when it has no such part; B = n x T, turned
/// round when dP/dv points the other way (mirrored coordinates).
fn orthonormal(n: V3, du: V3, dv: V3) -> (V3, V3) {
    let t = du - n * n.dot(du);
    let len = t.length();
    let t = if len > 1e-9 * du.length() && len.is_finite() && len > 0.0 {
        t / len
    } else {
        plane_axes(n).0
    };
    let b = n.cross(t);
    if b.dot(dv) < 0.0 {
        (t, -b)
    } else {
        (t, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: V3, b: V3) -> bool {
        (a - b).length() < 1e-6
    }

    fn flat(du: V3, dv: V3) -> Tangents {
        Tangents {
            du,
            dv,
            n: V3::new(0.0, 0.0, 1.0),
        }
    }

    #[test]
    fn a_flat_texel_keeps_the_normal_and_red_and_green_tilt_it_along_u_and_v() {
        let z = V3::new(0.0, 0.0, 1.0);
        let t = flat(V3::new(2.0, 0.0, 0.0), V3::new(0.0, 3.0, 0.0));
        assert!(close(perturbed(z, &t, [0.5, 0.5, 1.0]), z));
        let s = 0.5f64.sqrt();
        // +x in the map is +u (red), +y is +v (green: OpenGL, +Y up)
        assert!(close(perturbed(z, &t, [1.0, 0.5, 1.0]), V3::new(s, 0.0, s)));
        assert!(close(perturbed(z, &t, [0.5, 1.0, 1.0]), V3::new(0.0, s, s)));
        // mirrored v: green tilts towards dP/dv, wherever it points
        let m = flat(V3::new(1.0, 0.0, 0.0), V3::new(0.0, -1.0, 0.0));
        assert!(close(
            perturbed(z, &m, [0.5, 1.0, 1.0]),
            V3::new(0.0, -s, s)
        ));
        // seen from the back, the whole normal turns round
        assert!(close(
            perturbed(-z, &t, [1.0, 0.5, 1.0]),
            V3::new(-s, 0.0, -s)
        ));
    }

    #[test]
    fn a_degenerate_frame_or_texel_gives_a_unit_normal_not_nan() {
        let z = V3::new(0.0, 0.0, 1.0);
        let zero = V3::new(0.0, 0.0, 0.0);
        for t in [
            flat(zero, zero),
            flat(z, z),
            flat(V3::new(f64::NAN, 0.0, 0.0), zero),
        ] {
            for rgb in [[0.5, 0.5, 0.5], [1.0, 0.0, 1.0], [0.3, 0.8, 0.9]] {
                let n = perturbed(z, &t, rgb);
                assert!((n.length() - 1.0).abs() < 1e-9, "{t:?} {rgb:?}: {n:?}");
            }
        }
    }
}
