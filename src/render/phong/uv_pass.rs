//! The surface pass: for every pixel, which object the camera sees there
//! and at which texture coordinates (`scene::texture::uv`), found by the
//! built-in tracer's camera rays. It is the scene's geometry, not a
//! backend's drawing, so it holds for whichever renderer fits (they
//! agree on where things are). The diagnosis solves a texture in the
//! object's frame from it (`diagnose/texels.rs`). Normal renders never
//! run it.

use super::camera::CameraRays;
use super::geometry::Geometry;
use super::paths::{Vertex, Via, NO_PARENT};
use super::texture::{hit_uv, object_meshes, Frame};
use crate::scene::Scene;
use rayon::prelude::*;

/// What one pixel sees: an object and its texture coordinates there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    pub object: u32,
    /// Single precision: 16 bytes a pixel with its Option, for every
    /// photograph of a set at once.
    pub uv: [f32; 2],
}

/// Per pixel (rows top to bottom): what it sees, or None where it sees
/// nothing, more than one object (an edge: its antialiasing samples
/// disagree) or a surface without texture coordinates (a mesh without
/// UVs).
pub struct SurfaceCoords {
    pub width: u32,
    pub height: u32,
    pub points: Vec<Option<SurfacePoint>>,
}

/// The surface pass of `scene`: the texture coordinates at each pixel's
/// centre, kept where every antialiasing sample of the pixel hits the
/// same object (its render then mixes nothing else).
pub fn surface_coords(scene: &Scene) -> SurfaceCoords {
    let geometry = Geometry::new(scene);
    let cam = CameraRays::new(&scene.camera, scene.image);
    let rects = geometry.screen_rects(&cam);
    let (w, h) = (scene.image.width, scene.image.height);
    let aa = scene.render.antialias.max(1);
    let frames: Vec<Option<Frame>> = scene.objects.iter().map(Frame::of).collect();
    let meshes = object_meshes(scene);
    let object_at = |fx: f64, fy: f64| {
        let (o, d) = cam.ray(fx, fy);
        geometry
            .intersect_camera_ray(o, d, (fx, fy), &rects)
            .map(|hit| (o, d, hit))
    };
    let point = |x: u32, y: u32| -> Option<SurfacePoint> {
        let (o, d, hit) = object_at(x as f64 + 0.5, y as f64 + 0.5)?;
        for sy in 0..aa {
            for sx in 0..aa {
                let fx = x as f64 + (sx as f64 + 0.5) / aa as f64;
                let fy = y as f64 + (sy as f64 + 0.5) / aa as f64;
                if object_at(fx, fy).map(|s| s.2.object) != Some(hit.object) {
                    return None;
                }
            }
        }
        let k = hit.object as usize;
        let vert = Vertex {
            pixel: y * w + x,
            object: hit.object,
            parent: NO_PARENT,
            via: Via::Camera,
            p: o + d * hit.t,
            n: hit.n,
            v: -d,
            tri: hit.tri,
        };
        let object = &scene.objects[k];
        let uv = hit_uv(object, frames[k].as_ref(), meshes[k].as_deref(), &vert)?;
        Some(SurfacePoint {
            object: hit.object,
            uv: uv.map(|x| x as f32),
        })
    };
    let points = (0..h)
        .into_par_iter()
        .flat_map_iter(|y| (0..w).map(move |x| (x, y)).collect::<Vec<_>>())
        .map(|(x, y)| point(x, y))
        .collect();
    SurfaceCoords {
        width: w,
        height: h,
        points,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sphere seen head-on: the pixel at its image's centre sees the
    /// point facing the camera (+z from the centre: u = 3/4, v = 1/2),
    /// the corners see nothing, and a pixel above the centre a higher v.
    #[test]
    fn the_pass_finds_the_sphere_and_its_coordinates() {
        let scene: Scene = crate::scene::parse(
            r#"{"format": "scenefit-scene/1", "image": {"width": 33, "height": 33},
            "camera": {"type": "perspective", "position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 30},
            "lights": [{"name": "key", "type": "point", "position": [0, 0, 5], "intensity": 1}],
            "objects": [{"name": "ball", "shape": {"type": "sphere", "center": [0, 0, 0], "radius": 1},
                         "material": {"color": [1, 1, 1]}}]}"#,
            "s.json",
            &[],
        )
        .unwrap();
        let s = surface_coords(&scene);
        let at = |x: u32, y: u32| s.points[(y * s.width + x) as usize];
        let c = at(16, 16).unwrap();
        assert_eq!(c.object, 0);
        assert!(
            (c.uv[0] - 0.75).abs() < 0.01 && (c.uv[1] - 0.5).abs() < 0.01,
            "{c:?}"
        );
        assert!(at(0, 0).is_none());
        assert!(at(16, 12).unwrap().uv[1] > c.uv[1] + 0.05);
    }
}
