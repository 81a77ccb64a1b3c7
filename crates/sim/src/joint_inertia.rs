//! The effective inertia that the joint controller drives, at one pose:
//! the inertia of the stability rule of the explicit joint torques
//! (`rules::pd_stability`, documented in docs/reference.md, `[control]`).
//!
//! Every joint has the same gains, so the linearised closed loop of the
//! free (flying) robot, `M(q)·q̈ = −kp·Sᵀ·S·q − kd·Sᵀ·S·q̇` (`M` the mass
//! matrix in the generalised coordinates, `S` the selection of the joint
//! angles), falls apart into independent modes: the eigenvectors of the
//! joint block `S·M⁻¹·Sᵀ` of the inverse mass matrix. A mode of
//! eigenvalue `μ` is one joint of inertia `1/μ` under `kp` and `kd`, so
//! the binding inertia is `1/μ_max`, the smallest of the modes.
//!
//! It is much smaller than any one link's inertia about its joint: hip
//! and knee turning in opposite directions swing the light upper link
//! while the heavy lower link mostly translates. On the default planar
//! robot in flight it is 0.0103 kg·m² at θ3 = 250° and 0.0025 kg·m² with
//! the legs straight (θ3 = 180°), and 0.026 kg·m² at θ3 = 250° standing on
//! both feet, against 0.125 kg·m² for the lower link about the knee.
//!
//! A robot with feet on the ground has constraints `G·q̈ = …` and the
//! inverse inertia `M⁻¹ − M⁻¹Gᵀ(G·M⁻¹Gᵀ)⁺G·M⁻¹ ≤ M⁻¹`: its modes are
//! slower, the free robot's the fastest. The rule takes the feet that the
//! configuration stands on (every foot for `pd` and `trajectory`, the
//! stance feet of each step for `gait`, none without ground): with the
//! free robot's modes the shipped standing examples, stable in practice,
//! would be refused (the planar PD stand, kd = 10 at Δt = 2 ms: limit
//! 7.3 N·m·s/rad in flight, 23.2 standing), and with every foot down the
//! walk's swinging legs would be missed. On `examples/hexapod_walk.toml`
//! the rule allows kd < 19.74 N·m·s/rad; the walk runs with kd = 20 and
//! blows up with kd = 22.

use fbd_dynamics::spatial::so3::hat;
use fbd_dynamics::spatial::{SpatialKin, SpatialMechanism, lower_body, upper_body};
use fbd_dynamics::tree::kin::TreeKin;
use fbd_dynamics::{Mechanism, PointKind};
use fbd_kinematics::nalgebra::{DMatrix, Matrix3, Matrix3x6, Matrix6, SMatrix, Vector3};
use fbd_robot::RobotModel;

/// The mass matrix `M(q)` (kinetic energy `½·q̇ᵀ·M·q̇`) of the planar
/// model at `q`.
pub fn planar_mass_matrix(mech: &Mechanism, q: &[f64]) -> DMatrix<f64> {
    let chains = &mech.chains;
    let nq = chains.nq;
    let mut kin = chains.new_data();
    chains.eval_positions(q, &mut kin);
    chains.eval_jacobians(&mut kin);
    let mut m = DMatrix::zeros(nq, nq);
    for b in &mech.bodies {
        let angle = &chains.angles[b.angle];
        for i in 0..nq {
            for j in 0..nq {
                let v: f64 = (0..2)
                    .map(|axis| kin.jac_at(b.com, axis, i) * kin.jac_at(b.com, axis, j))
                    .sum();
                m[(i, j)] += b.mass * v + b.inertia * angle.coefficient(i) * angle.coefficient(j);
            }
        }
    }
    m
}

/// The mass matrix `M(q)` of the spatial model at `q`: every body's
/// `m·Jcᵀ·Jc + Jωᵀ·(R·I·Rᵀ)·Jω`.
pub fn spatial_mass_matrix(mech: &SpatialMechanism, q: &[f64]) -> DMatrix<f64> {
    let nq = mech.layout().nq;
    let mut kin = SpatialKin::new(mech);
    kin.eval(mech, q);
    let mut m = DMatrix::zeros(nq, nq);
    for (b, body) in mech.bodies.iter().enumerate() {
        let jc = kin.com_jacobian(mech, b);
        let jw = kin.angular_jacobian(mech, b);
        let r = kin.rot[b];
        let inertia: Matrix3<f64> = r * body.inertia * r.transpose();
        for (i, ci) in jc.iter() {
            for (j, cj) in jc.iter() {
                m[(*i, *j)] += body.mass * ci.dot(cj);
            }
        }
        for (i, wi) in jw.iter() {
            for (j, wj) in jw.iter() {
                m[(*i, *j)] += wi.dot(&(inertia * wj));
            }
        }
    }
    m
}

/// The Jacobian `∂p/∂q` of the feet of the planar model (2 rows per foot,
/// feet in the order of `index.tip`): the constraints of the feet on the
/// ground.
pub fn planar_feet_jacobian(mech: &Mechanism, tips: &[usize], q: &[f64]) -> DMatrix<f64> {
    let chains = &mech.chains;
    let mut kin = chains.new_data();
    chains.eval_positions(q, &mut kin);
    chains.eval_jacobians(&mut kin);
    DMatrix::from_fn(2 * tips.len(), chains.nq, |r, i| {
        kin.jac_at(tips[r / 2], r % 2, i)
    })
}

/// The Jacobian of the feet of the legs in `slots` of the spatial model
/// (3 rows per foot).
pub fn spatial_feet_jacobian(mech: &SpatialMechanism, slots: &[usize], q: &[f64]) -> DMatrix<f64> {
    let mut kin = SpatialKin::new(mech);
    kin.eval(mech, q);
    let mut g = DMatrix::zeros(3 * slots.len(), mech.layout().nq);
    for (r, &s) in slots.iter().enumerate() {
        for (i, c) in kin.contact_jacobian(mech, s, PointKind::Tip).iter() {
            for a in 0..3 {
                g[(3 * r + a, *i)] += c[a];
            }
        }
    }
    g
}

/// The fastest mode of the joints at one pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointMode {
    /// Its effective inertia `1/μ_max` (kg·m²).
    pub inertia: f64,
    /// The position in `joints` of the joint that moves most in it.
    pub joint: usize,
}

/// The smallest effective joint inertia of mass matrix `m` under the
/// constraints `g·q̈ = …` (rows of `g`; none for the free robot), the
/// joint angles at `joints` (indices into `q`): `1/μ_max` of the joint
/// block of `M⁻¹ − M⁻¹Gᵀ(G·M⁻¹Gᵀ)⁺G·M⁻¹`.
///
/// # Panics
/// When `m` is not symmetric positive definite (a mechanism's mass matrix
/// with positive masses and inertias always is).
pub fn fastest_mode(m: &DMatrix<f64>, g: &DMatrix<f64>, joints: &[usize]) -> JointMode {
    let n = m.nrows();
    assert_eq!(g.ncols(), n, "one constraint column per coordinate");
    let chol = m
        .clone()
        .cholesky()
        .expect("a mass matrix is positive definite");
    let mut minv = chol.inverse();
    if g.nrows() > 0 {
        let gm = g * &minv;
        // Redundant constraints (a singular G·M⁻¹Gᵀ) are harmless: the
        // pseudo-inverse projects on the constrained directions.
        let s = (&gm * g.transpose())
            .pseudo_inverse(1e-12)
            .expect("the tolerance is not negative");
        minv -= gm.transpose() * s * &gm;
    }
    let block = DMatrix::from_fn(joints.len(), joints.len(), |r, c| {
        0.5 * (minv[(joints[r], joints[c])] + minv[(joints[c], joints[r])])
    });
    let eig = block.symmetric_eigen();
    let top = eig.eigenvalues.imax();
    let v = eig.eigenvectors.column(top);
    JointMode {
        inertia: 1.0 / eig.eigenvalues[top],
        joint: v.iamax(),
    }
}

/// Whether every joint mode of the spatial model at `q`, with the tips of
/// the slots `standing` on the ground, is slower than a joint of inertia
/// `inertia`: whether the smallest effective joint inertia of
/// [`fastest_mode`] (on [`spatial_mass_matrix`] and
/// [`spatial_feet_jacobian`]) exceeds `inertia`, decided without an
/// eigenvalue. `None` when a standing leg is at (or near) a singular pose,
/// where only [`fastest_mode`] decides.
///
/// `1/μ_max > I` for the joint block `P` of the constrained inverse
/// inertia if and only if the kinetic energy beats `I`'s on every motion
/// the feet allow: `q̇ᵀ·M·q̇ > I·|S·q̇|²` for every `q̇ ≠ 0` with `G·q̇ = 0`,
/// i.e. `K = M − I·SᵀS` positive definite on the null space of `G`
/// (minimising `q̇ᵀMq̇` over the motions with given joint rates
/// `S·q̇ = y` leaves `yᵀP⁻¹y`). The central body's coordinates do not
/// matter (a change of them is a congruence): here its twist, `ω` and the
/// velocity `v` of its centre of mass, so that `M` is the composite
/// rigid-body inertia (each leg coupled only with the central body). A
/// standing foot fixes its leg's rates by the twist
/// (`θ̇ = T·(ω, v)`, `T = −G_leg⁻¹·G_body`), so `K` is positive definite
/// if and only if every swinging leg's `3×3` block is, and the central
/// body's `6×6` block after eliminating every leg (Schur complements):
/// a few hundred flops and Cholesky factorisations of `3×3` and `6×6`
/// per pose.
///
/// `kin` is a workspace for `mech`.
pub fn spatial_modes_slower_than(
    mech: &SpatialMechanism,
    kin: &mut SpatialKin,
    q: &[f64],
    standing: &[usize],
    inertia: f64,
) -> Option<bool> {
    kin.eval(mech, q);
    let o = kin.fk.body_com;
    // The composite inertia about `o`: mass, first moment, rotational.
    let central = &mech.bodies[0];
    let mut mass = central.mass;
    let mut first = Vector3::zeros();
    let mut rot = world_inertia(kin.rot[0], &central.inertia);
    // Eliminated legs' energy on the twist (ω, v).
    let mut k_body = Matrix6::zeros();
    for s in 0..mech.legs.len() {
        let l = &kin.fk.legs[mech.legs[s] - 1];
        let axes = [l.hip_axis, l.upper_versor, l.lower_versor];
        let pivots = [l.hip, l.hip, l.knee];
        // Leg block, and its coupling with ω (rows 0–2) and v (rows 3–5).
        let mut m_leg = Matrix3::zeros();
        let mut m_bl = SMatrix::<f64, 6, 3>::zeros();
        for (b, depth) in [(upper_body(s), 2), (lower_body(s), 3)] {
            let body = &mech.bodies[b];
            let (m, c) = (body.mass, kin.com[b]);
            let r = c - o;
            let iw = world_inertia(kin.rot[b], &body.inertia);
            mass += m;
            first += m * r;
            rot += iw + m * (Matrix3::from_diagonal_element(r.norm_squared()) - r * r.transpose());
            let mut u = [Vector3::zeros(); 3];
            let mut iwa = [Vector3::zeros(); 3];
            for j in 0..depth {
                u[j] = axes[j].cross(&(c - pivots[j]));
                iwa[j] = iw * axes[j];
                let top = m * r.cross(&u[j]) + iwa[j];
                let bottom = m * u[j];
                for a in 0..3 {
                    m_bl[(a, j)] += top[a];
                    m_bl[(3 + a, j)] += bottom[a];
                }
                for k in 0..=j {
                    let v = m * u[j].dot(&u[k]) + axes[k].dot(&iwa[j]);
                    m_leg[(j, k)] += v;
                    if k != j {
                        m_leg[(k, j)] += v;
                    }
                }
            }
        }
        let k_leg = m_leg - Matrix3::identity() * inertia;
        if standing.contains(&s) {
            let p = l.tip;
            let g_leg = Matrix3::from_columns(&[
                axes[0].cross(&(p - pivots[0])),
                axes[1].cross(&(p - pivots[1])),
                axes[2].cross(&(p - pivots[2])),
            ]);
            let t = standing_rates(&g_leg, &(p - o))?;
            let c = m_bl * t;
            k_body += c + c.transpose() + t.transpose() * k_leg * t;
        } else {
            let Some(chol) = k_leg.cholesky() else {
                return Some(false);
            };
            k_body -= m_bl * chol.solve(&m_bl.transpose());
        }
    }
    let h = hat(&first);
    let mut k = Matrix6::zeros();
    k.fixed_view_mut::<3, 3>(0, 0).copy_from(&rot);
    k.fixed_view_mut::<3, 3>(0, 3).copy_from(&h);
    k.fixed_view_mut::<3, 3>(3, 0).copy_from(&h.transpose());
    k.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&(Matrix3::identity() * mass));
    k += k_body;
    let k = 0.5 * (k + k.transpose());
    Some(k.cholesky().is_some())
}

/// The rates `θ̇ = T·(ω, v)` of a leg whose foot stands still, its foot at
/// `r` from the point `o` whose velocity is `v`, the foot's velocity per
/// unit joint rate the columns of `g_leg`: from `v + ω × r + G_leg·θ̇ = 0`.
/// `None` near a singular leg, where the null space is ill-conditioned
/// (the eigenvalues decide; so do non-finite values).
fn standing_rates(g_leg: &Matrix3<f64>, r: &Vector3<f64>) -> Option<Matrix3x6<f64>> {
    let scale = g_leg.column(0).norm() * g_leg.column(1).norm() * g_leg.column(2).norm();
    let det = g_leg.determinant().abs();
    if !det.is_finite() || det <= 1e-6 * scale {
        return None;
    }
    let g_inv = g_leg.try_inverse()?;
    let mut t = Matrix3x6::zeros();
    t.fixed_view_mut::<3, 3>(0, 0).copy_from(&(g_inv * hat(r)));
    t.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-g_inv));
    Some(t)
}

/// `R·I·Rᵀ`: a body's inertia tensor in the inertial frame; for a link's
/// (`diag(a, t, t)`, symmetric about its axis, the first column `e` of
/// `R`) `t·1 + (a − t)·e·eᵀ`.
fn world_inertia(r: Matrix3<f64>, inertia: &Matrix3<f64>) -> Matrix3<f64> {
    let (a, t) = (inertia[(0, 0)], inertia[(1, 1)]);
    if inertia[(2, 2)] == t && *inertia == Matrix3::from_diagonal(&Vector3::new(a, t, t)) {
        let e = r.column(0);
        Matrix3::from_diagonal_element(t) + (a - t) * e * e.transpose()
    } else {
        r * inertia * r.transpose()
    }
}

/// The Jacobian of the contact points `standing` (indices into
/// `robot.contacts`) of any robot at `q` (3 rows per point): the
/// constraints of its feet on the ground (a sticking sphere does not roll:
/// its centre's velocity).
pub fn tree_feet_jacobian(robot: &RobotModel, standing: &[usize], q: &[f64]) -> DMatrix<f64> {
    let mut kin = TreeKin::new(robot);
    kin.eval(robot, q);
    let mut g = DMatrix::zeros(3 * standing.len(), q.len());
    for (r, &c) in standing.iter().enumerate() {
        kin.contact_jacobian(c).for_each(|i, v| {
            for a in 0..3 {
                g[(3 * r + a, i)] += v[a];
            }
        });
    }
    g
}

/// The workspace of [`tree_modes_slower_than`] for one robot.
#[derive(Clone, Debug)]
pub struct ModeWork {
    kin: TreeKin,
    stance: Vec<bool>,
    limbs: Vec<([usize; 3], usize)>,
    ia: Vec<Matrix6<f64>>,
}

impl ModeWork {
    /// A workspace for `robot`.
    pub fn new(robot: &RobotModel) -> Self {
        Self {
            kin: TreeKin::new(robot),
            stance: vec![false; robot.joints.len()],
            limbs: Vec::with_capacity(robot.contacts.len()),
            ia: vec![Matrix6::zeros(); robot.bodies.len()],
        }
    }
}

/// Body `b`'s kinetic energy as a quadratic form of a twist `(ω, v_o)`
/// (`v_o` the velocity of the inertial point at `o`): its 6×6 inertia
/// about `o` in the inertial frame.
fn inertia_about(robot: &RobotModel, kin: &TreeKin, b: usize, o: &Vector3<f64>) -> Matrix6<f64> {
    let body = &robot.bodies[b];
    let mut k = Matrix6::zeros();
    if body.mass == 0.0 {
        return k;
    }
    let m = body.mass;
    let r = kin.com[b] - o;
    let ic = world_inertia(kin.rotation[b], &body.inertia);
    let h = hat(&(m * r));
    k.fixed_view_mut::<3, 3>(0, 0).copy_from(
        &(ic + m * (Matrix3::from_diagonal_element(r.norm_squared()) - r * r.transpose())),
    );
    k.fixed_view_mut::<3, 3>(0, 3).copy_from(&h);
    k.fixed_view_mut::<3, 3>(3, 0).copy_from(&h.transpose());
    k.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&Matrix3::from_diagonal_element(m));
    k
}

/// Joint `j`'s twist per unit rate in the coordinates of
/// [`inertia_about`]: `(u, u × (o − p))`, `u` its axis through `p`.
fn joint_twist(kin: &TreeKin, j: usize, o: &Vector3<f64>) -> SMatrix<f64, 6, 1> {
    let u = kin.axis[j];
    let v = u.cross(&(o - kin.joint_origin[j]));
    SMatrix::<f64, 6, 1>::new(u.x, u.y, u.z, v.x, v.y, v.z)
}

/// [`spatial_modes_slower_than`] for any robot on the tree equations: the
/// same test (`K = M − I·SᵀS` positive definite on the motions the
/// standing points allow), decided along its tree by eliminations in the
/// twist coordinates `(ω, v_o)` of the root about its centre of mass `o`,
/// in which every body's twist is its parent's plus its joint's
/// ([`joint_twist`]):
///
/// * a joint whose subtree swings, children first: its pivot
///   `d = sᵀ·Ĩ·s − I` (`Ĩ` its child's inertia with the subtree's
///   eliminated) must be positive, and `Ĩ − (Ĩs)(Ĩs)ᵀ/d` adds to its
///   parent's;
/// * a limb standing on a contact point (a chain of three joints from the
///   root to the point's body, without branches): its rates follow from
///   the root's twist (`θ̇ = T·V`, `T = −G_leg⁻¹·G_root`, `G` the point's
///   velocity), and its energy, `M_rr + M_lrᵀT + TᵀM_lr + Tᵀ(M_ll − I)T`
///   from its composite inertias, adds to the root's;
/// * the root's 6×6 block must then be positive definite.
///
/// Some 100 flops per joint and a 6×6 Cholesky per pose, no allocation.
/// `None` when a standing limb is not such a chain or is near a singular
/// pose (the eigenvalues decide: [`fastest_mode`] on
/// [`crate::robot::mass_matrix`] and [`tree_feet_jacobian`]). `standing`
/// are indices into `robot.contacts`.
pub fn tree_modes_slower_than(
    robot: &RobotModel,
    work: &mut ModeWork,
    q: &[f64],
    standing: &[usize],
    inertia: f64,
) -> Option<bool> {
    let ModeWork {
        kin,
        stance,
        limbs,
        ia,
    } = work;
    kin.eval(robot, q);
    let o = kin.com[0];
    let nj = robot.joints.len();
    // The standing limbs' joints, root first.
    stance.fill(false);
    limbs.clear();
    for &c in standing {
        let mut chain = Vec::with_capacity(3);
        let mut j = robot.bodies[robot.contacts[c].body].joint;
        while let Some(k) = j {
            if chain.len() == 3 || stance[k] {
                return None;
            }
            chain.push(k);
            j = robot.bodies[robot.joints[k].parent].joint;
        }
        if chain.len() != 3 {
            return None;
        }
        chain.reverse();
        for &k in &chain {
            stance[k] = true;
        }
        limbs.push(([chain[0], chain[1], chain[2]], c));
    }
    // No branch off a standing limb: every child of one of its bodies is
    // its next joint's.
    for (j, joint) in robot.joints.iter().enumerate() {
        if !stance[j]
            && let Some(up) = robot.bodies[joint.parent].joint
            && stance[up]
        {
            return None;
        }
    }
    for (b, k) in ia.iter_mut().enumerate() {
        *k = inertia_about(robot, kin, b, &o);
    }
    // The swinging subtrees, children first.
    for j in (0..nj).rev() {
        if stance[j] {
            continue;
        }
        let (parent, child) = (robot.joints[j].parent, robot.joints[j].child);
        let s = joint_twist(kin, j, &o);
        let h = ia[child] * s;
        let d = s.dot(&h) - inertia;
        // A NaN pivot (a degenerate pose) is no proof of stability.
        if d.is_nan() || d <= 0.0 {
            return Some(false);
        }
        let add = ia[child] - h * h.transpose() / d;
        ia[parent] += add;
    }
    let mut k = ia[0];
    for &(chain, c) in limbs.iter() {
        let f = kin.contact_center[c];
        let s = chain.map(|j| joint_twist(kin, j, &o));
        let body = chain.map(|j| robot.joints[j].child);
        // Composite inertias below each joint.
        let ic2 = ia[body[2]];
        let ic1 = ia[body[1]] + ic2;
        let ic0 = ia[body[0]] + ic1;
        let ic = [ic0, ic1, ic2];
        let g_leg =
            Matrix3::from_columns(&chain.map(|j| kin.axis[j].cross(&(f - kin.joint_origin[j]))));
        let t = standing_rates(&g_leg, &(f - o))?;
        let mut m_lr = Matrix3x6::zeros();
        let mut m_ll = Matrix3::zeros();
        for a in 0..3 {
            m_lr.row_mut(a).copy_from(&(s[a].transpose() * ic[a]));
            for b in 0..3 {
                m_ll[(a, b)] = (s[a].transpose() * ic[a.max(b)] * s[b])[(0, 0)];
            }
        }
        let c = m_lr.transpose() * t;
        k += ic0 + c + c.transpose() + t.transpose() * (m_ll - Matrix3::identity() * inertia) * t;
    }
    let k = 0.5 * (k + k.transpose());
    Some(k.cholesky().is_some())
}

/// A set of poses of a robot for the stability rule of its joint
/// controller: `poses(visit)` calls `visit(q, standing)` on each pose in
/// order (the coordinates; the contact points standing on the ground,
/// indices into `robot.contacts`) until `visit` returns `false`.
pub type Poses<'a> = dyn Fn(&mut dyn FnMut(&[f64], &[usize]) -> bool) + 'a;

/// Whether every pose of `poses` has every joint mode slower than a joint
/// of inertia `inertia` ([`tree_modes_slower_than`]): `Some(false)` at
/// the first pose with a faster one, `None` when a pose is undecided
/// (a standing limb that is not a chain of three joints, or singular).
pub fn poses_slower_than(robot: &RobotModel, poses: &Poses<'_>, inertia: f64) -> Option<bool> {
    let mut work = ModeWork::new(robot);
    let mut verdict = Some(true);
    poses(
        &mut |q, standing| match tree_modes_slower_than(robot, &mut work, q, standing, inertia) {
            Some(true) => true,
            Some(false) => {
                verdict = Some(false);
                false
            }
            None => {
                verdict = None;
                true
            }
        },
    );
    verdict
}

/// The smallest effective joint inertia over the poses of `poses` and its
/// joint (an index into `robot.joints`), from the eigenvalues of each pose
/// ([`fastest_mode`] on [`crate::robot::mass_matrix`] under
/// [`tree_feet_jacobian`]); `(∞, 0)` without poses.
pub fn fastest_mode_over(robot: &RobotModel, poses: &Poses<'_>) -> (f64, usize) {
    let joints: Vec<usize> = (0..robot.joints.len())
        .map(|j| fbd_dynamics::tree::kin::BASE_DOF + j)
        .collect();
    let (mut inertia, mut joint) = (f64::INFINITY, 0);
    poses(&mut |q, standing| {
        let mode = fastest_mode(
            &crate::robot::mass_matrix(robot, q),
            &tree_feet_jacobian(robot, standing, q),
            &joints,
        );
        if mode.inertia < inertia {
            (inertia, joint) = (mode.inertia, mode.joint);
        }
        true
    });
    (inertia, joint)
}

/// Most times of a gait at which the stability rule evaluates the
/// effective inertia (evenly spread over the run).
pub(crate) const GAIT_POSES: usize = 200;

/// The stability rule of the explicit joint controller
/// ([`crate::rules::pd_stability`]) at the commanded poses `poses` of any
/// model on the tree equations: gains `kp`, `kd` (the largest of any
/// joint) must be stable at step `dt` on the smallest effective joint
/// inertia of every pose. [`poses_slower_than`] decides it without an
/// eigenvalue, its limit raised by a relative 1e-6 so that a pose within
/// round-off of it is left to the eigenvalues; when it does not pass,
/// `fastest` gives the smallest inertia and its joint (an index into
/// `robot.joints`: [`fastest_mode_over`], or a cached value of it), and
/// `name` names that joint in the error.
pub(crate) fn check_gains(
    robot: &RobotModel,
    poses: &Poses<'_>,
    (kp, kd, dt): (f64, f64, f64),
    fastest: impl FnOnce() -> (f64, usize),
    name: impl FnOnce(usize) -> String,
) -> Result<(), crate::SimError> {
    if robot.joints.is_empty() || (kp == 0.0 && kd == 0.0) {
        return Ok(());
    }
    let limit = crate::rules::pd_inertia_limit(kp, kd, dt) * (1.0 + 1e-6);
    if poses_slower_than(robot, poses, limit) == Some(true) {
        return Ok(());
    }
    let (inertia, joint) = fastest();
    crate::rules::pd_stability(kp, kd, inertia, dt, &name(joint))
}
