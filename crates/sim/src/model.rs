//! The immutable [`Model`] of a planar run, validated from [`PlanarParams`].

use crate::control::Control;
use crate::joint_inertia::{fastest_mode, planar_feet_jacobian, planar_mass_matrix};
use crate::rules::{check, positive};
use crate::{PlanarParams, SimError};
use fbd_contact::{ContactParams, ContactState};
use fbd_dynamics::{Mechanism, PointKind};
use fbd_kinematics::Joint;
use fbd_kinematics::planar::{TwoLegIndex, theta2_index, theta3_index};
use fbd_solver::NewtonParams;

/// Everything fixed during a run: parameters, mechanism, tolerances.
#[derive(Clone, Debug)]
pub struct Model {
    /// The parameters the model was built from.
    pub params: PlanarParams,
    /// Bodies, joints and contact points.
    pub mech: Mechanism,
    /// Named points and angles of the two-leg model.
    pub index: TwoLegIndex,
    /// Contact switching tolerances.
    pub contact: ContactParams,
    /// Newton tolerances.
    pub newton: NewtonParams,
    /// Steps to solve: `round(duration/dt) + 1`.
    pub steps: usize,
    /// Compliance of each contact point's anchor at the model's Δt (m/N):
    /// 0 for the feet (rigid, as the paper's), `β_b·Δt²/M` for knees and
    /// hips ([`ContactParams::bumper_regularization`]).
    pub contact_compliance: Vec<f64>,
    /// Dimensionless regularisation of each contact point's position rows
    /// on top of [`ContactParams::regularization`]: 0 for the feet,
    /// [`ContactParams::bumper_regularization`] for knees and hips. It is
    /// independent of Δt (so are the impacts it makes plastic).
    pub contact_bumper: Vec<f64>,
    /// Contact state of each point at `t = 0` (docs/reference.md).
    pub initial_states: Vec<ContactState>,
    /// Which joint of its leg each joint limit (order of
    /// `mech.limits`) is: θ2 (hips) or θ3 (knees).
    pub limit_joint: Vec<Joint>,
    /// Hexapod leg number (3 or 4) of each joint limit.
    pub limit_leg: Vec<usize>,
    /// Finest subdivision of a step that cannot be solved whole: it is
    /// retried as 2, 4, … up to `max_substeps` substeps before the run
    /// fails. Default 64 (Δt/64: 0.16 ms at the default Δt = 10 ms).
    pub max_substeps: usize,
    /// A state search that cycles is closed by its least inconsistent
    /// trial when that trial violates the contact and limit laws by at
    /// most this force (N); otherwise the step is retried in substeps.
    /// Default `1e-7 × weight` (13 µN on the default robot: a penetration
    /// of 0.1 nm at Δt = 10 ms), the order of the solver's tolerances.
    pub cycle_tolerance: f64,
}

impl PlanarParams {
    /// Checks every parameter's domain: the one source of these rules
    /// (the configuration loader, `fbd_scenario`, calls it and adds the
    /// file). Errors name the configuration key at fault. The joint limits
    /// and the initial contact with the terrain are checked by
    /// [`Model::planar`].
    pub fn validate(&self) -> Result<(), SimError> {
        let p = self;
        positive("time.dt", p.dt)?;
        positive("time.duration", p.duration)?;
        check(
            p.dt <= p.duration,
            "time.dt",
            "must not exceed time.duration",
            p.dt,
            "dt ≤ duration",
        )?;
        let steps_f = (p.duration / p.dt).round();
        check(
            steps_f <= 1e9,
            "time.duration",
            "needs too many steps",
            steps_f,
            "duration/dt ≤ 1e9",
        )?;
        check(
            p.gravity.is_finite() && p.gravity >= 0.0,
            "world.gravity",
            "is the magnitude g of gravity (which acts along −Y) and must be finite and ≥ 0",
            p.gravity,
            "a finite value ≥ 0, e.g. 9.81",
        )?;
        positive("body.mass", p.body_mass)?;
        positive("body.inertia", p.body_inertia)?;
        positive("body.side", p.side)?;
        positive("leg.upper_length", p.upper_length)?;
        positive("leg.upper_mass", p.upper_mass)?;
        positive("leg.upper_inertia", p.upper_inertia)?;
        positive("leg.lower_length", p.lower_length)?;
        positive("leg.lower_mass", p.lower_mass)?;
        positive("leg.lower_inertia", p.lower_inertia)?;
        for (key, v) in [
            ("leg.upper_com", p.upper_com),
            ("leg.lower_com", p.lower_com),
        ] {
            check(
                v.is_finite() && (0.0..=1.0).contains(&v),
                key,
                "must lie on the link",
                v,
                "a fraction in [0, 1]",
            )?;
        }
        let names = [
            "initial.position",
            "initial.position",
            "initial.phi_z_deg",
            "initial.leg3.theta_deg",
            "initial.leg3.theta_deg",
            "initial.leg4.theta_deg",
            "initial.leg4.theta_deg",
        ];
        let rates = [
            "initial.velocity",
            "initial.velocity",
            "initial.omega_z_deg",
            "initial.leg3.rate_deg",
            "initial.leg3.rate_deg",
            "initial.leg4.rate_deg",
            "initial.leg4.rate_deg",
        ];
        for i in 0..7 {
            check(
                p.q0[i].is_finite(),
                names[i],
                "must be finite",
                p.q0[i],
                "a finite value",
            )?;
            check(
                p.qdot0[i].is_finite(),
                rates[i],
                "must be finite",
                p.qdot0[i],
                "a finite value",
            )?;
        }
        if let Err(e) = p.terrain.validate() {
            check(
                false,
                &format!("terrain.{}", e.key),
                e.what,
                e.got,
                e.expected,
            )?;
        }
        if let Err((key, what, got)) = p.control.validate() {
            check(false, &key, what, got, "see the [control] documentation")?;
        }
        check(
            p.friction.mu_static.is_finite() && p.friction.mu_static >= 0.0,
            "terrain.mu_static",
            "must be finite and ≥ 0",
            p.friction.mu_static,
            "0 ≤ mu_static",
        )?;
        check(
            p.friction.mu_dynamic.is_finite()
                && p.friction.mu_dynamic >= 0.0
                && p.friction.mu_dynamic <= p.friction.mu_static,
            "terrain.mu_dynamic",
            "must satisfy 0 ≤ mu_dynamic ≤ mu_static",
            p.friction.mu_dynamic,
            &format!("0 ≤ mu_dynamic ≤ {}", p.friction.mu_static),
        )?;
        crate::rules::stride(p.stride)?;
        p.solver.validate()?;
        Ok(())
    }
}

/// The named angles and points of the two-leg model in its mechanism's
/// kinematics ([`Mechanism::in_plane`] of `fbd_robot::dh::planar`): its
/// bodies' angles and centres of mass, its joints' points, and the feet
/// (contact points of the model, named `tip{n}`, whether or not they are
/// contact points of the run).
fn two_leg_index(mech: &Mechanism) -> TwoLegIndex {
    let body = |name: String| {
        mech.bodies
            .iter()
            .find(|b| b.name == name)
            .expect("a body of the planar model")
    };
    let joint = |name: String| {
        mech.joints
            .iter()
            .find(|j| j.name == name)
            .expect("a joint of the planar model")
            .point
    };
    let tip = |n: usize| {
        let name = format!("tip{n}");
        mech.chains
            .points
            .iter()
            .position(|p| p.name == name)
            .expect("a foot of the planar model")
    };
    let legs = |f: &dyn Fn(usize) -> usize| [f(3), f(4)];
    TwoLegIndex {
        body_angle: mech.bodies[0].angle,
        upper_angle: legs(&|n| body(format!("upper{n}")).angle),
        lower_angle: legs(&|n| body(format!("lower{n}")).angle),
        hip: legs(&|n| joint(format!("hip{n}"))),
        knee: legs(&|n| joint(format!("knee{n}"))),
        tip: legs(&tip),
        upper_com: legs(&|n| body(format!("upper{n}")).com),
        lower_com: legs(&|n| body(format!("lower{n}")).com),
        body_com: mech.bodies[0].com,
    }
}

impl Model {
    /// Validates `params` and builds the model. Errors name the
    /// configuration key at fault.
    pub fn planar(params: &PlanarParams) -> Result<Self, SimError> {
        let p = params;
        p.validate()?;
        let steps_f = (p.duration / p.dt).round();

        let robot = p.robot_model();
        let cp = p.contact_points;
        let contacts: Vec<usize> = fbd_dynamics::tree::contacts_by_kind(&robot)
            .into_iter()
            .filter(|&c| {
                let kind = PointKind::ALL
                    .into_iter()
                    .find(|k| robot.contacts[c].name.starts_with(k.as_str()));
                match kind {
                    Some(PointKind::Tip) => cp.tips,
                    Some(PointKind::Knee) => cp.knees,
                    Some(PointKind::Hip) => cp.hips,
                    None => false,
                }
            })
            .collect();
        let mech = Mechanism::in_plane(&robot, &contacts, p.gravity)
            .expect("the planar model lies in the plane");
        let index = two_leg_index(&mech);
        crate::rules::joint_ranges(p.joint_limits.is_valid(), "leg.theta2_deg", &p.joint_limits)?;
        // Every joint whose range has a finite end gets a stop; the initial
        // angles must lie in the ranges.
        let mut limited = Vec::new();
        let (mut limit_joint, mut limit_leg) = (Vec::new(), Vec::new());
        for (j, spec) in mech.joints.iter().enumerate() {
            let (leg, joint) = (spec.leg, spec.joint);
            if let Err(e) = p.joint_limits.check(joint, p.q0[spec.q_index]) {
                check(
                    false,
                    &format!("initial.leg{leg}.theta_deg"),
                    "outside the joint limits",
                    e.to_string(),
                    &format!("angles inside [leg] {}_deg", joint.name()),
                )?;
            }
            let [lo, hi] = p.joint_limits.range(joint);
            if lo.is_finite() || hi.is_finite() {
                limited.push(j);
                limit_joint.push(joint);
                limit_leg.push(leg);
            }
        }
        let mech = mech.with_limits(limited);
        pd_stability(p, &mech, &index)?;
        let contact = ContactParams::default();
        let contact_bumper: Vec<f64> = mech
            .contacts
            .iter()
            .map(|c| match c.kind {
                PointKind::Tip => 0.0,
                PointKind::Knee | PointKind::Hip => contact.bumper_regularization,
            })
            .collect();
        let total_mass = mech.total_mass();
        let mut kin = mech.chains.new_data();
        mech.chains.eval_positions(&p.q0, &mut kin);
        let mut initial_states = Vec::with_capacity(mech.contacts.len());
        for c in &mech.contacts {
            let state = ContactState::initial(kin.pos[c.point], &p.terrain, contact.initial_tol)
                .map_err(|depth| SimError::InitialPenetration {
                    leg: format!("leg{}", c.leg),
                    point: c.name.clone(),
                    depth,
                })?;
            initial_states.push(state);
        }
        Ok(Self {
            params: p.clone(),
            mech,
            index,
            contact,
            newton: p.solver.applied(NewtonParams {
                // At the small steps of a simulation the previous
                // factorisation is an excellent approximate Jacobian; a chord
                // step that does not contract falls back to full Newton, so
                // the tolerances are unchanged.
                chord_steps: crate::DEFAULT_CHORD_STEPS,
                // A refactorisation (the Jacobian, faer's numeric LU of the
                // 15–31 unknowns) costs about eight chord steps here;
                // renewing the kept one at that cost cut the instructions
                // per step of the `bench/peer` cases by 2–4 % (callgrind;
                // 4 and 12 within 2 % of it, 20 less). The 3D models
                // renew at 24 (`crate::engine::surface::newton_params`).
                refactor_cost: 8.0,
                ..NewtonParams::default()
            }),
            steps: steps_f as usize + 1,
            contact_compliance: contact_bumper
                .iter()
                .map(|b| b * p.dt * p.dt / total_mass)
                .collect(),
            contact_bumper,
            initial_states,
            limit_joint,
            limit_leg,
            max_substeps: 64,
            cycle_tolerance: 1e-7 * total_mass * p.gravity.abs(),
        })
    }

    /// Time step (s).
    pub fn dt(&self) -> f64 {
        self.params.dt
    }
}

/// The stability rule of the explicit joint controller
/// ([`crate::rules::pd_stability`]) on the smallest effective joint
/// inertia of the robot standing on both feet (floating, without ground;
/// [`crate::joint_inertia`]) at the commanded poses: the initial one and
/// every target (each knot of a trajectory).
fn pd_stability(p: &PlanarParams, mech: &Mechanism, index: &TwoLegIndex) -> Result<(), SimError> {
    let (kp, kd, times) = match &p.control {
        Control::None => return Ok(()),
        Control::Pd { kp, kd, .. } => (*kp, *kd, vec![0.0]),
        Control::Trajectory { kp, kd, legs, .. } => {
            let mut t: Vec<f64> = legs.iter().flat_map(|l| l.times.iter().copied()).collect();
            t.sort_by(f64::total_cmp);
            (*kp, *kd, t)
        }
    };
    if kp == 0.0 && kd == 0.0 {
        return Ok(());
    }
    let joints: Vec<usize> = mech.joints.iter().map(|j| j.q_index).collect();
    // Without ground no foot ever stands: the free robot's modes.
    let feet: &[usize] = if p.terrain.exists() { &index.tip } else { &[] };
    let mut poses = vec![p.q0];
    for t in times {
        let mut q = p.q0;
        for leg in 0..2 {
            if let Some([t2, t3]) = p.control.target(leg, t) {
                q[theta2_index(leg)] = t2;
                q[theta3_index(leg)] = t3;
            }
        }
        poses.push(q);
    }
    let (mut inertia, mut joint) = (f64::INFINITY, 0);
    for q in &poses {
        let mode = fastest_mode(
            &planar_mass_matrix(mech, q),
            &planar_feet_jacobian(mech, feet, q),
            &joints,
        );
        if mode.inertia < inertia {
            (inertia, joint) = (mode.inertia, mode.joint);
        }
    }
    let spec = &mech.joints[joint];
    crate::rules::pd_stability(
        kp,
        kd,
        inertia,
        p.dt,
        &format!("leg {} {}", spec.leg, spec.joint.name()),
    )
}
