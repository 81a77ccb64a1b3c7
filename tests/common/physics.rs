//! Physics helpers shared by the scenario tests: body coordinates from `q`,
//! the system's centre of mass, momenta.

use fbd_dynamics::FbdData;
use fbd_sim::{Model, PlanarParams, RobotRecord};

/// `(X, Y, ψ)` of every body at `q`.
pub fn body_coords(model: &Model, q: &[f64]) -> Vec<[f64; 3]> {
    let mut kin = model.mech.chains.new_data();
    model.mech.chains.eval_positions(q, &mut kin);
    (0..model.mech.bodies.len())
        .map(|b| FbdData::body_coords(&model.mech, &kin, b))
        .collect()
}

/// Inertial position of every chain point at `q`.
pub fn points(model: &Model, q: &[f64]) -> Vec<[f64; 2]> {
    let mut kin = model.mech.chains.new_data();
    model.mech.chains.eval_positions(q, &mut kin);
    kin.pos
}

/// The system's centre of mass at `q`.
pub fn system_com(model: &Model, q: &[f64]) -> [f64; 2] {
    let m = model.mech.total_mass();
    let mut c = [0.0; 2];
    for (b, x) in body_coords(model, q).iter().enumerate() {
        let mb = model.mech.bodies[b].mass;
        c[0] += mb * x[0] / m;
        c[1] += mb * x[1] / m;
    }
    c
}

/// Discrete linear momentum `Σ m (X[k+1] − X[k])/Δt` between two rows.
pub fn momentum(model: &Model, q0: &[f64], q1: &[f64], dt: f64) -> [f64; 2] {
    let (a, b) = (body_coords(model, q0), body_coords(model, q1));
    let mut p = [0.0; 2];
    for (i, spec) in model.mech.bodies.iter().enumerate() {
        p[0] += spec.mass * (b[i][0] - a[i][0]) / dt;
        p[1] += spec.mass * (b[i][1] - a[i][1]) / dt;
    }
    p
}

/// Discrete angular momentum about the system's centre of mass at `k`,
/// `Σ m (X[k] − Xc[k]) × (X[k+1] − X[k])/Δt + I (ψ[k+1] − ψ[k])/Δt`: the
/// scheme conserves it exactly when no external moment acts about the
/// centre of mass.
pub fn angular_momentum(model: &Model, q0: &[f64], q1: &[f64], dt: f64) -> f64 {
    let (a, b) = (body_coords(model, q0), body_coords(model, q1));
    let c = system_com(model, q0);
    let mut l = 0.0;
    for (i, spec) in model.mech.bodies.iter().enumerate() {
        let r = [a[i][0] - c[0], a[i][1] - c[1]];
        let v = [(b[i][0] - a[i][0]) / dt, (b[i][1] - a[i][1]) / dt];
        l += spec.mass * (r[0] * v[1] - r[1] * v[0]) + spec.inertia * (b[i][2] - a[i][2]) / dt;
    }
    l
}

/// The robot of the default experiment thrown as in a run of
/// `examples/sweep_landing_1000.toml`: initial tilt and spin (degrees,
/// °/s), drop height of the lowest point (m), legs 3 and 4 `[θ2, θ3]`
/// (degrees), μS (μD = 0.75 μS).
pub fn landing(
    phi_deg: f64,
    omega_deg: f64,
    drop: f64,
    t3: [f64; 2],
    t4: [f64; 2],
    mus: f64,
) -> PlanarParams {
    let mut p = PlanarParams::default();
    p.q0[2] = phi_deg.to_radians();
    p.qdot0[2] = omega_deg.to_radians();
    p.q0[3] = t3[0].to_radians();
    p.q0[4] = t3[1].to_radians();
    p.q0[5] = t4[0].to_radians();
    p.q0[6] = t4[1].to_radians();
    p.friction.mu_static = mus;
    p.friction.mu_dynamic = 0.75 * mus;
    p.set_drop_height(drop);
    p
}

/// The in-plane coordinates `(x, y)` of a record's point (its z is 0).
pub fn plane(p: [f64; 3]) -> [f64; 2] {
    [p[0], p[1]]
}

/// Builds and runs a model; panics with the error if the run fails.
pub fn run_ok(p: &PlanarParams) -> (Model, Vec<RobotRecord>, fbd_sim::RunSummary) {
    let model = Model::planar(p).expect("valid parameters");
    let (rows, summary) = fbd_sim::run_collect(&model);
    if let Some(e) = &summary.error {
        panic!("run failed: {e}");
    }
    (model, rows, summary)
}

/// `q[k]` of the paper's pose with `Ry` chosen so that both tips touch flat
/// ground at `y = 0` (θ3₃ = θ3₄ = `theta3_deg`, θ2 = 0).
pub fn standing_q(p: &PlanarParams, theta3_deg: f64) -> [f64; 7] {
    let mut q = [
        0.0,
        1.0,
        0.0,
        0.0,
        theta3_deg.to_radians(),
        0.0,
        theta3_deg.to_radians(),
    ];
    let model = Model::planar(&PlanarParams {
        q0: q,
        terrain: fbd_contact::Terrain::None,
        ..p.clone()
    })
    .unwrap();
    let pts = points(&model, &q);
    q[1] -= pts[model.index.tip[0]][1];
    q
}

/// Checks every body's Newton–Euler equations (translation and rotation)
/// at every interior row from the recorded configurations and forces alone:
/// accelerations by the central difference of the recorded `q`, forces from
/// the recorded joint forces, contact forces, torques and gravity. Returns
/// the worst imbalance in newtons (moments divided by the model's length
/// scale).
pub fn worst_body_imbalance(model: &Model, rows: &[RobotRecord]) -> (f64, String) {
    worst_body_imbalance_except(model, rows, &[])
}

/// [`worst_body_imbalance`] without the rows of the steps in `skip`: the
/// steps solved in substeps, whose recorded forces are their first
/// substep's (at `t_k`, over `Δt/n`), not a whole step's.
pub fn worst_body_imbalance_except(
    model: &Model,
    rows: &[RobotRecord],
    skip: &[usize],
) -> (f64, String) {
    let mech = &model.mech;
    let dt = model.params.dt;
    let mut worst = (0.0f64, String::new());
    for w in rows.windows(3) {
        let (prev, cur, next) = (&w[0], &w[1], &w[2]);
        assert_eq!(cur.step, prev.step + 1, "force balance needs stride 1");
        if skip.contains(&cur.step) {
            continue;
        }
        let (xp, xk, xn) = (
            body_coords(model, &prev.plane_q()),
            body_coords(model, &cur.plane_q()),
            body_coords(model, &next.plane_q()),
        );
        let pts = points(model, &cur.plane_q());
        // Applied forces and moments about each centre of mass at k.
        let mut acc: Vec<[f64; 3]> = mech
            .bodies
            .iter()
            .map(|b| [0.0, -b.mass * mech.gravity, 0.0])
            .collect();
        let mut apply = |b: usize, p: [f64; 2], f: [f64; 2], tz: f64| {
            let r = [p[0] - xk[b][0], p[1] - xk[b][1]];
            acc[b][0] += f[0];
            acc[b][1] += f[1];
            acc[b][2] += r[0] * f[1] - r[1] * f[0] + tz;
        };
        for (j, spec) in mech.joints.iter().enumerate() {
            let f = [cur.reaction_force[j][0], cur.reaction_force[j][1]];
            // Joint torque and the moment of the joint-limit stop.
            let tz = spec.axis_z * (cur.torque[j] + cur.stop[j]);
            apply(spec.child, pts[spec.point], f, tz);
            apply(spec.parent, pts[spec.point], [-f[0], -f[1]], -tz);
        }
        for (c, spec) in mech.contacts.iter().enumerate() {
            let x = pts[spec.point][0];
            let (t, n) = model.params.terrain.frame(x);
            let _ = (t, n);
            let (t, n) = if let fbd_contact::Terrain::None = model.params.terrain {
                ([1.0, 0.0], [0.0, 1.0])
            } else {
                (t, n)
            };
            let (fa, fn_) = (cur.contacts[c].tangential[0], cur.contacts[c].normal);
            let f = [fa * t[0] + fn_ * n[0], fa * t[1] + fn_ * n[1]];
            apply(spec.body, pts[spec.point], f, 0.0);
        }
        for (b, spec) in mech.bodies.iter().enumerate() {
            let a: Vec<f64> = (0..3)
                .map(|i| (xn[b][i] - 2.0 * xk[b][i] + xp[b][i]) / (dt * dt))
                .collect();
            let e = [
                spec.mass * a[0] - acc[b][0],
                spec.mass * a[1] - acc[b][1],
                (spec.inertia * a[2] - acc[b][2]) / mech.length_scale(),
            ];
            for (i, v) in e.iter().enumerate() {
                if v.abs() > worst.0 {
                    worst = (
                        v.abs(),
                        format!(
                            "t = {}, body {}, equation {}: imbalance {v:e}",
                            cur.t,
                            spec.name,
                            ["x", "y", "rotation"][i]
                        ),
                    );
                }
            }
        }
    }
    worst
}
