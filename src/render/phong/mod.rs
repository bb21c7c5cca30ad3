//! The built-in Phong-Blinn ray tracer: perspective and orthographic
//! cameras; spheres, planes, quads and boxes; point and directional lights
//! with inverse-square or no falloff; hard shadows; ambient; normalised
//! Blinn-Phong specular; mirror reflection and refraction to a depth limit.
//! The shading equation is in `shade.rs` and docs/renderers.md.
//!
//! Reads from the scene: `camera`, `image`, `ambient`, `indirect_light`,
//! `lights` (with `radius` for soft shadows and `falloff_power`), `objects`
//! (with `fresnel`, `specular2`, `shininess2`, `albedo_map`, and the
//! texture maps `color_map`, `specular_map`, `shininess_map`: `texture.rs`;
//! `normal_map`: `normal_map.rs`), `render.antialias`,
//! `render.max_depth`. The camera's `vignetting` and `response` are applied
//! after any renderer (render/camera_effects.rs).
//!
//! Speed: what camera rays hit is traced once per session when no free
//! parameter moves geometry, and a candidate only re-shades those hits.
//! A batch renders its candidates in parallel; each render is sequential and
//! deterministic.

mod accel;
mod bounce;
mod bvh;
mod bvh_build;
mod bvh_node;
mod camera;
mod effects;
mod geometry;
mod hull_faces;
mod inner_ball;
pub mod measure;
mod normal_map;
mod packed;
mod paths;
mod shade;
mod texture;
mod trimesh;
pub mod uv_pass;

use super::{Image, RenderFailure, RenderResult, RenderSession, Renderer};
use crate::error::{Error, Result};
use crate::exec::cancel;
use crate::scene::{ParamSpace, Scene};
use packed::Packed;
use paths::{Paths, Variation};
use rayon::prelude::*;
use std::sync::Arc;

/// The built-in tracer.
pub struct Phong;

impl Renderer for Phong {
    fn name(&self) -> String {
        "phong".into()
    }

    fn session(
        &self,
        base: &Scene,
        varying: &ParamSpace,
        jobs: usize,
    ) -> Result<Box<dyn RenderSession>> {
        // The tracer is CPU-bound: threads beyond the cores only cost (a
        // huge --jobs once started 50,000 threads and stalled the machine).
        // The result does not depend on the thread count.
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(jobs.clamp(1, self.default_jobs()))
            .build()
            .map_err(|e| Error::Run(format!("phong: cannot start threads: {e}")))?;
        let variation = Variation::new(base, varying);
        let moves_geometry = varying.fields().iter().any(|f| f.moves_geometry());
        let cached = if moves_geometry {
            None
        } else {
            let prepared = pool
                .install(|| Prepared::new(base, &variation, true))
                .map_err(|e| Error::Run(e.message))?;
            Some(Arc::new(prepared))
        };
        Ok(Box::new(PhongSession {
            pool,
            variation,
            cached,
        }))
    }
}

/// Hits traced once, in both layouts.
struct Prepared {
    paths: Paths,
    packed: Packed,
}

impl Prepared {
    fn new(
        scene: &Scene,
        variation: &Variation,
        parallel: bool,
    ) -> std::result::Result<Prepared, RenderFailure> {
        let paths = Paths::build(scene, variation, parallel);
        // A cancelled build is empty (paths.rs): packing it costs nothing.
        let mut packed = Packed::new(&paths, scene.lights.len());
        // a normal map is a file, never a free parameter: fixed with the hits
        normal_map::perturb(&paths, &mut packed, scene)?;
        Ok(Prepared { paths, packed })
    }
}

struct PhongSession {
    pool: rayon::ThreadPool,
    variation: Variation,
    cached: Option<Arc<Prepared>>,
}

impl PhongSession {
    fn render(&self, scene: &Scene) -> RenderResult {
        // Ctrl-C (exec::cancel) ends a batch within one pass of one render:
        // the rest of the batch is not drawn, and a render cut short (or
        // drawn from paths whose tracing was cut short) is a failure,
        // never an image.
        if cancel::is_cancelled() {
            return Err(RenderFailure::new(cancel::MESSAGE));
        }
        let (w, h) = (scene.image.width, scene.image.height);
        let mut buf = vec![0u8; (w * h * 3) as usize];
        let maps = shade::albedo_maps(scene)?;
        // meshes were read with the scene; a file unreadable since fails here
        for o in &scene.objects {
            if let crate::scene::Shape::Mesh { file } = &o.shape {
                trimesh::get(file).map_err(|e| RenderFailure::new(e.to_string()))?;
            }
        }
        match &self.cached {
            Some(p) => {
                let tex = texture::HitMaps::new(&p.paths, &p.packed, scene)?;
                shade::shade(&p.paths, &p.packed, scene, &maps, tex.as_ref(), &mut buf)
            }
            None => {
                let p = Prepared::new(scene, &self.variation, false)?;
                // a cancelled build is cut short, never shaded
                if cancel::is_cancelled() {
                    return Err(RenderFailure::new(cancel::MESSAGE));
                }
                let tex = texture::HitMaps::new(&p.paths, &p.packed, scene)?;
                shade::shade(&p.paths, &p.packed, scene, &maps, tex.as_ref(), &mut buf)
            }
        }
        if cancel::is_cancelled() {
            return Err(RenderFailure::new(cancel::MESSAGE));
        }
        Ok(Image::from_raw(w, h, buf).expect("buffer sized to the image"))
    }
}

impl RenderSession for PhongSession {
    fn describe(&self) -> String {
        format!("phong (scenefit {})", env!("CARGO_PKG_VERSION"))
    }

    fn render_batch(&mut self, scenes: &[Scene], _seed: u64) -> Vec<RenderResult> {
        let this = &*self;
        self.pool
            .install(|| scenes.par_iter().map(|s| this.render(s)).collect())
    }
}
