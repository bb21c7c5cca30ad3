//! A normal-mapped mesh as POV-Ray can draw it: the mesh cut into
//! smaller triangles, each corner given the normal the map makes there,
//! which POV-Ray interpolates across each small triangle as it does any
//! `mesh2`'s `normal_vectors`. POV-Ray's own bump patterns cannot do it:
//! on a mesh its `uv_mapping` turns a pattern's gradient along the
//! world's axes, not the surface's. A sphere, quad or box whose map is no
//! height field's (`pov_bumps`) is made triangles and baked the same way
//! (`bakes`); a plane has no end to cut.
//!
//! The built-in tracer interpolates the map's texels at each hit and then
//! perturbs (`scene::texture::tangent::perturbed`); here the perturbed
//! normals are interpolated, which is the same once the small triangles
//! are a fraction of a texel (`FINE` a texel along their edges). The
//! normal is worked out in the world, as the built-in tracer does (the
//! map's frame turned by the object's transform, so an uneven scale is
//! drawn too), and written back in the mesh's frame (`Affine::normal_back`)
//! for POV-Ray to carry through the same transform. The written text of
//! the last two is kept (`written`): a fit redraws the same one.

use super::recent::Recent;
use crate::math::V3;
use crate::scene::mesh::Mesh;
use crate::scene::texture::tangent::{self, Tangents};
use crate::scene::texture::{self, MapKind, Texels, TextureRef};
use crate::scene::transform::{Affine, Transform};
use crate::scene::{Object, Shape};
use std::path::Path;
use std::sync::Arc;

/// Small triangles per texel along each edge.
const FINE: f64 = 2.0;

/// The most triangles a baked mesh has (about 40 bytes of `mesh2` text
/// each and 80 of memory while it is written): a finer map over a larger
/// mesh is cut more coarsely, evenly, and drawn less exactly.
pub const MAX_TRIANGLES: usize = 1 << 19;

/// What a baked mesh is made of: the shape (a mesh's file), its normal
/// map, its transform.
type Key = (Shape, TextureRef, Option<Transform>);

/// The last baked meshes as written (`mesh2` text), by what they are made
/// of: a fit renders the same mesh under the same map on every candidate,
/// and at the budget the cut and its text take over a second. Two kept:
/// a few tens of MB each at most.
static WRITTEN: Recent<Key, Arc<str>> = Recent::new(2);

/// Whether POV-Ray draws `o`'s normal map baked into a mesh: a mesh's
/// always; a sphere's, quad's or box's where it cannot draw it as a
/// height field's gradient (`pov_bumps`): the slopes no height's on a
/// face (`pov_bumps::refused`), or the object scaled unevenly (POV-Ray
/// would turn the gradient as a normal, the built-in tracer turns the
/// map's frame). Never a plane's: it has no end to cut. An unreadable
/// map is not baked (the scene check reports it).
pub fn bakes(o: &Object) -> bool {
    let Some(t) = o.material.map(MapKind::Normal) else {
        return false;
    };
    match o.shape {
        Shape::Mesh { .. } => true,
        Shape::Plane { .. } => false,
        _ => {
            scaled_unevenly(o)
                || o.shape.faces().iter().any(|f| {
                    super::pov_bumps::laid(f, t.scale())
                        .is_some_and(|lay| matches!(super::pov_bumps::missed(t, lay), Ok(Some(_))))
                })
        }
    }
}

/// Whether `o`'s transform scales its axes differently.
pub fn scaled_unevenly(o: &Object) -> bool {
    o.transform.as_ref().and_then(|t| t.scale).is_some_and(|s| {
        let [a, b, c] = s.axes();
        (a - b).abs() > 1e-9 * a.abs() || (a - c).abs() > 1e-9 * a.abs()
    })
}

/// The object `o` (`bakes`) as a mesh baked with its normal map and
/// written by `write`, or the text kept from a render before.
pub fn written(o: &Object, write: impl FnOnce(&Mesh) -> String) -> Result<Arc<str>, String> {
    let t = o.material.map(MapKind::Normal);
    let t = t.ok_or_else(|| format!("objects.{}.material.normal_map: none to bake", o.name))?;
    let key = (o.shape.clone(), t.clone(), o.transform.clone());
    WRITTEN.get_or(key, || {
        let mesh = match &o.shape {
            Shape::Mesh { file } => crate::scene::mesh::get(Path::new(file))
                .map_err(|e| format!("objects.{}.shape.file: {e}", o.name))?,
            shape => Arc::new(tessellated(shape).ok_or_else(|| {
                format!(
                    "objects.{}.material.normal_map: a plane is not baked",
                    o.name
                )
            })?),
        };
        // without texture coordinates the map changes nothing, as in the
        // built-in tracer
        if mesh.texcoords.is_empty() {
            return Ok(write(&mesh).into());
        }
        Ok(write(&baked(o, t, &mesh)?).into())
    })
}

/// Rows and columns of a sphere's grid of longitude and latitude: its
/// silhouette is then within 8e-5 of its radius; the bake cuts finer.
const SPHERE_GRID: [u32; 2] = [256, 128];

/// A sphere, quad or box as triangles in its own frame, with its texture
/// coordinates (`texture::uv`) and outward normals; None for a plane or a
/// mesh.
fn tessellated(shape: &Shape) -> Option<Mesh> {
    let mut m = Mesh::default();
    match *shape {
        Shape::Sphere { center, radius } => {
            let [nu, nv] = SPHERE_GRID;
            for j in 0..=nv {
                let lat = std::f64::consts::PI * (j as f64 / nv as f64 - 0.5);
                for i in 0..=nu {
                    let lon = 2.0 * std::f64::consts::PI * i as f64 / nu as f64;
                    // texture::uv::sphere_uv: u = atan2(-z, x) / 2 pi, v = 1/2 + lat / pi
                    let d = [lon.cos() * lat.cos(), lat.sin(), -lon.sin() * lat.cos()];
                    m.positions
                        .push([0, 1, 2].map(|k| center[k] + radius * d[k]));
                    m.normals.push(d);
                    m.texcoords
                        .push([i as f64 / nu as f64, j as f64 / nv as f64]);
                }
            }
            let at = |i: u32, j: u32| j * (nu + 1) + i;
            for j in 0..nv {
                for i in 0..nu {
                    // a pole's row keeps only the triangle with area
                    if j > 0 {
                        m.triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                    }
                    if j + 1 < nv {
                        m.triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
                    }
                }
            }
        }
        Shape::Quad { .. } | Shape::Box { .. } => {
            for face in shape.faces() {
                let Shape::Quad {
                    corner,
                    edge_u,
                    edge_v,
                } = face
                else {
                    return None;
                };
                let (c, u, v) = (V3::from(corner), V3::from(edge_u), V3::from(edge_v));
                let n = u.cross(v).normalized();
                let base = m.positions.len() as u32;
                for (s, t) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                    let p = c + u * s + v * t;
                    m.positions.push([p.x, p.y, p.z]);
                    m.normals.push([n.x, n.y, n.z]);
                    m.texcoords.push([s, t]);
                }
                m.triangles.push([base, base + 1, base + 2]);
                m.triangles.push([base, base + 2, base + 3]);
            }
        }
        Shape::Plane { .. } | Shape::Mesh { .. } => return None,
    }
    Some(m)
}

/// `mesh` (the object `o`'s, with texture coordinates) cut and given the
/// normals of its normal map `t`, with its texture coordinates.
fn baked(o: &Object, t: &TextureRef, mesh: &Mesh) -> Result<Mesh, String> {
    let texels = texture::get(Path::new(t.file()), t.encoding(MapKind::Normal))
        .map_err(|e| format!("objects.{}.material.normal_map: {}: {e}", o.name, t.file()))?;
    let affine = o.transform.as_ref().map(Affine::new);
    let cuts = cuts(mesh, t, &texels);
    let mut out = Mesh::default();
    for (tri, &k) in cuts.iter().enumerate() {
        cut(mesh, tri, k, &mut out, |uv, frame| {
            normal(frame, affine.as_ref(), map_value(t, &texels, uv))
        });
    }
    Ok(out)
}

/// The map's value at texture coordinates `uv`, after its `scale` and
/// `range`, as the built-in tracer reads it.
fn map_value(t: &TextureRef, texels: &Texels, uv: [f64; 2]) -> [f32; 3] {
    let [s0, s1] = t.scale();
    let [lo, hi] = t.range().map(|x| x as f32);
    texels
        .sample(uv[0] * s0, uv[1] * s1)
        .map(|x| lo + x * (hi - lo))
}

/// The normal, in the mesh's frame, that the texel `rgb` gives where the
/// surface's frame (mesh's frame) is `frame`.
fn normal(frame: Tangents, affine: Option<&Affine>, rgb: [f32; 3]) -> V3 {
    let world = match affine {
        Some(a) => Tangents {
            du: a.vector(frame.du),
            dv: a.vector(frame.dv),
            n: a.normal(frame.n),
        },
        None => frame,
    };
    let n = world.n.normalized();
    let p = tangent::perturbed(n, &world, rgb);
    match affine {
        Some(a) => a.normal_back(p),
        None => p,
    }
}

/// How many parts each triangle's edges are cut into: `FINE` a texel
/// along its longest edge, fewer (evenly) when the whole would pass
/// `MAX_TRIANGLES`.
fn cuts(mesh: &Mesh, t: &TextureRef, texels: &Texels) -> Vec<u32> {
    let [s0, s1] = t.scale();
    let (w, h) = (texels.width as f64 * s0, texels.height as f64 * s1);
    let want: Vec<f64> = (mesh.triangles.iter())
        .map(|tri| {
            let uv = |k: usize| mesh.texcoords[tri[k] as usize];
            let texels = |a: [f64; 2], b: [f64; 2]| ((a[0] - b[0]) * w).hypot((a[1] - b[1]) * h);
            let (a, b, c) = (uv(0), uv(1), uv(2));
            let longest = texels(a, b).max(texels(b, c)).max(texels(c, a));
            // a non-finite or huge edge is capped: the budget decides
            (FINE * longest).clamp(1.0, 1e6)
        })
        .collect();
    let total: f64 = want.iter().map(|k| k.ceil() * k.ceil()).sum();
    if total <= MAX_TRIANGLES as f64 {
        return want.iter().map(|k| k.ceil() as u32).collect();
    }
    // floor(k s)^2 summed is at most s^2 times the total: the budget
    let shrink = (MAX_TRIANGLES as f64 / total).sqrt();
    want.iter()
        .map(|k| ((k * shrink).floor() as u32).max(1))
        .collect()
}

/// Triangle `tri` of `mesh` cut into k x k triangles (its winding kept),
/// appended to `out`, each corner's normal `normal_at(uv, frame)`.
/// Corners on an edge are computed from the edge's two ends in the order
/// of their indices, so that the two triangles sharing it meet exactly.
fn cut(
    mesh: &Mesh,
    tri: usize,
    k: u32,
    out: &mut Mesh,
    normal_at: impl Fn([f64; 2], Tangents) -> V3,
) {
    let t = mesh.triangles[tri];
    let mut order = [0usize, 1, 2];
    order.sort_by_key(|&c| t[c]);
    let base = out.positions.len() as u32;
    let kf = k as f64;
    for j in 0..=k {
        for i in 0..=k - j {
            let w = [(k - i - j) as f64 / kf, i as f64 / kf, j as f64 / kf];
            let mut p = [0.0; 3];
            let mut uv = [0.0; 2];
            for &c in &order {
                let v = t[c] as usize;
                for (a, x) in p.iter_mut().zip(mesh.positions[v]) {
                    *a += w[c] * x;
                }
                for (a, x) in uv.iter_mut().zip(mesh.texcoords[v]) {
                    *a += w[c] * x;
                }
            }
            let frame = tangent::mesh_tangents(mesh, tri, w[1], w[2])
                .expect("the mesh has texture coordinates");
            let n = apart(normal_at(uv, frame), (i + 2 * j) % 3);
            out.positions.push(p);
            out.texcoords.push(uv);
            out.normals.push([n.x, n.y, n.z]);
        }
    }
    // corner (i, j) of row j: rows hold k + 1, k, ..., 1 corners
    let at = |i: u32, j: u32| base + j * (k + 1) - j * j.saturating_sub(1) / 2 + i;
    for j in 0..k {
        for i in 0..k - j {
            out.triangles.push([at(i, j), at(i + 1, j), at(i, j + 1)]);
            if i + j + 1 < k {
                out.triangles
                    .push([at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }
}

/// How far (relative) the corners of one small triangle are set apart:
/// POV-Ray draws a triangle whose three normals are equal (within about
/// 1e-5, measured) with its face's normal, which would lose a tilt the
/// map holds over a whole small triangle; 1e-4 of a radian shows in no
/// pixel.
const APART: f64 = 1e-4;

/// `n` turned by `APART` times -1, 0 or 1 (`colour`): colours i + 2j
/// (mod 3) give the three corners of every small triangle three
/// different turns.
fn apart(n: V3, colour: u32) -> V3 {
    let (t, _) = crate::scene::texture::uv::plane_axes(n);
    n + t * (APART * n.length() * (colour as f64 - 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Mesh {
        Mesh {
            positions: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            normals: vec![],
            texcoords: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    /// Cut k x k, a triangle keeps its area, winding and texture
    /// coordinates, its small triangles' corners are set apart, and its
    /// corners on a shared edge are the neighbour's, to the bit.
    #[test]
    fn a_cut_triangle_keeps_its_area_and_meets_its_neighbour_exactly() {
        let m = square();
        for k in [1, 2, 3, 7] {
            let mut out = Mesh::default();
            for tri in 0..2 {
                cut(&m, tri, k, &mut out, |_, f| f.n);
            }
            assert_eq!(out.triangles.len(), 2 * (k * k) as usize);
            let p = |i: u32| V3::from(out.positions[i as usize]);
            let area: f64 = (out.triangles.iter())
                .map(|t| (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])).z / 2.0)
                .sum();
            // every small triangle wound as its parent (+z)
            assert!((area - 1.0).abs() < 1e-12, "k {k}: area {area}");
            assert!(out
                .triangles
                .iter()
                .all(|t| { (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])).z > 0.0 }));
            // one normal everywhere, yet no small triangle's three alike
            let n = |i: u32| V3::from(out.normals[i as usize]).normalized();
            assert!(out.triangles.iter().all(|t| {
                let d = |a: u32, b: u32| (n(a) - n(b)).length();
                d(t[0], t[1]).min(d(t[1], t[2])).min(d(t[2], t[0])) > 0.9 * APART
            }));
            // uv = (x, y) on this square
            for (q, uv) in out.positions.iter().zip(&out.texcoords) {
                assert!((q[0] - uv[0]).abs() < 1e-12 && (q[1] - uv[1]).abs() < 1e-12);
            }
            // the diagonal's corners: each appears once from each side
            let diagonal: Vec<_> = (out.positions.iter()).filter(|q| q[0] == q[1]).collect();
            assert_eq!(diagonal.len(), 2 * (k as usize + 1), "k {k}");
            for q in &diagonal {
                assert_eq!(diagonal.iter().filter(|r| r == &q).count(), 2, "{q:?}");
            }
        }
    }

    /// Each triangle is cut `FINE` a texel along its longest edge; over
    /// the budget, fewer, and the whole within it.
    #[test]
    fn the_cuts_follow_the_texels_within_the_budget() {
        let m = square();
        let small = Texels {
            width: 8,
            height: 8,
            values: vec![0.5; 8 * 8 * 3],
        };
        let t = TextureRef::File("t.png".into());
        // the diagonal is 8 sqrt 2 texels: 2 x 11.3 -> 23
        assert_eq!(cuts(&m, &t, &small), vec![23, 23]);
        let huge = Texels {
            width: 4096,
            height: 4096,
            values: vec![],
        };
        let k = cuts(&m, &t, &huge);
        let total: u64 = k.iter().map(|&k| (k as u64).pow(2)).sum();
        assert!(
            total <= MAX_TRIANGLES as u64 && total > MAX_TRIANGLES as u64 / 2,
            "{k:?}"
        );
    }

    /// A flat texel keeps the surface's normal; a tilted one tilts it
    /// along dP/du in the world, and an uneven scale is undone by
    /// `normal_back` as POV-Ray's transform of a normal does it.
    #[test]
    fn the_normal_is_the_maps_in_the_world_written_in_the_mesh_frame() {
        let frame = Tangents {
            du: V3::new(1.0, 0.0, 0.0),
            dv: V3::new(0.0, 1.0, 0.0),
            n: V3::new(0.0, 0.0, 1.0),
        };
        let flat = normal(frame, None, [0.5, 0.5, 1.0]);
        assert!((flat - frame.n).length() < 1e-12);
        let tr: crate::scene::transform::Transform = serde_json::from_value(
            serde_json::json!({"scale": [2.0, 1.0, 0.5], "rotate_deg": [0.0, 0.0, 30.0]}),
        )
        .unwrap();
        let a = Affine::new(&tr);
        let back = normal(frame, Some(&a), [1.0, 0.5, 1.0]);
        // carried as POV-Ray carries a normal: the world's 45-degree tilt
        let world = a.normal(back).normalized();
        let (du, n) = (
            a.vector(frame.du).normalized(),
            a.normal(frame.n).normalized(),
        );
        let s = 0.5f64.sqrt();
        assert!((world - (du * s + n * s)).length() < 1e-9, "{world:?}");
    }
}
