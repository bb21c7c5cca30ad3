//! A calibrated camera, `"type": "pinhole"`, in OpenCV's conventions
//! exactly: a world point X is seen at Xc = R X + t (`rotation` the
//! Rodrigues vector of R, `translation` t: the `rvec`/`tvec` that
//! `calibrateCamera` and `solvePnP` return), camera x right, y down, z
//! forward; x' = Xc/Zc, y' = Yc/Zc, distorted by `distortion` [k1, k2, p1,
//! p2, k3] (OpenCV's five-coefficient model), then u = fx x'' + cx, v = fy
//! y'' + cy in pixels, (0, 0) the centre of the top-left pixel. The
//! built-in tracer shoots rays through pixel centres, undistorting them by
//! the iterative inverse OpenCV's `undistortPoints` uses.

use super::checks::{finite3, positive};
use super::types::{Camera, CameraKind};
use crate::error::{Error, Result};
use crate::math::{Vec3, V3};

/// A pinhole camera ready to project points and shoot rays.
#[derive(Clone, Copy, Debug)]
pub struct Pinhole {
    /// Rows of R, world to camera.
    r: [V3; 3],
    t: V3,
    fx: f64,
    fy: f64,
    cx: f64,
    cy: f64,
    /// k1, k2, p1, p2, k3.
    d: [f64; 5],
}

/// Undistortion stops when a step moves the point less than this (in
/// normalised image coordinates: 1e-12 of a focal length).
const UNDISTORT_TOLERANCE: f64 = 1e-12;
const UNDISTORT_ITERATIONS: usize = 50;

impl Pinhole {
    /// The pinhole of a validated `pinhole` camera (None for other kinds).
    pub fn of(c: &Camera) -> Option<Pinhole> {
        if c.kind != CameraKind::Pinhole {
            return None;
        }
        Some(Pinhole {
            r: rodrigues(c.rotation?),
            t: V3::from(c.translation?),
            fx: c.fx?,
            fy: c.fy?,
            cx: c.cx?,
            cy: c.cy?,
            d: c.distortion.unwrap_or_default(),
        })
    }

    /// True when the lens has any distortion.
    pub fn distorts(&self) -> bool {
        self.d != [0.0; 5]
    }

    /// fx, fy, cx, cy.
    pub fn intrinsics(&self) -> (f64, f64, f64, f64) {
        (self.fx, self.fy, self.cx, self.cy)
    }

    /// R^T v: a camera-frame vector in the world.
    pub fn camera_to_world(&self, v: V3) -> V3 {
        self.r[0] * v.x + self.r[1] * v.y + self.r[2] * v.z
    }

    /// The camera's centre in the world: -R^T t.
    pub fn centre(&self) -> V3 {
        -self.camera_to_world(self.t)
    }

    /// The camera's forward (+z) axis in the world.
    pub fn forward(&self) -> V3 {
        self.camera_to_world(V3::new(0.0, 0.0, 1.0))
    }

    /// OpenCV's distortion of normalised coordinates (x', y') -> (x'', y'').
    pub fn distort(&self, x: f64, y: f64) -> (f64, f64) {
        let [k1, k2, p1, p2, k3] = self.d;
        let r2 = x * x + y * y;
        let radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
        (
            x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
            y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y,
        )
    }

    /// The inverse of [`Pinhole::distort`], by OpenCV's fixed-point
    /// iteration (exact for no distortion).
    pub fn undistort(&self, xd: f64, yd: f64) -> (f64, f64) {
        if !self.distorts() {
            return (xd, yd);
        }
        let [k1, k2, p1, p2, k3] = self.d;
        let (mut x, mut y) = (xd, yd);
        for _ in 0..UNDISTORT_ITERATIONS {
            let r2 = x * x + y * y;
            let radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
            let dx = 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
            let dy = p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
            let (nx, ny) = ((xd - dx) / radial, (yd - dy) / radial);
            let step = (nx - x).abs().max((ny - y).abs());
            (x, y) = (nx, ny);
            if step < UNDISTORT_TOLERANCE {
                break;
            }
        }
        (x, y)
    }

    /// Where world point `p` is seen, in OpenCV pixel coordinates; None
    /// behind the camera.
    pub fn project(&self, p: V3) -> Option<(f64, f64)> {
        let q = V3::new(self.r[0].dot(p), self.r[1].dot(p), self.r[2].dot(p)) + self.t;
        if q.z <= 1e-12 {
            return None;
        }
        let (x, y) = self.distort(q.x / q.z, q.y / q.z);
        Some((self.fx * x + self.cx, self.fy * y + self.cy))
    }

    /// The ray seen at OpenCV pixel coordinates (u, v): the camera's centre
    /// and a unit direction.
    pub fn ray(&self, u: f64, v: f64) -> (V3, V3) {
        let (x, y) = self.undistort((u - self.cx) / self.fx, (v - self.cy) / self.fy);
        (
            self.centre(),
            self.camera_to_world(V3::new(x, y, 1.0)).normalized(),
        )
    }
}

/// The rotation matrix (rows) of a Rodrigues vector: about r/|r| by |r|
/// radians, as OpenCV's `Rodrigues`.
pub fn rodrigues(r: Vec3) -> [V3; 3] {
    let v = V3::from(r);
    let theta = v.length();
    let (s, c, k) = if theta < 1e-300 {
        (0.0, 1.0, V3::new(0.0, 0.0, 0.0))
    } else {
        let (s, c) = theta.sin_cos();
        (s, c, v / theta)
    };
    // R = c I + (1 - c) k k^T + s [k]x, row by row
    let cross = [
        V3::new(0.0, -k.z, k.y),
        V3::new(k.z, 0.0, -k.x),
        V3::new(-k.y, k.x, 0.0),
    ];
    let row = |i: usize| {
        let mut e = [0.0; 3];
        e[i] = c;
        V3::from(e) + k * ((1.0 - c) * k.get(i)) + cross[i] * s
    };
    [row(0), row(1), row(2)]
}

impl Camera {
    /// Where the camera is: `position`, or a pinhole's centre.
    pub fn eye(&self) -> Vec3 {
        match Pinhole::of(self) {
            Some(p) => p.centre().to_array(),
            None => self.position.unwrap_or_default(),
        }
    }

    /// A point the camera looks at: `look_at`, or one unit along a
    /// pinhole's optical axis.
    pub fn target(&self) -> Vec3 {
        match Pinhole::of(self) {
            Some(p) => (p.centre() + p.forward()).to_array(),
            None => self.look_at.unwrap_or_default(),
        }
    }
}

/// A pinhole camera's own fields present and in range, and none of the
/// look-at cameras' fields.
pub(crate) fn check(c: &Camera, file: &str) -> Result<()> {
    let need = |key: &str, v: Option<f64>| {
        v.ok_or_else(|| {
            Error::invalid(
                file,
                format!("camera.{key}"),
                "missing; a pinhole camera needs fx, fy, cx, cy, rotation and translation",
            )
        })
    };
    positive(file, "camera.fx", need("fx", c.fx)?)?;
    positive(file, "camera.fy", need("fy", c.fy)?)?;
    for (key, v) in [("cx", c.cx), ("cy", c.cy)] {
        if !need(key, v)?.is_finite() {
            return Err(Error::invalid(
                file,
                format!("camera.{key}"),
                "expected a finite number",
            ));
        }
    }
    for (key, v) in [("rotation", c.rotation), ("translation", c.translation)] {
        let v = v.ok_or_else(|| {
            Error::invalid(
                file,
                format!("camera.{key}"),
                "missing; a pinhole camera needs rotation and translation (OpenCV's rvec and tvec)",
            )
        })?;
        if !finite3(v) {
            return Err(Error::invalid(
                file,
                format!("camera.{key}"),
                "expected three finite numbers",
            ));
        }
    }
    if c.distortion
        .is_some_and(|d| d.iter().any(|x| !x.is_finite()))
    {
        return Err(Error::invalid(
            file,
            "camera.distortion",
            "expected five finite numbers [k1, k2, p1, p2, k3]",
        ));
    }
    let unused = "not used by a pinhole camera (rotation and translation place it, fx and fy set its field of view)";
    for (key, present) in [
        ("position", c.position.is_some()),
        ("look_at", c.look_at.is_some()),
        ("fov_y_deg", c.fov_y_deg.is_some()),
        ("height", c.height.is_some()),
        ("up", c.up != [0.0, 1.0, 0.0]),
    ] {
        if present {
            return Err(Error::invalid(file, format!("camera.{key}"), unused));
        }
    }
    Ok(())
}

/// A look-at camera (`perspective`, `orthographic`) has none of a
/// pinhole's fields.
pub(crate) fn forbid_in_other_kinds(c: &Camera, file: &str) -> Result<()> {
    for (key, present) in [
        ("fx", c.fx.is_some()),
        ("fy", c.fy.is_some()),
        ("cx", c.cx.is_some()),
        ("cy", c.cy.is_some()),
        ("rotation", c.rotation.is_some()),
        ("translation", c.translation.is_some()),
        ("distortion", c.distortion.is_some()),
    ] {
        if present {
            return Err(Error::invalid(
                file,
                format!("camera.{key}"),
                "used by a pinhole camera only (\"type\": \"pinhole\")",
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(json: serde_json::Value) -> Camera {
        serde_json::from_value(json).unwrap()
    }

    /// A ray through a point's projection passes through the point, with
    /// and without distortion; a turn about y by 90 degrees sends the
    /// camera's z to world -x... (R^T e_z).
    #[test]
    fn rays_pass_through_the_points_they_project() {
        for d in [[0.0; 5], [-0.12, 0.03, 0.002, -0.003, 0.01]] {
            let c = camera(
                serde_json::json!({"type": "pinhole", "fx": 150.0, "fy": 140.0,
                "cx": 70.3, "cy": 44.8, "rotation": [0.25, -0.4, 0.1], "translation": [0.3, -0.2, 4.0],
                "distortion": d}),
            );
            let p = Pinhole::of(&c).unwrap();
            for q in [
                V3::new(0.0, 0.0, 0.0),
                V3::new(-1.1, 0.6, 0.3),
                V3::new(1.0, -0.5, -0.4),
            ] {
                let (u, v) = p.project(q).unwrap();
                let (o, dir) = p.ray(u, v);
                let off = (q - o) - dir * (q - o).dot(dir);
                assert!(off.length() < 1e-9, "{d:?} {q:?}: {}", off.length());
            }
        }
        let r = rodrigues([0.0, std::f64::consts::FRAC_PI_2, 0.0]);
        // rows of R: R e_x = -e_z... check R (1,0,0) = (0,0,-1)
        let x = V3::new(r[0].x, r[1].x, r[2].x);
        assert!((x - V3::new(0.0, 0.0, -1.0)).length() < 1e-12, "{x:?}");
    }
}
