//! What `benches/mesh.rs` measures of the built-in tracer that a render
//! session does not show apart: the structure a mesh is traced through,
//! built alone (without the process-wide cache a session reads it from),
//! and the rays a render traces, counted rather than estimated.

use super::bvh::Bvh;
use super::paths::{Paths, Variation};
use super::trimesh::{self, TriMesh};
use crate::scene::mesh::Mesh;
use crate::scene::{ParamSpace, Scene};

pub use super::paths::Rays;

/// Builds the BVH of `mesh` alone; returns its triangle count (so that
/// the build is not optimised away).
pub fn build_bvh(mesh: &Mesh) -> usize {
    Bvh::build(&trimesh::boxes(mesh)).order.len()
}

/// Builds everything a mesh is traced through (its BVH, its triangles in
/// the BVH's order, its bounding sphere and, for a closed mesh, its inner
/// ball), on the threads of the current rayon pool; true when it holds
/// an inner ball.
pub fn build_mesh(mesh: &Mesh) -> bool {
    TriMesh::new(mesh).has_inner_ball()
}

/// The rays a render of `scene` traces while its paths are built, when
/// `varying` is free (`Rays`): all of them when only geometry and fixed
/// lights are involved; a moving light's shadow rays are cast at shading
/// and not counted.
pub fn rays_traced(scene: &Scene, varying: &ParamSpace) -> Rays {
    Paths::build(scene, &Variation::new(scene, varying), false).rays
}
