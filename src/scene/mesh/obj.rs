//! OBJ through `tobj` (maintained, no dependencies of its own, and it
//! already handles relative indices, polygons and the v/vt/vn triples):
//! its models joined into one mesh, one index per vertex, polygons fanned
//! into triangles. Material libraries are not opened: a mesh's look is
//! the scene's material, and every file read goes through `input/`.

use super::data::Mesh;

/// Parses a whole OBJ file.
pub fn parse(bytes: &[u8]) -> Result<Mesh, String> {
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = std::io::Cursor::new(bytes);
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| e.to_string())?;
    let with_normals = models.iter().all(|m| !m.mesh.normals.is_empty());
    let with_uv = models.iter().all(|m| !m.mesh.texcoords.is_empty());
    let mut mesh = Mesh::default();
    for m in &models {
        let m = &m.mesh;
        let base = mesh.positions.len() as u64;
        let triples = |v: &[f32]| -> Vec<[f64; 3]> {
            v.chunks_exact(3)
                .map(|c| [c[0] as f64, c[1] as f64, c[2] as f64])
                .collect()
        };
        let count = m.positions.len() / 3;
        mesh.positions.extend(triples(&m.positions));
        if with_normals {
            if m.normals.len() != m.positions.len() {
                return Err("normals do not match the vertices".into());
            }
            mesh.normals.extend(triples(&m.normals));
        }
        if with_uv {
            if m.texcoords.len() / 2 != count {
                return Err("texture coordinates do not match the vertices".into());
            }
            let uv = m.texcoords.chunks_exact(2);
            mesh.texcoords
                .extend(uv.map(|c| [c[0] as f64, c[1] as f64]));
        }
        for t in m.indices.chunks_exact(3) {
            let idx = |i: u32| u32::try_from(base + i as u64).map_err(|_| "too many vertices");
            mesh.triangles.push([idx(t[0])?, idx(t[1])?, idx(t[2])?]);
        }
    }
    Ok(mesh)
}
