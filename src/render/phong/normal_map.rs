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
use crate::render::RenderFailure;
use crate::scene::mesh::{self, Mesh};
use crate::scene::texture::tangent::{self, perturbed, Tangents};
use crate::scene::texture::MapKind;
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
