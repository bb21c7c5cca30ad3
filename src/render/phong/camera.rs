//! Camera rays of the built-in tracer: a look-at pinhole (`perspective`,
//! vertical field of view `fov_y_deg`), a parallel projection
//! (`orthographic`, vertical extent `height` in metres) or a calibrated
//! `pinhole` (OpenCV's model with distortion, scene/pinhole.rs), through
//! pixel-centre grids.

use crate::math::V3;
use crate::scene::pinhole::Pinhole;
use crate::scene::{Camera, CameraKind, ImageSize};

/// A camera ready to shoot rays.
pub enum CameraRays {
    LookAt(LookAt),
    Pinhole(Pinhole),
}

/// A `perspective` or `orthographic` camera.
pub struct LookAt {
    orthographic: bool,
    origin: V3,
    forward: V3,
    right: V3,
    up: V3,
    /// Half extent of the image plane: at distance 1 (perspective) or in
    /// metres (orthographic).
    half_h: f64,
    half_w: f64,
    width: f64,
    height: f64,
}

impl CameraRays {
    pub fn new(cam: &Camera, size: ImageSize) -> CameraRays {
        match Pinhole::of(cam) {
            Some(p) => CameraRays::Pinhole(p),
            None => CameraRays::LookAt(LookAt::new(cam, size)),
        }
    }

    /// The ray through image point (x, y) in pixels, (0, 0) the top-left
    /// corner: origin and unit direction. (OpenCV's pixel coordinates put
    /// (0, 0) at the top-left pixel's centre: half a pixel less.)
    pub fn ray(&self, x: f64, y: f64) -> (V3, V3) {
        match self {
            CameraRays::LookAt(c) => c.ray(x, y),
            CameraRays::Pinhole(p) => p.ray(x - 0.5, y - 0.5),
        }
    }

    /// Where point `p` lands on the image, in pixels (the inverse of
    /// [`CameraRays::ray`]), for bounding a shape's image by its corners';
    /// `None` when it is not in front of a pinhole, or the lens distorts
    /// (a distorted image of a convex shape may leave its corners' hull).
    pub fn pixel_of(&self, p: V3) -> Option<(f64, f64)> {
        match self {
            CameraRays::LookAt(c) => c.pixel_of(p),
            CameraRays::Pinhole(c) if c.distorts() => None,
            CameraRays::Pinhole(c) => c.project(p).map(|(u, v)| (u + 0.5, v + 0.5)),
        }
    }
}

impl LookAt {
    fn new(cam: &Camera, size: ImageSize) -> LookAt {
        let origin = V3::from(cam.eye());
        let forward = (V3::from(cam.target()) - origin).normalized();
        let right = forward.cross(V3::from(cam.up)).normalized();
        let up = right.cross(forward);
        let aspect = size.width as f64 / size.height as f64;
        let orthographic = cam.kind == CameraKind::Orthographic;
        let half_h = if orthographic {
            cam.height.unwrap_or(1.0) / 2.0
        } else {
            (cam.fov_y_deg.unwrap_or(40.0).to_radians() / 2.0).tan()
        };
        LookAt {
            orthographic,
            origin,
            forward,
            right,
            up,
            half_h,
            half_w: half_h * aspect,
            width: size.width as f64,
            height: size.height as f64,
        }
    }

    fn ray(&self, x: f64, y: f64) -> (V3, V3) {
        let sx = (2.0 * x / self.width - 1.0) * self.half_w;
        let sy = (1.0 - 2.0 * y / self.height) * self.half_h;
        if self.orthographic {
            (self.origin + self.right * sx + self.up * sy, self.forward)
        } else {
            (
                self.origin,
                (self.forward + self.right * sx + self.up * sy).normalized(),
            )
        }
    }

    fn pixel_of(&self, p: V3) -> Option<(f64, f64)> {
        let q = p - self.origin;
        let (sx, sy) = if self.orthographic {
            (q.dot(self.right), q.dot(self.up))
        } else {
            let z = q.dot(self.forward);
            if z <= 1e-9 {
                return None;
            }
            (q.dot(self.right) / z, q.dot(self.up) / z)
        };
        Some((
            (sx / self.half_w + 1.0) * self.width / 2.0,
            (1.0 - sy / self.half_h) * self.height / 2.0,
        ))
    }
}
