//! Where a swinging foot lands.
//!
//! Each leg has a neutral foot position: the horizontal offset of its
//! initial foot from the initial body centre, in the heading frame. Swing
//! `k` of leg `i` lands where that offset, carried by the planned planar
//! body path, will be at the *middle of the following stance*
//! ([`super::schedule::mid_stance_time`]); the foot is put on the terrain
//! there (`y = ϱ(x, z)`). With a steady twist the stance then sweeps
//! symmetrically about the neutral position, half a stride ahead of it at
//! touchdown and half behind at lift-off.

use fbd_contact::Surface;
use fbd_kinematics::nalgebra::Vector3;

use super::body::BodyPlan;
use super::params::GaitParams;
use super::schedule::mid_stance_time;

/// The foothold of swing `k` of leg `leg`, whose neutral horizontal offset
/// in the initial heading frame is `neutral = (dx, dz)` (m).
#[inline]
pub fn foothold(
    params: &GaitParams,
    plan: &BodyPlan,
    surface: &Surface,
    psi0: f64,
    neutral: [f64; 2],
    leg: usize,
    k: usize,
) -> Vector3<f64> {
    let pl = plan.planar_at(mid_stance_time(params, leg, k));
    let (s, c) = (pl.q[2] - psi0).sin_cos();
    // Ry(Δψ) on the horizontal offset: x' = c·x + s·z, z' = −s·x + c·z.
    let x = pl.q[0] + c * neutral[0] + s * neutral[1];
    let z = pl.q[1] - s * neutral[0] + c * neutral[1];
    let y = if surface.exists() {
        surface.height(x, z)
    } else {
        0.0
    };
    Vector3::new(x, y, z)
}
