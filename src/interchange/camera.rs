//! A calibrated camera as the calibration tools give it, in OpenCV's
//! conventions (scene/pinhole.rs): Xc = R X + t with R as a Rodrigues
//! vector, fx fy cx cy in pixels with (0, 0) the centre of the top-left
//! pixel, distortion [k1, k2, p1, p2, k3]. Written as a shot's `set`
//! values (`camera.fx`, ..., `camera.distortion.k1`, ...).

use crate::scene::Vec3;
use serde_json::{json, Map, Value};

/// One photograph's camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Calibrated {
    /// The image size the calibration is for, when the file gives it.
    pub size: Option<(u32, u32)>,
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
    /// k1, k2, p1, p2, k3.
    pub distortion: [f64; 5],
    /// The Rodrigues vector of R (world to camera).
    pub rotation: Vec3,
    pub translation: Vec3,
}

/// The distortion coefficients' names, in the order of the array.
const DISTORTION: [&str; 5] = ["k1", "k2", "p1", "p2", "k3"];

impl Calibrated {
    /// The shot's `set` values: the camera's calibration by field path
    /// (distortion only when the lens has any, as the scene's camera then
    /// needs a `distortion` for the paths to resolve).
    pub fn set_values(&self) -> Map<String, Value> {
        let mut m = Map::new();
        for (k, v) in [
            ("fx", self.fx),
            ("fy", self.fy),
            ("cx", self.cx),
            ("cy", self.cy),
        ] {
            m.insert(format!("camera.{k}"), json!(v));
        }
        m.insert("camera.rotation".into(), json!(self.rotation));
        m.insert("camera.translation".into(), json!(self.translation));
        if self.distorts() {
            for (k, v) in DISTORTION.iter().zip(self.distortion) {
                m.insert(format!("camera.distortion.{k}"), json!(v));
            }
        }
        m
    }

    /// True when any distortion coefficient is not zero.
    pub fn distorts(&self) -> bool {
        self.distortion != [0.0; 5]
    }
}

/// The Rodrigues vector of the rotation of unit quaternion (w, x, y, z)
/// (Hamilton convention, as COLMAP writes it); the quaternion need not be
/// normalised. Computed from the quaternion directly (angle 2 atan2(|v|, w))
/// so that small and half-turn rotations keep their precision.
pub fn quaternion_to_rodrigues(w: f64, x: f64, y: f64, z: f64) -> Vec3 {
    // q and -q are one rotation; w >= 0 gives the angle in [0, pi]
    let s = if w < 0.0 { -1.0 } else { 1.0 };
    let (w, x, y, z) = (w * s, x * s, y * s, z * s);
    let n = (x * x + y * y + z * z).sqrt();
    if n == 0.0 {
        return [0.0; 3];
    }
    let k = 2.0 * n.atan2(w) / n;
    [x * k, y * k, z * k]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::pinhole::rodrigues;

    /// The rotation matrix of a unit quaternion (rows), by the textbook
    /// formula: the reference the Rodrigues vector must give back.
    fn matrix(w: f64, x: f64, y: f64, z: f64) -> [[f64; 3]; 3] {
        [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
            ],
            [
                2.0 * (x * y + w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - w * x),
            ],
            [
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ]
    }

    #[test]
    fn quaternions_give_the_rodrigues_vector_of_their_rotation() {
        for q in [
            [1.0, 0.0, 0.0, 0.0],
            [0.9, 0.1, -0.3, 0.2],
            [-0.2, 0.7, 0.1, -0.4],
            [0.0, 0.0, 1.0, 0.0],
            [1.0, 1e-9, 0.0, -2e-9],
        ] {
            let n = q.iter().map(|a| a * a).sum::<f64>().sqrt();
            let [w, x, y, z] = q.map(|a| a / n);
            let want = matrix(w, x, y, z);
            let got = rodrigues(quaternion_to_rodrigues(q[0], q[1], q[2], q[3]));
            for i in 0..3 {
                let row = got[i].to_array();
                for j in 0..3 {
                    assert!((row[j] - want[i][j]).abs() < 1e-12, "{q:?}: {got:?}");
                }
            }
        }
    }

    #[test]
    fn distortion_is_written_only_for_a_lens_that_has_it() {
        let mut c = Calibrated {
            size: None,
            fx: 100.0,
            fy: 100.0,
            cx: 10.0,
            cy: 8.0,
            distortion: [0.0; 5],
            rotation: [0.0; 3],
            translation: [0.0, 0.0, 1.0],
        };
        assert!(!c.set_values().contains_key("camera.distortion.k1"));
        c.distortion[3] = 0.01;
        assert_eq!(c.set_values()["camera.distortion.p2"], json!(0.01));
    }
}
