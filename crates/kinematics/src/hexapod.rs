//! 24-DOF forward kinematics of the hexapod (paper §3.1, docs/reference.md),
//! every auxiliary point and rotation versor, into a reusable workspace.
//!
//! The model ([`HexapodModel`]) is immutable; [`forward`] fills a
//! [`HexapodData`] without allocating and computes each sine/cosine once
//! (3 pairs for the body, 3 per leg: 21 in all).
//!
//! # How the chain is expanded
//!
//! With `Rot` the body rotation (columns `e_x, e_y, e_z`: the body axes in
//! the inertial frame), `C_γ` the rotation of eq. (5) and the leg expansion
//! of [`crate::leg`], the chain `R + Rot·cA0i·0A1·1A2·2A3` collapses to
//!
//! ```text
//! hip   = R + d·(cosγ·e_x − sinγ·e_z)
//! u     = Rot·C_γ·(cosθ1, sinθ1, 0) = −cos(γ+θ1)·e_x + sin(γ+θ1)·e_z
//! knee  = hip  − a·cosθ2·u − a·sinθ2·e_y
//! tip   = knee + c·cos(θ2+θ3)·u + c·sin(θ2+θ3)·e_y
//! ```
//!
//! `u` is the horizontal (in the body) direction of the leg's vertical plane,
//! pointing towards the body at θ2 = 0 (the upper link then points along
//! `−u`, outward, as docs/reference.md says).
//!
//! # Rotation versors (paper §5.2)
//!
//! The paper projects each body's moment on its "rotation versor", the D-H
//! `Z` axis of the joint frame about which the body turns, expressed in the
//! inertial frame. This module stores:
//!
//! * [`LegData::hip_axis`] — `z0` of the leg base frame, the θ1 axis. By eq.
//!   (5) it is the body's `+y` (vertical) axis, `Rot·(0,1,0)`, the same for
//!   every leg.
//! * [`LegData::upper_versor`] — `z1`, the θ2 axis: the versor of the upper
//!   link. `z1 = Rot·C_γ·(sinθ1, −cosθ1, 0) = −sin(γ+θ1)·e_x − cos(γ+θ1)·e_z`.
//! * [`LegData::lower_versor`] — `z2`, the θ3 axis: the versor of the lower
//!   link. `1A2` rotates about `z1`, so `z2 = z1` always; it is stored
//!   separately so that callers index bodies uniformly.
//! * [`HexapodData::body_versor`] — the central body's **body `z` axis**,
//!   `Rot·(0,0,1)`. Chosen because it is the axis the planar model rotates
//!   about (`φz`): restricted to the plane it is the inertial `+Z`, exactly
//!   the paper's `vers_cp`, while the body `y` axis (the θ1 axis) would be
//!   perpendicular to the plane's rotation. A free 3D body has no single
//!   rotation axis, so the whole frame is kept too: [`HexapodData::rotation`]
//!   (columns = body axes) and [`HexapodData::phi_axes`] (the inertial axes
//!   about which `φx, φy, φz` turn, i.e. `ω = Σ phi_axes[k]·φ̇_k`).
//!
//! Check in the plane: leg 4 (γ = 0, θ1 = 0) has `z1 = −Z`, leg 3 (γ = 180°)
//! has `z1 = +Z`, matching paper §5.2 and docs/reference.md.
//!
//! # Generalised coordinates
//!
//! `q = (Rx, Ry, Rz, φx, φy, φz, θ1₁, θ2₁, θ3₁, …, θ1₆, θ2₆, θ3₆)`, see
//! [`HexapodConfig::from_q`] and [`joint_index`].

use nalgebra::{Matrix3, SMatrix, Vector3};

use crate::body::{GAMMA_DEG, LEG_COUNT, LegMount, hip_distance};
use crate::leg::LegGeometry;
use crate::leg_jacobian::LegTrig;
use crate::planar::PlanarGeometry;
use crate::pose::BodyPose;

/// Number of generalised coordinates of the hexapod.
pub const NQ: usize = 24;
/// Index of `Rx` in `q` (`Ry`, `Rz` follow).
pub const POSITION: usize = 0;
/// Index of `φx` in `q` (`φy`, `φz` follow).
pub const PHI: usize = 3;

/// Index in `q` of joint `joint` (0 = θ1, 1 = θ2, 2 = θ3) of the leg with
/// array index `leg` (0–5, i.e. leg number − 1).
pub const fn joint_index(leg: usize, joint: usize) -> usize {
    6 + 3 * leg + joint
}

/// Immutable geometry of the hexapod: hexagonal body of side `L`, six alike
/// legs, centres of mass of the links.
#[derive(Clone, Debug, PartialEq)]
pub struct HexapodModel {
    side: f64,
    leg: LegGeometry,
    upper_com: f64,
    lower_com: f64,
    mounts: [LegMount; LEG_COUNT],
}

impl Default for HexapodModel {
    /// The paper's robot (docs/reference.md test-vector geometry):
    /// * `side` `L = 0.25` m (so `d = 0.25·cos 30°`),
    /// * `leg` `a = 0.2` m, `c = 0.42` m,
    /// * `upper_com = lower_com = 0.5` (centres of mass at mid-link).
    fn default() -> Self {
        Self::new(0.25, LegGeometry::default(), 0.5, 0.5)
    }
}

impl HexapodModel {
    /// A model with body side `side` (`L`, m), leg link lengths `leg`, and
    /// link centres of mass at fractions `upper_com` (of `a`, from the hip)
    /// and `lower_com` (of `c`, from the knee).
    pub fn new(side: f64, leg: LegGeometry, upper_com: f64, lower_com: f64) -> Self {
        let d = hip_distance(side);
        let mounts = GAMMA_DEG.map(|g| LegMount::new(g.to_radians(), d));
        Self {
            side,
            leg,
            upper_com,
            lower_com,
            mounts,
        }
    }

    /// Side `L` of the hexagonal body (m).
    pub fn side(&self) -> f64 {
        self.side
    }

    /// `d = L·cos(π/6)` (m).
    pub fn d(&self) -> f64 {
        self.mounts[0].d
    }

    /// Link lengths of every leg.
    pub fn leg(&self) -> &LegGeometry {
        &self.leg
    }

    /// Upper link centre of mass, fraction of `a` from the hip.
    pub fn upper_com(&self) -> f64 {
        self.upper_com
    }

    /// Lower link centre of mass, fraction of `c` from the knee.
    pub fn lower_com(&self) -> f64 {
        self.lower_com
    }

    /// The mount (eq. 5) of the leg with array index `leg` (0–5).
    pub fn mount(&self, leg: usize) -> &LegMount {
        &self.mounts[leg]
    }

    /// The same geometry as the planar two-leg model of
    /// [`crate::planar`] (legs 3 and 4).
    pub fn planar_geometry(&self) -> PlanarGeometry {
        PlanarGeometry {
            d: self.d(),
            a: self.leg.a,
            c: self.leg.c,
            upper_com: self.upper_com,
            lower_com: self.lower_com,
        }
    }
}

/// A configuration of the 24 DOF: body pose and the joints of every leg.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HexapodConfig {
    /// The central body's pose.
    pub pose: BodyPose,
    /// `(θ1, θ2, θ3)` of each leg (rad), indexed by leg number − 1.
    pub joints: [[f64; 3]; LEG_COUNT],
}

impl Default for HexapodConfig {
    /// The zero configuration:
    /// * `pose`: [`BodyPose::default`] (body at the origin, no rotation),
    /// * `joints`: every `(θ1, θ2, θ3) = (0, 0, 0)` (upper link horizontal
    ///   and outward, lower link folded back along it — a reference, not a
    ///   stance).
    fn default() -> Self {
        Self {
            pose: BodyPose::default(),
            joints: [[0.0; 3]; LEG_COUNT],
        }
    }
}

impl HexapodConfig {
    /// From the generalised coordinates (layout in the module docs).
    pub fn from_q(q: &[f64; NQ]) -> Self {
        let mut joints = [[0.0; 3]; LEG_COUNT];
        for (i, j) in joints.iter_mut().enumerate() {
            j.copy_from_slice(&q[joint_index(i, 0)..joint_index(i, 0) + 3]);
        }
        Self {
            pose: BodyPose::new(
                [q[POSITION], q[POSITION + 1], q[POSITION + 2]],
                [q[PHI], q[PHI + 1], q[PHI + 2]],
            ),
            joints,
        }
    }

    /// To the generalised coordinates (layout in the module docs).
    pub fn to_q(&self) -> [f64; NQ] {
        let mut q = [0.0; NQ];
        q[POSITION..POSITION + 3].copy_from_slice(self.pose.position.as_slice());
        q[PHI..PHI + 3].copy_from_slice(self.pose.phi.as_slice());
        for (i, j) in self.joints.iter().enumerate() {
            q[joint_index(i, 0)..joint_index(i, 0) + 3].copy_from_slice(j);
        }
        q
    }
}

/// Inertial points and versors of one leg, filled by [`forward`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LegData {
    /// Hip: origin of the leg base frame 0 (m).
    pub hip: Vector3<f64>,
    /// Knee: `0A1·1A2·[0,0,0,1]ᵀ` (m).
    pub knee: Vector3<f64>,
    /// Tip (foot): `0A1·1A2·2A3·[0,0,0,1]ᵀ` (m).
    pub tip: Vector3<f64>,
    /// Upper link centre of mass, `hip + upper_com·(knee − hip)` (m).
    pub upper_com: Vector3<f64>,
    /// Lower link centre of mass, `knee + lower_com·(tip − knee)` (m).
    pub lower_com: Vector3<f64>,
    /// `z0`, the θ1 axis (unit; = body `+y`).
    pub hip_axis: Vector3<f64>,
    /// `z1`, the θ2 axis: the upper link's rotation versor (unit).
    pub upper_versor: Vector3<f64>,
    /// `z2`, the θ3 axis: the lower link's rotation versor (unit, = `z1`).
    pub lower_versor: Vector3<f64>,
}

impl Default for LegData {
    /// Every point and versor zero (filled by [`forward`]).
    fn default() -> Self {
        let z = Vector3::zeros();
        Self {
            hip: z,
            knee: z,
            tip: z,
            upper_com: z,
            lower_com: z,
            hip_axis: z,
            upper_versor: z,
            lower_versor: z,
        }
    }
}

/// Which point of a leg (for [`HexapodData::leg_point`] and Jacobians).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LegPoint {
    /// The hip (origin of frame 0).
    Hip,
    /// The knee.
    Knee,
    /// The tip (foot).
    Tip,
    /// The upper link's centre of mass.
    UpperCom,
    /// The lower link's centre of mass.
    LowerCom,
}

/// Workspace of [`forward`]: every inertial auxiliary point and versor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HexapodData {
    /// `Rot = Rx(φx)·Rz(φz)·Ry(φy)`, body → inertial; its columns are the
    /// body axes in the inertial frame.
    pub rotation: Matrix3<f64>,
    /// Central body centre of mass `R` (m).
    pub body_com: Vector3<f64>,
    /// The central body's rotation versor: body `z` axis, `Rot·(0,0,1)`
    /// (see the module docs for why).
    pub body_versor: Vector3<f64>,
    /// Inertial axes about which `φx`, `φy`, `φz` rotate the body:
    /// `(X, Rx·Rz·Y, Rx·Z)`, so the body's angular velocity is
    /// `ω = Σ_k phi_axes[k]·φ̇_k`.
    pub phi_axes: [Vector3<f64>; 3],
    /// Per-leg points and versors, indexed by leg number − 1.
    pub legs: [LegData; LEG_COUNT],
}

impl Default for HexapodData {
    /// A zeroed workspace, to be filled by [`forward`]:
    /// * `rotation`: zero matrix,
    /// * `body_com`, `body_versor`, `phi_axes`: zero vectors,
    /// * `legs`: [`LegData::default`] each.
    fn default() -> Self {
        Self {
            rotation: Matrix3::zeros(),
            body_com: Vector3::zeros(),
            body_versor: Vector3::zeros(),
            phi_axes: [Vector3::zeros(); 3],
            legs: [LegData::default(); LEG_COUNT],
        }
    }
}

impl HexapodData {
    /// A zeroed workspace (see [`HexapodData::default`]).
    pub fn new() -> Self {
        Self::default()
    }

    /// The inertial position of `point` of the leg with array index `leg`.
    pub fn leg_point(&self, leg: usize, point: LegPoint) -> Vector3<f64> {
        let l = &self.legs[leg];
        match point {
            LegPoint::Hip => l.hip,
            LegPoint::Knee => l.knee,
            LegPoint::Tip => l.tip,
            LegPoint::UpperCom => l.upper_com,
            LegPoint::LowerCom => l.lower_com,
        }
    }

    /// Analytic Jacobian of `point` of leg `leg` (array index) with respect
    /// to the 9 coordinates it depends on, columns
    /// `(Rx, Ry, Rz, φx, φy, φz, θ1, θ2, θ3)` of that leg; every other
    /// column of the 24-DOF Jacobian is zero. Call after [`forward`].
    ///
    /// Each revolute coordinate contributes `axis × (p − pivot)`: the φ's
    /// pivot on `R` about [`Self::phi_axes`], θ1 and θ2 on the hip about
    /// `z0` and `z1`, θ3 on the knee about `z2`.
    pub fn leg_point_jacobian(&self, leg: usize, point: LegPoint) -> SMatrix<f64, 3, 9> {
        let l = &self.legs[leg];
        let p = self.leg_point(leg, point);
        let mut j = SMatrix::<f64, 3, 9>::zeros();
        j.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&Matrix3::identity());
        let r = p - self.body_com;
        for k in 0..3 {
            j.set_column(3 + k, &self.phi_axes[k].cross(&r));
        }
        let (moves_t1, moves_t2, moves_t3) = match point {
            LegPoint::Hip => (false, false, false),
            LegPoint::Knee | LegPoint::UpperCom => (true, true, false),
            LegPoint::Tip | LegPoint::LowerCom => (true, true, true),
        };
        if moves_t1 {
            j.set_column(6, &l.hip_axis.cross(&(p - l.hip)));
        }
        if moves_t2 {
            j.set_column(7, &l.upper_versor.cross(&(p - l.hip)));
        }
        if moves_t3 {
            j.set_column(8, &l.lower_versor.cross(&(p - l.knee)));
        }
        j
    }

    /// Analytic `∂tip/∂(θ1, θ2, θ3)` of leg `leg` (array index) in the
    /// inertial frame (the last three columns of
    /// [`Self::leg_point_jacobian`]). Call after [`forward`].
    pub fn tip_joint_jacobian(&self, leg: usize) -> Matrix3<f64> {
        let l = &self.legs[leg];
        let (th, tk) = (l.tip - l.hip, l.tip - l.knee);
        Matrix3::from_columns(&[
            l.hip_axis.cross(&th),
            l.upper_versor.cross(&th),
            l.lower_versor.cross(&tk),
        ])
    }
}

/// Full 24-DOF forward kinematics: fills `data` with every inertial
/// auxiliary point and versor of configuration `cfg`. Allocation-free,
/// 21 `sin_cos` evaluations ([`forward_trig`] takes them precomputed).
#[inline]
pub fn forward(model: &HexapodModel, cfg: &HexapodConfig, data: &mut HexapodData) {
    let trig = cfg.joints.map(LegTrig::new);
    forward_trig(model, &cfg.pose, &cfg.pose.rotation(), &trig, data);
}

/// [`forward`] with the trigonometry precomputed: `rotation` is
/// `pose.rotation()` (e.g. kept from the body's motion) and `trig[i]` the
/// sines and cosines of leg i's joint angles (e.g. from the inverse
/// kinematics, [`crate::ik::leg_ik_trig`]): one `sin_cos` (of φx, for
/// [`HexapodData::phi_axes`]) instead of 21. With `pose.rotation()` and
/// [`LegTrig::new`] of the angles it is [`forward`], bit for bit.
#[inline]
pub fn forward_trig(
    model: &HexapodModel,
    pose: &BodyPose,
    rotation: &Matrix3<f64>,
    trig: &[LegTrig; LEG_COUNT],
    data: &mut HexapodData,
) {
    let (sx, cx) = pose.phi.x.sin_cos();
    // Rot = Rx(φx)·Rz(φz)·Ry(φy), by columns.
    let ex: Vector3<f64> = rotation.column(0).into();
    let ey: Vector3<f64> = rotation.column(1).into();
    let ez: Vector3<f64> = rotation.column(2).into();
    data.rotation = *rotation;
    let r = pose.position;
    data.body_com = r;
    data.body_versor = ez;
    data.phi_axes = [Vector3::x(), ey, Vector3::new(0.0, -sx, cx)];

    let (a, c) = (model.leg.a, model.leg.c);
    let (fu, fl) = (model.upper_com, model.lower_com);
    for ((out, m), t) in data.legs.iter_mut().zip(&model.mounts).zip(trig) {
        let (s1, c1, s2, c2, s23, c23) = (t.s1, t.c1, t.s2, t.c2, t.s23, t.c23);
        // cos(γ+θ1), sin(γ+θ1) by the addition formulas (γ's are constants).
        let cg = m.cos_gamma * c1 - m.sin_gamma * s1;
        let sg = m.sin_gamma * c1 + m.cos_gamma * s1;
        let hip = r + (m.d * m.cos_gamma) * ex - (m.d * m.sin_gamma) * ez;
        let u = sg * ez - cg * ex;
        let upper = (-a * c2) * u - (a * s2) * ey;
        let lower = (c * c23) * u + (c * s23) * ey;
        let knee = hip + upper;
        let tip = knee + lower;
        let z1 = -(sg * ex + cg * ez);
        *out = LegData {
            hip,
            knee,
            tip,
            upper_com: hip + fu * upper,
            lower_com: knee + fl * lower,
            hip_axis: ey,
            upper_versor: z1,
            lower_versor: z1,
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dh::{a01, a12, a23, body_to_leg_base, rotation_block};
    use crate::fd::{FdTolerance, check_jacobian};
    use nalgebra::{Matrix4, Vector4};

    fn sample() -> HexapodConfig {
        HexapodConfig {
            pose: BodyPose::new([0.1, 0.55, -0.2], [0.3, -0.7, 0.45]),
            joints: [
                [0.1, 0.2, 4.0],
                [-0.3, -0.1, 4.4],
                [0.5, 0.6, 3.9],
                [0.0, 0.0, 4.3],
                [-0.7, 0.3, 2.0],
                [1.1, -0.5, 4.7],
            ],
        }
    }

    /// The same chain by literal 4×4 products of eqs. (1)–(5).
    #[test]
    fn matches_matrix_chain() {
        let model = HexapodModel::new(0.3, LegGeometry { a: 0.25, c: 0.5 }, 0.4, 0.7);
        let cfg = sample();
        let mut d = HexapodData::new();
        forward(&model, &cfg, &mut d);
        let mut ic = Matrix4::identity();
        ic.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&cfg.pose.rotation());
        ic.fixed_view_mut::<3, 1>(0, 3)
            .copy_from(&cfg.pose.position);
        let o = Vector4::new(0.0, 0.0, 0.0, 1.0);
        for (i, th) in cfg.joints.iter().enumerate() {
            let m = model.mount(i);
            let t0 = ic * body_to_leg_base(m.gamma, m.d);
            let t1 = t0 * a01(th[0]);
            let t2 = t1 * a12(th[1], 0.25);
            let t3 = t2 * a23(th[2], 0.5);
            let l = &d.legs[i];
            let close = |a: Vector3<f64>, b: Vector4<f64>| (a - b.xyz()).norm() < 1e-14;
            assert!(close(l.hip, t0 * o) && close(l.knee, t2 * o) && close(l.tip, t3 * o));
            let z = |t: &Matrix4<f64>| rotation_block(t).column(2).into_owned();
            assert!((l.hip_axis - z(&t0)).norm() < 1e-14);
            assert!((l.upper_versor - z(&t1)).norm() < 1e-14);
            assert!((l.lower_versor - z(&t2)).norm() < 1e-14);
            let uc = l.hip + 0.4 * (l.knee - l.hip);
            let lc = l.knee + 0.7 * (l.tip - l.knee);
            assert!((l.upper_com - uc).norm() < 1e-14 && (l.lower_com - lc).norm() < 1e-14);
        }
        assert!((d.rotation - cfg.pose.rotation()).norm() < 1e-15);
    }

    #[test]
    fn point_jacobians_match_finite_differences() {
        let model = HexapodModel::default();
        let q = sample().to_q();
        let mut d = HexapodData::new();
        forward(&model, &HexapodConfig::from_q(&q), &mut d);
        let points = [
            LegPoint::Hip,
            LegPoint::Knee,
            LegPoint::Tip,
            LegPoint::UpperCom,
            LegPoint::LowerCom,
        ];
        for leg in 0..LEG_COUNT {
            for &pt in &points {
                let j = d.leg_point_jacobian(leg, pt);
                let mut w = HexapodData::new();
                check_jacobian(
                    &q,
                    3,
                    |x, out| {
                        forward(
                            &model,
                            &HexapodConfig::from_q(x.try_into().unwrap()),
                            &mut w,
                        );
                        out.copy_from_slice(w.leg_point(leg, pt).as_slice());
                    },
                    |i, k| match k {
                        0..6 => j[(i, k)],
                        _ if (joint_index(leg, 0)..joint_index(leg, 0) + 3).contains(&k) => {
                            j[(i, 6 + k - joint_index(leg, 0))]
                        }
                        _ => 0.0,
                    },
                    FdTolerance::default(),
                )
                .unwrap_or_else(|e| panic!("leg {} {pt:?}: {e}", leg + 1));
            }
            let tj = d.tip_joint_jacobian(leg);
            let full = d.leg_point_jacobian(leg, LegPoint::Tip);
            assert!((tj - full.fixed_view::<3, 3>(0, 6)).norm() < 1e-15);
        }
    }

    #[test]
    fn forward_trig_is_forward() {
        let (model, cfg) = (HexapodModel::default(), sample());
        let mut want = HexapodData::new();
        forward(&model, &cfg, &mut want);
        // With the angles' own trigonometry: bit for bit.
        let mut got = HexapodData::new();
        let trig = cfg.joints.map(LegTrig::new);
        forward_trig(&model, &cfg.pose, &cfg.pose.rotation(), &trig, &mut got);
        assert_eq!(got, want);
        // With the inverse kinematics' sines and cosines: to round-off.
        let trig: [LegTrig; LEG_COUNT] = std::array::from_fn(|i| {
            let p0 = model
                .mount(i)
                .body_to_base(&cfg.pose.to_body(&want.legs[i].tip));
            let branch = crate::ik::KneeBranch::of(cfg.joints[i][2]);
            crate::ik::leg_ik_trig(model.leg(), &p0, branch).unwrap().1
        });
        forward_trig(&model, &cfg.pose, &cfg.pose.rotation(), &trig, &mut got);
        for (g, w) in got.legs.iter().zip(&want.legs) {
            assert!((g.tip - w.tip).norm() < 1e-14, "{:?} vs {:?}", g.tip, w.tip);
            assert!((g.knee - w.knee).norm() < 1e-14);
        }
    }

    #[test]
    fn q_round_trip() {
        let cfg = sample();
        assert_eq!(HexapodConfig::from_q(&cfg.to_q()), cfg);
    }
}
