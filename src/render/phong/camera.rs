//! Camera rays of the built-in tracer: a pinhole (`perspective`, vertical
//! field of view `fov_y_deg`) or a parallel projection (`orthographic`,
//! vertical extent `height` in metres), through pixel-centre grids.

use crate::math::V3;
use crate::scene::{Camera, CameraKind, ImageSize};

/// A camera ready to shoot rays.
pub struct CameraRays {
    kind: CameraKind,
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
        let origin = V3::from(cam.position);
        let forward = (V3::from(cam.look_at) - origin).normalized();
        let right = forward.cross(V3::from(cam.up)).normalized();
        let up = right.cross(forward);
        let aspect = size.width as f64 / size.height as f64;
        let half_h = match cam.kind {
            CameraKind::Perspective => (cam.fov_y_deg.unwrap_or(40.0).to_radians() / 2.0).tan(),
            CameraKind::Orthographic => cam.height.unwrap_or(1.0) / 2.0,
        };
        CameraRays {
            kind: cam.kind,
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

    /// The ray through image point (x, y) in pixels, (0, 0) the top-left
    /// corner: origin and unit direction.
    pub fn ray(&self, x: f64, y: f64) -> (V3, V3) {
        let sx = (2.0 * x / self.width - 1.0) * self.half_w;
        let sy = (1.0 - 2.0 * y / self.height) * self.half_h;
        match self.kind {
            CameraKind::Perspective => (
                self.origin,
                (self.forward + self.right * sx + self.up * sy).normalized(),
            ),
            CameraKind::Orthographic => {
                (self.origin + self.right * sx + self.up * sy, self.forward)
            }
        }
    }

    /// Where point `p` lands on the image, in pixels (the inverse of
    /// [`CameraRays::ray`]); `None` when it is not in front of a pinhole.
    pub fn pixel_of(&self, p: V3) -> Option<(f64, f64)> {
        let q = p - self.origin;
        let (sx, sy) = match self.kind {
            CameraKind::Perspective => {
                let z = q.dot(self.forward);
                if z <= 1e-9 {
                    return None;
                }
                (q.dot(self.right) / z, q.dot(self.up) / z)
            }
            CameraKind::Orthographic => (q.dot(self.right), q.dot(self.up)),
        };
        Some((
            (sx / self.half_w + 1.0) * self.width / 2.0,
            (1.0 - sy / self.half_h) * self.height / 2.0,
        ))
    }
}
