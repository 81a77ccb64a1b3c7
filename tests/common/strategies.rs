//! Bounded, physical proptest strategies: the one place tests draw random
//! configurations from.
//!
//! Bounds (SI units, radians):
//! * link lengths and the body side: 0.05–1 m;
//! * centre-of-mass fractions: 0–1;
//! * body position: each coordinate within ±2 m;
//! * body angles: |φ| < 60° each;
//! * joints: θ1 ∈ [−60°, 60°], θ2 ∈ [−90°, 90°], θ3 ∈ [0°, 360°).

use std::f64::consts::{FRAC_PI_2, FRAC_PI_3, TAU};

use fbd_kinematics::hexapod::{HexapodConfig, HexapodModel};
use fbd_kinematics::leg::LegGeometry;
use fbd_kinematics::planar::{NQ as PLANAR_NQ, PlanarGeometry};
use fbd_kinematics::pose::BodyPose;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

/// Largest |coordinate| of a random position (m).
pub const MAX_POSITION: f64 = 2.0;
/// Largest |φ| of a random body angle (rad): just under 60°.
pub const MAX_BODY_ANGLE: f64 = FRAC_PI_3 * 0.999;
/// Link lengths and body side lie in `LENGTH_RANGE` (m).
pub const LENGTH_RANGE: std::ops::RangeInclusive<f64> = 0.05..=1.0;

/// A reproducible proptest configuration: `cases` cases from a fixed seed,
/// no failure-persistence files.
pub fn fixed_config(cases: u32, seed: u64) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(seed),
        failure_persistence: None,
        ..Config::default()
    }
}

/// A link length or body side, 0.05–1 m.
pub fn length() -> impl Strategy<Value = f64> {
    LENGTH_RANGE
}

/// A centre-of-mass fraction along a link, 0–1.
pub fn com_fraction() -> impl Strategy<Value = f64> {
    0.0..=1.0f64
}

/// Leg link lengths `a`, `c`, each 0.05–1 m.
pub fn leg_geometry() -> impl Strategy<Value = LegGeometry> {
    (length(), length()).prop_map(|(a, c)| LegGeometry { a, c })
}

/// A hexapod: side 0.05–1 m, legs as [`leg_geometry`], any com fractions.
pub fn hexapod_model() -> impl Strategy<Value = HexapodModel> {
    (length(), leg_geometry(), com_fraction(), com_fraction())
        .prop_map(|(side, leg, u, l)| HexapodModel::new(side, leg, u, l))
}

/// A position with every coordinate within ±2 m.
pub fn position() -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(-MAX_POSITION..=MAX_POSITION)
}

/// A body angle, |φ| < 60°.
pub fn body_angle() -> impl Strategy<Value = f64> {
    -MAX_BODY_ANGLE..=MAX_BODY_ANGLE
}

/// A body pose: position within ±2 m, every |φ| < 60°.
pub fn body_pose() -> impl Strategy<Value = BodyPose> {
    (position(), prop::array::uniform3(body_angle())).prop_map(|(p, phi)| BodyPose::new(p, phi))
}

/// θ1 ∈ [−60°, 60°].
pub fn theta1() -> impl Strategy<Value = f64> {
    -FRAC_PI_3..=FRAC_PI_3
}

/// θ2 ∈ [−90°, 90°].
pub fn theta2() -> impl Strategy<Value = f64> {
    -FRAC_PI_2..=FRAC_PI_2
}

/// θ3 ∈ [0°, 360°).
pub fn theta3() -> impl Strategy<Value = f64> {
    0.0..TAU
}

/// `(θ1, θ2, θ3)` of one leg in the physical ranges above.
pub fn joint_angles() -> impl Strategy<Value = [f64; 3]> {
    (theta1(), theta2(), theta3()).prop_map(|(a, b, c)| [a, b, c])
}

/// A full 24-DOF configuration: [`body_pose`] and six [`joint_angles`].
pub fn hexapod_config() -> impl Strategy<Value = HexapodConfig> {
    (body_pose(), prop::array::uniform6(joint_angles()))
        .prop_map(|(pose, joints)| HexapodConfig { pose, joints })
}

/// The planar model's geometry: `d` from a side of 0.05–1 m, `a`, `c`
/// 0.05–1 m, any com fractions.
pub fn planar_geometry() -> impl Strategy<Value = PlanarGeometry> {
    (length(), leg_geometry(), com_fraction(), com_fraction()).prop_map(|(side, leg, u, l)| {
        PlanarGeometry {
            d: fbd_kinematics::body::hip_distance(side),
            a: leg.a,
            c: leg.c,
            upper_com: u,
            lower_com: l,
        }
    })
}

/// Planar `q = (Rx, Ry, φz, θ2₃, θ3₃, θ2₄, θ3₄)`: positions within ±2 m,
/// |φz| < 60°, θ2 ∈ [−90°, 90°], θ3 ∈ [0°, 360°).
pub fn planar_q() -> impl Strategy<Value = [f64; PLANAR_NQ]> {
    (
        -MAX_POSITION..=MAX_POSITION,
        -MAX_POSITION..=MAX_POSITION,
        body_angle(),
        theta2(),
        theta3(),
        theta2(),
        theta3(),
    )
        .prop_map(|(x, y, p, a, b, c, d)| [x, y, p, a, b, c, d])
}

/// Gait parameters of a walk the paper's robot can reach from the default
/// stance ([`fbd_sim::gait::InitialPose::default`]): a preset kind, period
/// 0.8–1.2 s, forward ±0.08 m/s, lateral ±0.03 m/s, yaw ±10°/s, swing
/// height 2–8 cm, body height ±2 cm, roll and pitch ±4°, sway 0–1.5 cm,
/// ramp 0–1 s.
pub fn gait_params() -> impl Strategy<Value = fbd_sim::gait::GaitParams> {
    use fbd_sim::gait::{Command, GaitKind, GaitParams};
    let kind = prop_oneof![
        Just(GaitKind::Tripod),
        Just(GaitKind::Ripple),
        Just(GaitKind::Wave)
    ];
    (
        kind,
        0.8..1.2f64,
        (-0.08..0.08f64, -0.03..0.03f64, -10.0..10.0f64),
        (0.02..0.08f64, -0.02..0.02f64),
        (-4.0..4.0f64, -4.0..4.0f64, 0.0..0.015f64, 0.0..1.0f64),
    )
        .prop_map(
            |(kind, period, (fwd, lat, yaw), (swing, height), (roll, pitch, sway, ramp))| {
                GaitParams {
                    period,
                    forward: Command::Constant(fwd),
                    lateral: Command::Constant(lat),
                    yaw_rate: Command::Constant(yaw.to_radians()),
                    swing_height: swing,
                    height,
                    roll: roll.to_radians(),
                    pitch: pitch.to_radians(),
                    sway,
                    ramp,
                    ..GaitParams::preset(kind)
                }
            },
        )
}

/// A throw of the PD-held 3D stance onto the ground (tests of sliding
/// friction): the body's horizontal velocity (direction any, 0.05–1.5 m/s),
/// its spin about the vertical (±3 rad/s), the drop (0–3 cm), the body's
/// mass (3–12 kg: the normal loads), μD (0.1–0.6) and μS/μD (1–1.5).
#[derive(Clone, Copy, Debug)]
pub struct SlideThrow {
    pub heading: f64,
    pub speed: f64,
    pub spin: f64,
    pub drop: f64,
    pub body_mass: f64,
    pub mu_dynamic: f64,
    pub mu_ratio: f64,
}

/// A [`SlideThrow`] within the bounds above.
#[allow(dead_code)]
pub fn slide_throw() -> impl Strategy<Value = SlideThrow> {
    (
        0.0..TAU,
        0.05..1.5f64,
        -3.0..3.0f64,
        0.0..0.03f64,
        3.0..12.0f64,
        0.1..0.6f64,
        1.0..1.5f64,
    )
        .prop_map(
            |(heading, speed, spin, drop, body_mass, mu_dynamic, mu_ratio)| SlideThrow {
                heading,
                speed,
                spin,
                drop,
                body_mass,
                mu_dynamic,
                mu_ratio,
            },
        )
}
