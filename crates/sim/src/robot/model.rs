//! The immutable model of a robot's run ([`RobotSim`]), validated from a
//! [`fbd_robot::RobotModel`] and [`RobotParams`].

use super::control::RobotControl;
use super::params::RobotParams;
use crate::SimError;
use crate::rules::{check, positive};
use fbd_contact::SpatialState;
use fbd_dynamics::tree::TreeMechanism;
use fbd_dynamics::tree::kin::{BASE_DOF, TreeKin};
use fbd_dynamics::{ContactSpec, PointKind};
use fbd_kinematics::nalgebra::DMatrix;
use fbd_robot::RobotModel;
use fbd_solver::NewtonParams;

/// Everything fixed during a robot's run.
#[derive(Clone, Debug)]
pub struct RobotSim {
    /// The parameters it was built from.
    pub params: RobotParams,
    /// The FBD mechanism: the robot's bodies, reactions, contact points
    /// (every point of the model on the ground, none in flight) and stops.
    pub mech: TreeMechanism,
    /// The contact points' identities for the generic step (name, FBD
    /// body; `leg` is the point's index + 1, `kind` tip).
    pub contact_specs: Vec<ContactSpec>,
    /// Each joint's effort limit (N·m), from the description.
    pub effort: Vec<Option<f64>>,
    /// Newton tolerances (the hexapod's).
    pub newton: NewtonParams,
    /// Steps to solve: `round(duration/dt) + 1`.
    pub steps: usize,
    /// Contact state of each point at `t = 0`.
    pub initial_states: Vec<SpatialState>,
    /// Finest subdivision of a step that cannot be solved whole. Default
    /// 256 (an impact on many points at once may close only below Δt/64).
    pub max_substeps: usize,
    /// A cycling state search is closed by its least inconsistent trial
    /// when its violation is at most this force (N). Default `1e-7 ×`
    /// weight.
    pub cycle_tolerance: f64,
    /// Whether the contact points in contact solve stick/slip and lift-off
    /// as a complementarity problem (default `true`, as the hexapod).
    pub complementarity: bool,
    /// Regularisation added to each contact point's position rows: 0
    /// (every point of an imported robot is a foot or a sphere).
    pub contact_bumper: Vec<f64>,
    /// Wall time (s) of the start-up stability check of the joint
    /// controller (`pd_stability`) in [`RobotSim::new`], as the hexapod's
    /// (`SpatialModel::stability_check_seconds`); next to nothing for a
    /// run without a controller, which has no gains to check.
    pub stability_check_seconds: f64,
    /// The (unused) ground of a run in flight.
    pub(crate) no_ground: fbd_contact::Surface,
}

impl RobotSim {
    /// Validates `params` for `robot` and builds the model.
    ///
    /// # Errors
    /// [`SimError::InvalidParameter`] naming the configuration key,
    /// [`SimError::InitialPenetration`] for a point starting below ground.
    pub fn new(robot: &RobotModel, params: &RobotParams) -> Result<Self, SimError> {
        let p = params;
        let nq = BASE_DOF + robot.joints.len();
        let nj = robot.joints.len();
        positive("time.dt", p.dt)?;
        check(
            p.duration.is_finite() && p.duration >= 0.0,
            "time.duration",
            "must be finite and not negative",
            p.duration,
            "≥ 0",
        )?;
        check(
            p.gravity.is_finite(),
            "world.gravity",
            "must be finite",
            p.gravity,
            "a finite value",
        )?;
        crate::rules::stride(p.stride)?;
        p.solver.validate()?;
        assert_eq!(p.q0.len(), nq, "q0: 6 base coordinates + one per joint");
        assert_eq!(p.qdot0.len(), nq, "qdot0: the layout of q0");
        crate::rules::friction(&p.friction)?;
        let gains = |kp: &[f64], kd: &[f64]| -> Result<(), SimError> {
            assert!(kp.len() == nj && kd.len() == nj, "one gain per joint");
            for (key, v) in kp
                .iter()
                .map(|&v| ("control.kp", v))
                .chain(kd.iter().map(|&v| ("control.kd", v)))
            {
                crate::rules::gain(key, v)?;
            }
            Ok(())
        };
        match &p.control {
            RobotControl::None => {}
            RobotControl::Pd {
                kp,
                kd,
                target,
                torque_limit,
            } => {
                gains(kp, kd)?;
                assert_eq!(target.len(), nj, "one target per joint");
                if let Some(l) = torque_limit {
                    positive("control.torque_limit", *l)?;
                }
            }
            RobotControl::Gait {
                kp,
                kd,
                plan,
                torque_limit,
            } => {
                gains(kp, kd)?;
                assert_eq!(plan.standing().len(), nj, "a plan of this robot");
                if let Some(l) = torque_limit {
                    positive("control.torque_limit", *l)?;
                }
            }
            RobotControl::Trajectory {
                kp,
                kd,
                trajectory,
                torque_limit,
            } => {
                gains(kp, kd)?;
                check(
                    !trajectory.times.is_empty()
                        && trajectory.times.len() == trajectory.angles.len()
                        && trajectory.times.windows(2).all(|w| w[0] < w[1])
                        && trajectory.angles.iter().all(|a| a.len() == nj),
                    "control.trajectory",
                    "needs at least one knot, times strictly increasing, one angle per joint",
                    trajectory.times.len(),
                    "≥ 1 knot",
                )?;
                if let Some(l) = torque_limit {
                    positive("control.torque_limit", *l)?;
                }
            }
        }
        for (j, joint) in robot.joints.iter().enumerate() {
            if let Some(l) = joint.limits {
                let a = p.q0[BASE_DOF + j];
                check(
                    a >= l.lower - 1e-12 && a <= l.upper + 1e-12,
                    &format!("initial.joints_deg.{}", joint.name),
                    "outside the joint's limits",
                    format!("{:.6}°", a.to_degrees()),
                    &format!(
                        "[{:.6}°, {:.6}°]",
                        l.lower.to_degrees(),
                        l.upper.to_degrees()
                    ),
                )?;
            }
        }
        let start = std::time::Instant::now();
        pd_stability(robot, p)?;
        let stability_check_seconds = start.elapsed().as_secs_f64();
        let contacts: Vec<usize> = if p.terrain.is_some() {
            (0..robot.contacts.len()).collect()
        } else {
            Vec::new()
        };
        let mech = TreeMechanism::with_contacts(robot, p.gravity, &contacts);
        let contact_specs: Vec<ContactSpec> = mech
            .contacts
            .iter()
            .enumerate()
            .map(|(i, c)| ContactSpec {
                name: c.name.clone(),
                leg: i + 1,
                kind: PointKind::Tip,
                body: c.body,
                point: i,
            })
            .collect();
        let mut initial_states = Vec::with_capacity(mech.contacts.len());
        if let Some(surface) = &p.terrain {
            let mut kin = TreeKin::new(robot);
            kin.eval(robot, &p.q0);
            for c in &mech.contacts {
                let pt = kin.contact[c.model_contact];
                let state =
                    SpatialState::initial([pt.x, pt.y, pt.z], surface, p.contact.initial_tol)
                        .map_err(|depth| SimError::InitialPenetration {
                            leg: "position".into(),
                            point: c.name.clone(),
                            depth,
                        })?;
                initial_states.push(state);
            }
        }
        let total_mass = mech.total_mass();
        Ok(Self {
            params: p.clone(),
            effort: robot.joints.iter().map(|j| j.effort).collect(),
            contact_bumper: vec![0.0; contact_specs.len()],
            contact_specs,
            newton: p.solver.applied(crate::engine::surface::newton_params()),
            steps: (p.duration / p.dt).round() as usize + 1,
            initial_states,
            max_substeps: 256,
            cycle_tolerance: 1e-7 * total_mass * p.gravity.abs().max(1.0),
            complementarity: true,
            stability_check_seconds,
            no_ground: fbd_contact::Surface::default(),
            mech,
        })
    }

    /// Number of generalised coordinates, `6 + joints`.
    pub fn nq(&self) -> usize {
        self.mech.nq()
    }
}

/// The mass matrix `M(q)` (kinetic energy `½·q̇ᵀ·M·q̇`) of `robot` at `q`
/// (`6 + joints` coordinates), from the bodies' centre-of-mass and angular
/// Jacobians.
pub fn mass_matrix(robot: &RobotModel, q: &[f64]) -> DMatrix<f64> {
    let mut kin = TreeKin::new(robot);
    kin.eval(robot, q);
    let n = q.len();
    let mut m = DMatrix::zeros(n, n);
    for (b, body) in robot.bodies.iter().enumerate() {
        if body.mass == 0.0 {
            continue;
        }
        let r = kin.rotation[b];
        let inertia = r * body.inertia * r.transpose();
        let jc = kin.com_jacobian(b);
        let jw = kin.angular_jacobian(b);
        for (i, a) in jc.iter() {
            for (j, c) in jc.iter() {
                m[(i, j)] += body.mass * a.dot(&c);
            }
        }
        for (i, a) in jw.iter() {
            for (j, c) in jw.iter() {
                m[(i, j)] += a.dot(&(inertia * c));
            }
        }
    }
    m
}

/// The stability rule of the explicit joint torques
/// ([`crate::rules::pd_stability`]) for a robot, the hexapod's rule: the
/// largest `kp` and `kd` of any joint must be stable on the smallest
/// effective joint inertia at the commanded poses ([`for_each_pose`]:
/// the initial one and every target, each knot of a trajectory, with
/// every contact point on the ground; a gait's joint targets along the
/// run with its stance feet on the ground; without ground the free
/// robot's). [`crate::joint_inertia::poses_slower_than`] decides it
/// without eigenvalues where every standing limb is a chain of three
/// joints; otherwise, or when it fails, the eigenvalues of every pose
/// ([`crate::joint_inertia::fastest_mode_over`]) give the verdict and
/// the error's inertia and joint. Errors name `control.kd` (or
/// `control.kp`) with the largest stable value and the joint that moves
/// most.
fn pd_stability(robot: &RobotModel, p: &RobotParams) -> Result<(), SimError> {
    let (kp, kd) = match &p.control {
        RobotControl::None => return Ok(()),
        RobotControl::Pd { kp, kd, .. }
        | RobotControl::Trajectory { kp, kd, .. }
        | RobotControl::Gait { kp, kd, .. } => (kp, kd),
    };
    let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    let poses = |visit: &mut dyn FnMut(&[f64], &[usize]) -> bool| for_each_pose(robot, p, visit);
    crate::joint_inertia::check_gains(
        robot,
        &poses,
        (max(kp), max(kd), p.dt),
        || crate::joint_inertia::fastest_mode_over(robot, &poses),
        |joint| format!("joint {}", robot.joints[joint].name),
    )
}

/// Steps between two of the poses a gait's start-up stability check
/// samples from a run of `steps` steps (at most
/// [`crate::joint_inertia::GAIT_POSES`] of them, evenly spread): the
/// stride of the targets a caller records for it
/// ([`fbd_robot::gait::GaitPlan::record_samples`]).
pub fn gait_pose_stride(steps: usize) -> usize {
    steps / crate::joint_inertia::GAIT_POSES + 1
}

/// The contact points of `plan`'s stance feet at `t` into `standing`
/// (none without ground).
fn stance_feet(plan: &fbd_robot::gait::GaitPlan, ground: bool, t: f64, standing: &mut Vec<usize>) {
    standing.clear();
    if ground {
        standing.extend(
            (0..plan.leg_count())
                .filter(|&l| plan.stance(l, t))
                .map(|l| plan.foot_contact(l)),
        );
    }
}

/// Calls `visit(q, standing)` on every pose of [`pd_stability`] in order
/// (the coordinates; the contact points standing, indices into
/// `robot.contacts`) until it returns `false`. Every pose keeps the root
/// of `q0` (a rigid motion of the whole robot leaves its modes as they
/// are).
fn for_each_pose(
    robot: &RobotModel,
    p: &RobotParams,
    visit: &mut dyn FnMut(&[f64], &[usize]) -> bool,
) {
    let ground = p.terrain.is_some();
    let all: Vec<usize> = if ground {
        (0..robot.contacts.len()).collect()
    } else {
        Vec::new()
    };
    let mut q = p.q0.clone();
    if !visit(&q, &all) {
        return;
    }
    match &p.control {
        RobotControl::None => {}
        RobotControl::Pd { target, .. } => {
            q[BASE_DOF..].copy_from_slice(target);
            visit(&q, &all);
        }
        RobotControl::Trajectory { trajectory, .. } => {
            for angles in &trajectory.angles {
                q[BASE_DOF..].copy_from_slice(angles);
                if !visit(&q, &all) {
                    return;
                }
            }
        }
        RobotControl::Gait { plan, .. } => {
            if let Some(samples) = plan.samples().filter(|s| s.dt == p.dt) {
                // The targets the run will command, recorded by the
                // configuration's reach check over the start-up, the ramp
                // and two periods (after the ramp the plan repeats itself
                // in the body's frame every period): no IK here.
                let mut standing = Vec::with_capacity(plan.leg_count());
                for (i, target) in samples.targets.iter().enumerate() {
                    let t = (i * samples.stride) as f64 * p.dt;
                    stance_feet(plan, ground, t, &mut standing);
                    q[BASE_DOF..].copy_from_slice(target);
                    if !visit(&q, &standing) {
                        return;
                    }
                }
                return;
            }
            let mut plan = (**plan).clone();
            let n = robot.joints.len();
            let (mut target, mut rate) = (vec![0.0; n], vec![0.0; n]);
            let steps = (p.duration / p.dt).round() as usize + 1;
            let stride = gait_pose_stride(steps);
            let mut standing = Vec::with_capacity(plan.leg_count());
            for k in (0..steps).step_by(stride) {
                let t = k as f64 * p.dt;
                // A foot out of reach fails at that step of the run, with
                // its own error.
                if plan.targets(t, &mut target, &mut rate).is_err() {
                    return;
                }
                stance_feet(&plan, ground, t, &mut standing);
                q[BASE_DOF..].copy_from_slice(&target);
                if !visit(&q, &standing) {
                    return;
                }
            }
        }
    }
}
