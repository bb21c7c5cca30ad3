//! The mesh as read: positions, optional per-vertex normals and texture
//! coordinates, triangles; its check, and the fan that turns a file's
//! polygon into triangles. The readers (`ply.rs`, `obj.rs`) fill it.

/// A triangle mesh in its file's frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<[f64; 3]>,
    /// One per position, or empty (the file has none).
    pub normals: Vec<[f64; 3]>,
    /// One (u, v) per position, or empty.
    pub texcoords: Vec<[f64; 2]>,
    /// Indices into `positions`, counter-clockwise as the file gives them.
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// Refuses what no renderer can draw: no triangles, an index past the
    /// vertices, a non-finite number, attribute lists of the wrong length.
    pub fn check(&self) -> std::result::Result<(), String> {
        if self.triangles.is_empty() {
            return Err("no faces; expected at least one triangle".into());
        }
        let n = self.positions.len();
        if let Some((f, t)) = self
            .triangles
            .iter()
            .enumerate()
            .find(|(_, t)| t.iter().any(|&i| i as usize >= n))
        {
            return Err(format!(
                "face {f} uses vertex {} of {n}; expected indices below the vertex count",
                t.iter().max().unwrap_or(&0)
            ));
        }
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        if let Some(i) = self.positions.iter().position(|p| !finite(p)) {
            return Err(format!("vertex {i} is not finite; expected numbers"));
        }
        if let Some(i) = self.normals.iter().position(|p| !finite(p)) {
            return Err(format!("the normal of vertex {i} is not finite"));
        }
        if let Some(i) = self.texcoords.iter().position(|p| !finite(p)) {
            return Err(format!(
                "the texture coordinates of vertex {i} are not finite"
            ));
        }
        for (what, len) in [
            ("normals", self.normals.len()),
            ("texture coordinates", self.texcoords.len()),
        ] {
            if len != 0 && len != n {
                return Err(format!("{len} {what} for {n} vertices"));
            }
        }
        Ok(())
    }

    /// The smallest box holding every vertex: (lo, hi).
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.positions {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        (lo, hi)
    }
}

/// Appends the polygon `face` (vertex indices) as a fan of triangles:
/// exact for the convex polygons files hold. Fewer than 3 vertices is
/// refused, naming the face.
pub(crate) fn fan(
    face: &[u32],
    index: usize,
    out: &mut Vec<[u32; 3]>,
) -> std::result::Result<(), String> {
    if face.len() < 3 {
        return Err(format!(
            "face {index} has {} vertices; expected 3 or more",
            face.len()
        ));
    }
    for k in 1..face.len() - 1 {
        out.push([face[0], face[k], face[k + 1]]);
    }
    Ok(())
}
