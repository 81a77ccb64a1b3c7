//! The central body's pose in the inertial frame (docs/reference.md).
//!
//! `p_inertial = R + Rot·p_body`, with `Rot = Rx(φx)·Rz(φz)·Ry(φy)`: rotations
//! about the *inertial* axes applied in the sequence Y, then Z, then X (the
//! paper's "(Y, Z, X)" sequence). `Ra(φ)` is the right-handed rotation by φ
//! about axis `a`. Inertial `Y` is vertical, up.

use nalgebra::{Matrix3, Vector3};

/// Right-handed rotation by `phi` about the X axis.
pub fn rot_x(phi: f64) -> Matrix3<f64> {
    let (s, c) = phi.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

/// Right-handed rotation by `phi` about the Y axis.
pub fn rot_y(phi: f64) -> Matrix3<f64> {
    let (s, c) = phi.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Right-handed rotation by `phi` about the Z axis.
pub fn rot_z(phi: f64) -> Matrix3<f64> {
    let (s, c) = phi.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// Position and orientation of the central body (6 DOF).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyPose {
    /// `R = (Rx, Ry, Rz)`: the central body's centre of mass, inertial (m).
    pub position: Vector3<f64>,
    /// `(φx, φy, φz)`: rotation angles about the inertial axes (rad), applied
    /// Y first, then Z, then X.
    pub phi: Vector3<f64>,
}

impl Default for BodyPose {
    /// The identity pose:
    /// * `position = (0, 0, 0)`,
    /// * `phi = (0, 0, 0)`.
    fn default() -> Self {
        Self {
            position: Vector3::zeros(),
            phi: Vector3::zeros(),
        }
    }
}

impl BodyPose {
    /// A pose from `R = (Rx, Ry, Rz)` and `(φx, φy, φz)`.
    pub fn new(position: [f64; 3], phi: [f64; 3]) -> Self {
        Self {
            position: Vector3::from(position),
            phi: Vector3::from(phi),
        }
    }

    /// `Rot = Rx(φx)·Rz(φz)·Ry(φy)`, body → inertial, in closed form
    /// (three `sin_cos`).
    #[inline]
    pub fn rotation(&self) -> Matrix3<f64> {
        let (sx, cx) = self.phi.x.sin_cos();
        let (sy, cy) = self.phi.y.sin_cos();
        let (sz, cz) = self.phi.z.sin_cos();
        Matrix3::new(
            cz * cy,
            -sz,
            cz * sy,
            cx * sz * cy + sx * sy,
            cx * cz,
            cx * sz * sy - sx * cy,
            sx * sz * cy - cx * sy,
            sx * cz,
            sx * sz * sy + cx * cy,
        )
    }

    /// `(roll, pitch, heading)` (rad) of the body, derived from φ: the
    /// body's forward axis is its −z, its right +x, its up +y (the gait's
    /// axes), and `Rot = Ry(heading)·Rx(pitch)·Rz(−roll)`:
    ///
    /// * heading: yaw about the vertical +Y, right-handed (counter-clockwise
    ///   seen from above), 0 facing −Z; equal to φy when the body is level,
    ///   and taken on the branch nearest φy (continuous with it);
    /// * pitch: the forward axis above the horizontal (nose up positive),
    ///   in [−π/2, π/2];
    /// * roll: about the forward axis, the right side (+x) down positive.
    pub fn attitude(&self) -> [f64; 3] {
        let r = self.rotation();
        // Forward f = Rot·(0, 0, −1), up u = Rot·(0, 1, 0), right l = Rot·(1, 0, 0).
        let f = [-r[(0, 2)], -r[(1, 2)], -r[(2, 2)]];
        let pitch = f[1].clamp(-1.0, 1.0).asin();
        let heading = (-f[0]).atan2(-f[2]);
        let tau = std::f64::consts::TAU;
        let heading = heading + tau * ((self.phi.y - heading) / tau).round();
        let roll = (-r[(1, 0)]).atan2(r[(1, 1)]);
        [roll, pitch, heading]
    }

    /// A body-frame point in the inertial frame: `R + Rot·p`.
    pub fn to_inertial(&self, p_body: &Vector3<f64>) -> Vector3<f64> {
        self.position + self.rotation() * p_body
    }

    /// An inertial point in the body frame: `Rotᵀ·(p − R)`.
    pub fn to_body(&self, p_inertial: &Vector3<f64>) -> Vector3<f64> {
        self.rotation().transpose() * (p_inertial - self.position)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attitude_recomposes_the_rotation() {
        // Rot = Ry(heading)·Rx(pitch)·Rz(−roll) for every pose sampled.
        for (i, phi) in [
            [0.0, 0.0, 0.0],
            [0.1, -0.4, 0.2],
            [-0.3, 2.9, -0.25],
            [0.05, 7.0, 0.061],
        ]
        .into_iter()
        .enumerate()
        {
            let p = BodyPose::new([0.0; 3], phi);
            let [roll, pitch, heading] = p.attitude();
            let m = rot_y(heading) * rot_x(pitch) * rot_z(-roll);
            assert!((m - p.rotation()).norm() < 1e-12, "pose {i}");
            assert!(
                (heading - phi[1]).abs() < std::f64::consts::PI,
                "branch {i}"
            );
        }
        // Level: heading is φy; a nose-up tilt about the right axis is pitch.
        let level = BodyPose::new([0.0; 3], [0.0, 0.7, 0.0]).attitude();
        assert!((level[2] - 0.7).abs() < 1e-15 && level[0] == 0.0);
        let nose_up = BodyPose::new([0.0; 3], [0.06, 0.0, 0.0]).attitude();
        assert!((nose_up[1] - 0.06).abs() < 1e-15 && nose_up[0].abs() < 1e-15);
    }

    #[test]
    fn closed_form_matches_product() {
        let p = BodyPose::new([0.1, 0.2, 0.3], [0.4, -0.9, 1.3]);
        let want = rot_x(p.phi.x) * rot_z(p.phi.z) * rot_y(p.phi.y);
        assert!((p.rotation() - want).norm() < 1e-15);
    }

    #[test]
    fn right_handed_elementary_rotations() {
        let q = std::f64::consts::FRAC_PI_2;
        let (ex, ey, ez) = (Vector3::x(), Vector3::y(), Vector3::z());
        assert!((rot_x(q) * ey - ez).norm() < 1e-15);
        assert!((rot_y(q) * ez - ex).norm() < 1e-15);
        assert!((rot_z(q) * ex - ey).norm() < 1e-15);
    }

    #[test]
    fn round_trip() {
        let p = BodyPose::new([0.1, 0.2, 0.3], [0.4, -0.9, 1.3]);
        let x = Vector3::new(-0.3, 0.8, 0.05);
        assert!((p.to_body(&p.to_inertial(&x)) - x).norm() < 1e-14);
    }
}
