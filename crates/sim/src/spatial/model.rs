//! The immutable spatial model, validated from [`SpatialParams`].

use super::params::{SpatialControl, SpatialParams};
use crate::SimError;
use crate::rules::{check, positive};
use fbd_contact::SpatialState;
use fbd_dynamics::spatial::{SpatialInertia, SpatialMechanism, q_joint};
use fbd_dynamics::tree::{TreeMechanism, contacts_by_kind};
use fbd_dynamics::{ContactSpec, PointKind};
use fbd_kinematics::Joint;
use fbd_kinematics::nalgebra::{Matrix3, Vector3};
use fbd_robot::RobotModel;
use fbd_solver::NewtonParams;

/// A joint stop of the hexapod: which leg slot and which joint of it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LegLimit {
    /// Position of the leg in [`SpatialModel::legs`].
    pub slot: usize,
    /// Which joint of the leg.
    pub joint: Joint,
    /// Its angle's index in `q` (`6 + 3·slot + j`).
    pub q_index: usize,
}

/// Everything fixed during a spatial run.
#[derive(Clone, Debug)]
pub struct SpatialModel {
    /// The parameters it was built from.
    pub params: SpatialParams,
    /// The FBD mechanism of the hexapod's generic robot model
    /// ([`SpatialParams::robot_model`], the D-H instance): 13 bodies for
    /// six legs, a two-axis hip and a knee reaction per leg, the contact
    /// points (every tip, then every knee, then every hip:
    /// [`contacts_by_kind`]) and the stops. The same equations as every
    /// imported robot's (`fbd_dynamics::tree`).
    pub mech: TreeMechanism,
    /// Leg numbers (1–6) of the model's legs, in slot order
    /// (`SpatialParams::legs`).
    pub legs: Vec<usize>,
    /// Each contact point's hexapod identity (leg, tip/knee/hip), in the
    /// order of `mech.contacts`.
    pub contacts: Vec<ContactSpec>,
    /// Each stop's leg and joint, in the order of `mech.limits`.
    pub limits: Vec<LegLimit>,
    /// Newton tolerances.
    pub newton: NewtonParams,
    /// Steps to solve: `round(duration/dt) + 1`.
    pub steps: usize,
    /// Regularisation added to each contact point's position rows: 0 for
    /// the feet, the bumper's for knees and hips (as in the planar model).
    pub contact_bumper: Vec<f64>,
    /// Contact state of each point at `t = 0`.
    pub initial_states: Vec<SpatialState>,
    /// Finest subdivision of a step that cannot be solved whole. Default
    /// 256 (an impact on many points at once may close only below Δt/64).
    pub max_substeps: usize,
    /// A cycling state search is closed by its least inconsistent trial
    /// when its violation is at most this force (N). Default `1e-7 ×`
    /// weight.
    pub cycle_tolerance: f64,
    /// Wall time (s) of the start-up stability check of the joint
    /// controller (`pd_stability`) in [`SpatialModel::new`]: under a
    /// millisecond when the gains pass the Cholesky test of every pose.
    pub stability_check_seconds: f64,
    /// Whether the contact points in contact solve stick/slip and lift-off
    /// in the step as a complementarity problem with the exact Coulomb law
    /// (`fbd_dynamics::rows::complementarity_rows`; default `true`), rather
    /// than in fixed states switched by the state search alone.
    pub complementarity: bool,
}

/// The body's inertia tensor from `[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]`.
pub fn inertia_matrix(i: &[f64; 6]) -> Matrix3<f64> {
    Matrix3::new(i[0], i[3], i[4], i[3], i[1], i[5], i[4], i[5], i[2])
}

impl SpatialParams {
    /// Checks every parameter's domain (the one source of these rules; the
    /// configuration loader calls it). Errors name the configuration key.
    pub fn validate(&self) -> Result<(), SimError> {
        let p = self;
        positive("time.dt", p.dt)?;
        check(
            p.duration.is_finite() && p.duration >= 0.0,
            "time.duration",
            "must be finite and not negative",
            p.duration,
            "a finite value ≥ 0",
        )?;
        check(
            p.gravity.is_finite() && p.gravity >= 0.0,
            "world.gravity",
            "is a magnitude (gravity acts along −Y)",
            p.gravity,
            "a finite value ≥ 0",
        )?;
        for (key, v) in [
            ("body.mass", p.body_mass),
            ("body.side", p.side),
            ("leg.upper_length", p.upper_length),
            ("leg.upper_mass", p.upper_mass),
            ("leg.upper_radius", p.upper_radius),
            ("leg.upper_inertia", p.upper_inertia),
            ("leg.lower_length", p.lower_length),
            ("leg.lower_mass", p.lower_mass),
            ("leg.lower_radius", p.lower_radius),
            ("leg.lower_inertia", p.lower_inertia),
        ] {
            positive(key, v)?;
        }
        for (key, v) in [
            ("leg.upper_com", p.upper_com),
            ("leg.lower_com", p.lower_com),
        ] {
            check(
                (0.0..=1.0).contains(&v),
                key,
                "is a fraction of the link",
                v,
                "0 ≤ value ≤ 1",
            )?;
        }
        let m = inertia_matrix(&p.body_inertia);
        let eig = m.symmetric_eigenvalues();
        let (e0, e1, e2) = (eig[0], eig[1], eig[2]);
        let triangle = e0 + e1 >= e2 * (1.0 - 1e-12)
            && e1 + e2 >= e0 * (1.0 - 1e-12)
            && e0 + e2 >= e1 * (1.0 - 1e-12);
        check(
            p.body_inertia.iter().all(|v| v.is_finite()) && eig.min() > 0.0 && triangle,
            "body.inertia",
            "must be a physical inertia tensor (positive definite, principal moments obeying the triangle inequality)",
            format!("{:?}", p.body_inertia),
            "e.g. [Ixx, Iyy, Izz] > 0 with Ixx + Iyy ≥ Izz",
        )?;
        check(
            !p.legs.is_empty()
                && p.legs.windows(2).all(|w| w[0] < w[1])
                && p.legs.iter().all(|l| (1..=6).contains(l)),
            "legs",
            "must be increasing leg numbers 1–6 without repeats",
            format!("{:?}", p.legs),
            "e.g. [1, 2, 3, 4, 5, 6] or [3, 4]",
        )?;
        let nq = 6 + 3 * p.legs.len();
        assert_eq!(p.q0.len(), nq, "q0 has the wrong length for the legs");
        assert_eq!(p.qdot0.len(), nq, "qdot0 has the wrong length for the legs");
        check(
            p.q0.iter().chain(&p.qdot0).all(|v| v.is_finite()),
            "initial",
            "must be finite",
            "a non-finite value",
            "finite numbers",
        )?;
        check(
            p.q0[5].cos().abs() > 1e-6,
            "initial.phi_deg",
            "φz = ±90° is the singularity of the body angles (rotation sequence Y, Z, X)",
            format!("{}°", p.q0[5].to_degrees()),
            "|φz| away from 90°",
        )?;
        crate::rules::friction(&p.friction)?;
        crate::rules::joint_ranges(p.joint_limits.is_valid(), "leg.theta1_deg", &p.joint_limits)?;
        crate::rules::stride(p.stride)?;
        p.solver.validate()?;
        let Some((kp, kd, limit)) = p.control.gains() else {
            return Ok(());
        };
        let nlegs = match &p.control {
            SpatialControl::Pd { target, .. } => target.len(),
            SpatialControl::Trajectory { legs, .. } => legs.len(),
            _ => p.legs.len(),
        };
        assert_eq!(nlegs, p.legs.len(), "one control entry per leg");
        for (key, v) in [("control.kp", kp), ("control.kd", kd)] {
            crate::rules::gain(key, v)?;
        }
        if let Some(l) = limit {
            positive("control.torque_limit", l)?;
        }
        Ok(())
    }
}

impl SpatialModel {
    /// Validates `params` and builds the model.
    ///
    /// # Errors
    /// [`SimError::InvalidParameter`] naming the configuration key,
    /// [`SimError::InitialPenetration`] for a point starting below ground.
    pub fn new(params: &SpatialParams) -> Result<Self, SimError> {
        let p = params;
        p.validate()?;
        let robot = p.robot_model();
        let mech = TreeMechanism::with_contacts(&robot, p.gravity, &contacts_by_kind(&robot));
        let start = std::time::Instant::now();
        pd_stability(p, &robot)?;
        let stability_check_seconds = start.elapsed().as_secs_f64();
        let legs = p.legs.clone();
        // Model joint 3·slot + j is θ(j+1) of leg `legs[slot]`.
        let joints = [Joint::Theta1, Joint::Theta2, Joint::Theta3];
        let limits: Vec<LegLimit> = mech
            .limits
            .iter()
            .map(|l| LegLimit {
                slot: l.joint / 3,
                joint: joints[l.joint % 3],
                q_index: l.q_index,
            })
            .collect();
        for lim in &limits {
            if let Err(e) = p.joint_limits.check(lim.joint, p.q0[lim.q_index]) {
                check(
                    false,
                    &format!("initial.leg{}.theta_deg", legs[lim.slot]),
                    "outside the joint limits",
                    e.to_string(),
                    &format!("angles inside [leg] {}_deg", lim.joint.name()),
                )?;
            }
        }
        let contacts = hexapod_contacts(&mech, &legs);
        let contact = p.contact;
        let contact_bumper = contacts
            .iter()
            .map(|c| match c.kind {
                PointKind::Tip => 0.0,
                PointKind::Knee | PointKind::Hip => contact.bumper_regularization,
            })
            .collect();
        let mut kin = fbd_dynamics::tree::kin::TreeKin::new(&mech.model);
        kin.eval(&mech.model, &p.q0);
        let mut initial_states = Vec::with_capacity(contacts.len());
        for (c, spec) in mech.contacts.iter().zip(&contacts) {
            let pt = kin.contact[c.model_contact];
            let state = SpatialState::initial([pt.x, pt.y, pt.z], &p.terrain, contact.initial_tol)
                .map_err(|depth| SimError::InitialPenetration {
                    leg: format!("leg{}", spec.leg),
                    point: spec.name.clone(),
                    depth,
                })?;
            initial_states.push(state);
        }
        let total_mass = mech.total_mass();
        let model = Self {
            params: p.clone(),
            steps: (p.duration / p.dt).round() as usize + 1,
            newton: p.solver.applied(crate::engine::surface::newton_params()),
            contact_bumper,
            initial_states,
            max_substeps: 256,
            cycle_tolerance: 1e-7 * total_mass * p.gravity.abs().max(1.0),
            stability_check_seconds,
            complementarity: true,
            mech,
            legs,
            contacts,
            limits,
        };
        Ok(model)
    }

    /// Time step (s).
    pub fn dt(&self) -> f64 {
        self.params.dt
    }

    /// Generalised coordinates.
    pub fn nq(&self) -> usize {
        self.mech.nq()
    }

    /// Gravity vector (m/s²).
    pub fn gravity(&self) -> Vector3<f64> {
        Vector3::new(0.0, -self.params.gravity, 0.0)
    }
}

/// Each contact point's hexapod identity (leg, tip/knee/hip), in the
/// order of `mech.contacts` (named `tip3`, `knee3`, `hip3`, … by
/// [`SpatialParams::robot_model`]); `legs` are the model's leg numbers in
/// slot order.
pub(crate) fn hexapod_contacts(mech: &TreeMechanism, legs: &[usize]) -> Vec<ContactSpec> {
    mech.contacts
        .iter()
        .map(|c| {
            let stem = c.name.trim_end_matches(|ch: char| ch.is_ascii_digit());
            let leg: usize = c.name[stem.len()..].parse().expect("a hexapod point's leg");
            let slot = legs
                .iter()
                .position(|&n| n == leg)
                .expect("a leg of the model");
            let kind = [PointKind::Tip, PointKind::Knee, PointKind::Hip]
                .into_iter()
                .find(|k| k.as_str() == stem)
                .expect("tip, knee or hip");
            ContactSpec {
                name: c.name.clone(),
                leg,
                kind,
                body: c.body,
                point: fbd_dynamics::spatial::point_id(slot, kind),
            }
        })
        .collect()
}

/// The hexapod of `p` in closed form ([`fbd_dynamics::spatial`]): its
/// bodies' masses and inertias on the leg kinematics of
/// `fbd_kinematics::hexapod`, the tests' independent reference for the
/// positions, statics and modes the generic tree computes.
pub fn closed_form(p: &SpatialParams) -> SpatialMechanism {
    let inertia = SpatialInertia {
        body_mass: p.body_mass,
        body_inertia: inertia_matrix(&p.body_inertia),
        upper_mass: p.upper_mass,
        upper_axial: 0.5 * p.upper_mass * p.upper_radius * p.upper_radius,
        upper_transverse: p.upper_inertia,
        lower_mass: p.lower_mass,
        lower_axial: 0.5 * p.lower_mass * p.lower_radius * p.lower_radius,
        lower_transverse: p.lower_inertia,
    };
    SpatialMechanism::new(
        p.kinematic_model(),
        &p.legs,
        &inertia,
        p.gravity,
        p.contact_points,
        &p.joint_limits,
    )
}

/// The stability rule of the explicit joint controller
/// ([`crate::rules::pd_stability`]) on the smallest effective joint
/// inertia ([`crate::joint_inertia`]) at the commanded poses: the initial
/// one and every target (each knot of a trajectory) with every foot on
/// the ground; for the gait, its joint angles along the run (at most
/// [`crate::joint_inertia::GAIT_POSES`] steps) with its stance feet on
/// the ground. Without ground, the free robot's
/// ([`crate::joint_inertia::check_gains`], as for any robot).
///
/// The rule holds when every pose's modes are slower than the inertia
/// limit of the gains ([`crate::rules::pd_inertia_limit`]), which
/// [`crate::joint_inertia::tree_modes_slower_than`] decides along the hexapod's D-H instance
/// (the generic robot model, as for any robot) from some 100 flops per
/// joint and a 6×6 Cholesky factorisation per pose. Only
/// when that fails (or is undecided at a singular standing leg) the
/// eigenvalues of every pose ([`fastest_mode_over_poses`]) give the
/// verdict and the error's inertia and joint (kept in the process,
/// [`MODES`]). The limit is raised by a
/// relative 1e-6 for the fast test, so that a pose within round-off of it
/// is left to the eigenvalues: both paths give the same verdict
/// (`tests/pd_stability.rs` compares them over a grid of gains and steps).
fn pd_stability(p: &SpatialParams, robot: &RobotModel) -> Result<(), SimError> {
    let Some((kp, kd, _)) = p.control.gains() else {
        return Ok(());
    };
    crate::joint_inertia::check_gains(
        robot,
        &|visit| for_each_pose(p, robot, visit),
        (kp, kd, p.dt),
        || {
            // Only now the parameters are cloned for the cache's key: a
            // passing check costs less than cloning a large terrain.
            let key = cache_key(p);
            cached(&MODES, &key).unwrap_or_else(|| {
                let mode = fastest_mode_over_poses(p, robot);
                keep(&MODES, key, mode);
                mode
            })
        },
        |joint| format!("leg {} theta{}", p.legs[joint / 3], joint % 3 + 1),
    )
}

/// Whether every pose of [`pd_stability`] has every joint mode slower
/// than a joint of inertia `inertia` (kg·m²,
/// [`crate::joint_inertia::tree_modes_slower_than`] on `robot`, the D-H instance of `p`,
/// [`SpatialParams::robot_model`]): `Some(false)` at the first pose that
/// has a faster one, `None` when a pose is undecided.
pub fn modes_slower_than(p: &SpatialParams, robot: &RobotModel, inertia: f64) -> Option<bool> {
    crate::joint_inertia::poses_slower_than(robot, &|visit| for_each_pose(p, robot, visit), inertia)
}

/// Results of [`fastest_mode_over_poses`] kept in this process, keyed by
/// the parameters with what it does not read normalised away
/// ([`cache_key`]): the runs of a sweep over gains or friction, and the
/// resets of an environment, compute it once. At most [`CACHE`] entries,
/// the oldest dropped first.
static MODES: std::sync::Mutex<Vec<(SpatialParams, (f64, usize))>> =
    std::sync::Mutex::new(Vec::new());

/// Entries of [`MODES`].
const CACHE: usize = 16;

/// `p` less what the poses of [`pd_stability`] do not depend on: the
/// gains and limits of the controller, friction, contact tolerances,
/// initial rates, output stride.
fn cache_key(p: &SpatialParams) -> SpatialParams {
    let mut key = p.clone();
    if let Some((kp, kd, torque_limit)) = key.control.gains_mut() {
        (*kp, *kd, *torque_limit) = (0.0, 0.0, None);
    }
    key.friction = Default::default();
    key.contact = Default::default();
    key.qdot0.clear();
    key.stride = 0;
    key.duration = 0.0;
    key
}

/// The value `cache` keeps for `key`.
fn cached<T: Copy>(
    cache: &std::sync::Mutex<Vec<(SpatialParams, T)>>,
    key: &SpatialParams,
) -> Option<T> {
    let cache = cache.lock().ok()?;
    cache.iter().find(|(k, _)| k == key).map(|(_, v)| *v)
}

/// Keeps `value` for `key` in `cache` (replacing its value, or dropping
/// the oldest entry of a full cache).
fn keep<T>(cache: &std::sync::Mutex<Vec<(SpatialParams, T)>>, key: SpatialParams, value: T) {
    if let Ok(mut cache) = cache.lock() {
        if let Some(entry) = cache.iter_mut().find(|(k, _)| *k == key) {
            entry.1 = value;
            return;
        }
        if cache.len() == CACHE {
            cache.remove(0);
        }
        cache.push((key, value));
    }
}

/// The smallest effective joint inertia over the poses of
/// [`pd_stability`] and its joint (index `3·slot + j`), from the
/// eigenvalues of each pose ([`crate::joint_inertia::fastest_mode`] on the mass matrix of
/// `robot`, the D-H instance of `p`).
pub fn fastest_mode_over_poses(p: &SpatialParams, robot: &RobotModel) -> (f64, usize) {
    crate::joint_inertia::fastest_mode_over(robot, &|visit| for_each_pose(p, robot, visit))
}

/// Calls `visit(q, standing)` on every pose of [`pd_stability`] (the
/// coordinates, the feet standing: indices into `robot.contacts`) in
/// order, until it returns `false`. A leg whose foot is not a contact
/// point never stands.
fn for_each_pose(
    p: &SpatialParams,
    robot: &RobotModel,
    visit: &mut dyn FnMut(&[f64], &[usize]) -> bool,
) {
    let nlegs = p.legs.len();
    // Each slot's foot among the contact points.
    let foot: Vec<Option<usize>> = p
        .legs
        .iter()
        .map(|n| {
            robot
                .contacts
                .iter()
                .position(|c| c.name == format!("tip{n}"))
        })
        .collect();
    // Without ground no foot ever stands: the free robot's modes.
    let ground = p.terrain.exists();
    let all: Vec<usize> = if ground {
        foot.iter().flatten().copied().collect()
    } else {
        Vec::new()
    };
    let mut q = p.q0.clone();
    fn at(q: &mut [f64], angles: impl Iterator<Item = [f64; 3]>) {
        for (s, a) in angles.enumerate() {
            for (j, v) in a.iter().enumerate() {
                q[q_joint(s, j)] = *v;
            }
        }
    }
    if !visit(&q, &all) {
        return;
    }
    match &p.control {
        SpatialControl::Pd { target, .. } => {
            at(&mut q, target.iter().copied());
            visit(&q, &all);
        }
        SpatialControl::Trajectory { legs, .. } => {
            for t in legs.iter().flat_map(|l| l.times.iter()) {
                at(&mut q, legs.iter().map(|l| l.at(*t)));
                if !visit(&q, &all) {
                    return;
                }
            }
        }
        SpatialControl::Gait { gait, .. } => {
            let mut g = crate::gait::GaitData::new(gait);
            let stride = gait.steps / crate::joint_inertia::GAIT_POSES + 1;
            let mut standing = Vec::with_capacity(nlegs);
            // Only the sampled steps: the gait's closed-form inverse
            // kinematics needs the previous angles only to stay on their
            // turn (±2π), which `stride` ms of a gait never leaves, so each
            // sample is the angles the run's controller computes at that
            // step (a 26th of the gait's steps on a 5 s walk at 1 ms).
            for k in (0..=gait.steps).step_by(stride) {
                // A gait that cannot place a foot fails at that step of
                // the run, with its own error.
                if crate::gait::step_targets(gait, &mut g, k).is_err() {
                    break;
                }
                let stance = g.stance();
                standing.clear();
                standing.extend(
                    (0..nlegs)
                        .filter(|&s| ground && stance[p.legs[s] - 1])
                        .filter_map(|s| foot[s]),
                );
                at(&mut q, p.legs.iter().map(|&n| g.legs[n - 1].theta));
                if !visit(&q, &standing) {
                    return;
                }
            }
        }
        SpatialControl::None => {}
    }
}
