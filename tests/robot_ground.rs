//! Imported robots on the ground (`fbd_sim::robot`): the generic tree
//! model stepped by the engine with the foot–soil state machine. Every
//! record is checked against the laws it reports — each FBD body's
//! translation balanced by the forces of the row (its joint reactions, its
//! contact forces, its weight), the whole robot's momentum changed by the
//! contact forces and gravity alone, `N ≥ 0`, `|Ft| ≤ μS·N` while
//! sticking, `Ft = −μD·N·ŝ` while sliding (ŝ the step's own slip).

use fbd_contact::StateCode;
use fbd_robot::RobotModel;
use fbd_robot::nalgebra::Vector3;
use fbd_sim::Engine;
use fbd_sim::robot::{RobotData, RobotRecord, RobotSim, step};

fn lab_stand() -> (RobotModel, Vec<f64>, Vec<f64>) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/robots/lab_hexapod_stand.toml");
    let robot = fbd_scenario::robot::load(&path).expect("loads");
    let (q0, qd0) = robot.flight_state();
    (robot.model, q0, qd0)
}

/// Runs `sim` to the end, every record kept.
fn run(sim: &RobotSim) -> (Vec<RobotRecord>, RobotData) {
    let mut data = RobotData::new(sim);
    let mut out = Vec::with_capacity(sim.steps);
    for _ in 0..sim.steps {
        step(sim, &mut data).unwrap_or_else(|e| panic!("{e}"));
        out.push(data.record.clone());
    }
    (out, data)
}

/// What a row of a robot's `trajectory.csv` says, read by column name.
struct Row {
    q: Vec<f64>,
    reaction_force: Vec<Vector3<f64>>,
    reaction_moment: Vec<Vector3<f64>>,
    state: Vec<String>,
    point: Vec<Vector3<f64>>,
    force: Vec<Vector3<f64>>,
    com: Vector3<f64>,
}

/// Writes `text` as a configuration, runs `fbd run` on it and reads its
/// `trajectory.csv` back by column names.
fn run_cli(text: &str, sim: &RobotSim) -> Vec<Row> {
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("robot.toml");
    std::fs::write(&cfg, text).unwrap();
    let out = dir.path().join("out");
    let code = fbd_cli::main_with_args([
        "fbd".to_owned(),
        "run".to_owned(),
        cfg.display().to_string(),
        "--out".to_owned(),
        out.display().to_string(),
    ]);
    assert_eq!(
        format!("{code:?}"),
        format!("{:?}", std::process::ExitCode::SUCCESS)
    );
    let mut rd = csv::Reader::from_path(out.join("trajectory.csv")).unwrap();
    let head = rd.headers().unwrap().clone();
    let col = |name: &str| {
        head.iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name}"))
    };
    let model = &sim.mech.model;
    let mut q_cols: Vec<usize> = ["rx", "ry", "rz", "phi_x", "phi_y", "phi_z"]
        .iter()
        .map(|c| col(c))
        .collect();
    q_cols.extend(model.joints.iter().map(|j| col(&j.name)));
    let v3 = |r: &csv::StringRecord, name: &str, s: [&str; 3]| {
        Vector3::from(s.map(|x| r[col(&format!("{name}{x}"))].parse::<f64>().unwrap()))
    };
    rd.records()
        .map(|r| {
            let r = r.unwrap();
            let reaction = |i: usize| &model.joints[sim.mech.reactions[i].joints[0]].name;
            Row {
                q: q_cols.iter().map(|&c| r[c].parse().unwrap()).collect(),
                reaction_force: (0..sim.mech.reactions.len())
                    .map(|i| v3(&r, reaction(i), ["_fx", "_fy", "_fz"]))
                    .collect(),
                reaction_moment: (0..sim.mech.reactions.len())
                    .map(|i| v3(&r, reaction(i), ["_mx", "_my", "_mz"]))
                    .collect(),
                state: sim
                    .mech
                    .contacts
                    .iter()
                    .map(|c| r[col(&format!("{}_state", c.name))].to_owned())
                    .collect(),
                point: sim
                    .mech
                    .contacts
                    .iter()
                    .map(|c| v3(&r, &c.name, ["_x", "_y", "_z"]))
                    .collect(),
                force: sim
                    .mech
                    .contacts
                    .iter()
                    .map(|c| v3(&r, &c.name, ["_fx", "_fy", "_fz"]))
                    .collect(),
                com: v3(&r, "com", ["_x", "_y", "_z"]),
            }
        })
        .collect()
}

/// The largest violation (N, and N·m over the length scale) over `rows`
/// of: each FBD body's translation (`m·Δ²c/Δt² = m·g + Σ forces`) and
/// rotation (the change of its discrete angular momentum about its centre
/// of mass, `(L[k+½] − L[k−½])/Δt`, equals the moments of the row about it:
/// reaction moments and forces at the joint origins, contact forces at
/// their points), the whole robot's centre of mass (`M·Δ²C/Δt² = M·g + Σ
/// contact forces`), and the contact laws (`N ≥ 0`; `|Ft| ≤ μS·N` while
/// sticking; `Ft = −μD·N·ŝ` while sliding, ŝ the step's own slip; no force
/// while free). Everything is recomputed from the rows alone.
fn audit(sim: &RobotSim, rows: &[Row]) -> [f64; 4] {
    use fbd_dynamics::spatial::half_momentum_value;
    let mech = &sim.mech;
    let model = &mech.model;
    let dt = sim.params.dt;
    let g = Vector3::new(0.0, -sim.params.gravity, 0.0);
    let length = mech.length_scale();
    let mut kin = fbd_dynamics::tree::kin::TreeKin::new(model);
    let poses: Vec<_> = rows
        .iter()
        .map(|r| {
            kin.eval(model, &r.q);
            (
                mech.bodies
                    .iter()
                    .map(|b| (kin.com[b.model_body], kin.rotation[b.model_body]))
                    .collect::<Vec<_>>(),
                (0..mech.reactions.len())
                    .map(|i| kin.joint_origin[mech.reactions[i].joints[0]])
                    .collect::<Vec<_>>(),
            )
        })
        .collect();
    let friction = sim.params.friction;
    let (mut body_err, mut turn_err, mut com_err, mut law_err) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for k in 1..rows.len() - 1 {
        let r = &rows[k];
        let (bodies, joints) = &poses[k];
        for (b, body) in mech.bodies.iter().enumerate() {
            let (c, rot) = bodies[b];
            let acc = (poses[k + 1].0[b].0 - 2.0 * c + poses[k - 1].0[b].0) / (dt * dt);
            let mut f = body.mass * g;
            let mut m = Vector3::zeros();
            for (i, re) in mech.reactions.iter().enumerate() {
                let (fr, mr) = (r.reaction_force[i], r.reaction_moment[i]);
                let arm = joints[i] - c;
                if re.child == b {
                    f += fr;
                    m += mr + arm.cross(&fr);
                }
                if re.parent == b {
                    f -= fr;
                    m -= mr + arm.cross(&fr);
                }
            }
            for (ci, tc) in mech.contacts.iter().enumerate() {
                if tc.body == b {
                    f += r.force[ci];
                    m += (r.point[ci] - c).cross(&r.force[ci]);
                }
            }
            body_err = body_err.max((body.mass * acc - f).norm());
            let l_plus = half_momentum_value(&rot, &poses[k + 1].0[b].1, &body.inertia, dt);
            let l_minus = half_momentum_value(&poses[k - 1].0[b].1, &rot, &body.inertia, dt);
            turn_err = turn_err.max(((l_plus - l_minus) / dt - m).norm() / length);
        }
        let acc = (rows[k + 1].com - 2.0 * r.com + rows[k - 1].com) / (dt * dt);
        let f = mech.total_mass() * g + r.force.iter().sum::<Vector3<f64>>();
        com_err = com_err.max((mech.total_mass() * acc - f).norm());
        for c in 0..r.state.len() {
            let f = r.force[c];
            let (n, ft) = (f.y, Vector3::new(f.x, 0.0, f.z));
            match r.state[c].as_str() {
                "ST1" => law_err = law_err.max(f.norm()),
                "ST2" => law_err = law_err.max(-n).max(ft.norm() - friction.mu_static * n),
                "ST3" => {
                    let s = rows[k + 1].point[c] - r.point[c];
                    let s = Vector3::new(s.x, 0.0, s.z);
                    let want = if s.norm() > 1e-9 {
                        -friction.mu_dynamic * n * s / s.norm()
                    } else {
                        ft
                    };
                    law_err = law_err.max(-n).max((ft - want).norm());
                }
                other => panic!("state {other}"),
            }
        }
    }
    [body_err, turn_err, com_err, law_err]
}

/// Prints the audit of `run` and asserts each part within 1e-6 of the
/// weight (N).
fn assert_exact(run: &str, audit: [f64; 4], weight: f64) {
    let [body, turn, com, law] = audit;
    eprintln!("{run}: body {body:.3e} N, rotation {turn:.3e} N, com {com:.3e} N, laws {law:.3e} N");
    for (what, v) in ["translation", "rotation", "centre of mass", "contact laws"]
        .into_iter()
        .zip(audit)
    {
        assert!(v < 1e-6 * weight, "{run}: {what}: {v} N");
    }
}

/// The configuration text of the lab hexapod under PD (kp 20, kd 0.2) on
/// flat ground of friction `mu` from `q0` (root and joint angles), the
/// root's velocity and angular velocity (deg/s).
fn lab_config(
    q0: &[f64],
    velocity: [f64; 3],
    omega_deg: [f64; 3],
    mu: [f64; 2],
    duration: f64,
) -> String {
    let (model, _, _) = lab_stand();
    let urdf =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/robots/lab_hexapod.urdf");
    let joints: Vec<String> = model
        .joints
        .iter()
        .enumerate()
        .map(|(j, joint)| format!("{} = {:?}", joint.name, q0[6 + j].to_degrees()))
        .collect();
    format!(
        "model = \"robot\"\n[robot]\nurdf = \"{}\"\n[initial]\nposition = {:?}\nphi_deg = {:?}\n\
         velocity = {velocity:?}\nomega_deg = {omega_deg:?}\njoints_deg = {{ {} }}\n\
         [terrain]\nkind = \"flat\"\nmu_static = {:?}\nmu_dynamic = {:?}\n\
         [control]\nkind = \"pd\"\nkp = 20.0\nkd = 0.2\n[time]\ndt = 0.001\nduration = {duration:?}\n",
        urdf.display(),
        [q0[0], q0[1], q0[2]],
        [q0[3].to_degrees(), q0[4].to_degrees(), q0[5].to_degrees()],
        joints.join(", "),
        mu[0],
        mu[1]
    )
}

/// Runs `text` in the library (every record) and through `fbd run` (its
/// `trajectory.csv` read back), checks that the two agree and audits the
/// CSV's rows ([`audit`]).
fn check(text: &str) -> (RobotSim, Vec<RobotRecord>, RobotData, [f64; 4]) {
    let robot =
        fbd_scenario::robot::load_str(text, std::path::Path::new("robot.toml")).expect("loads");
    let sim = robot.sim().expect("valid");
    let (records, data) = run(&sim);
    let rows = run_cli(text, &sim);
    assert_eq!(rows.len(), records.len());
    for (a, b) in rows.iter().zip(&records) {
        assert_eq!(
            a.q, b.q,
            "the CSV holds the records' values to the last bit"
        );
    }
    let audit = audit(&sim, &rows);
    (sim, records, data, audit)
}

#[test]
fn lab_hexapod_stands_under_pd_with_every_row_balanced() {
    let (model, q0, _) = lab_stand();
    let text = lab_config(&q0, [0.0; 3], [0.0; 3], [0.8, 0.6], 1.0);
    let (_, rows, data, [body, turn, com, law]) = check(&text);
    let weight = model.mass() * 9.81;
    let last = rows.last().expect("rows");
    let total: f64 = last.contacts.iter().map(|c| c.force[1]).sum();
    assert!(
        (total - weight).abs() < 1e-6 * weight,
        "at rest the feet carry the weight: {total} vs {weight} N"
    );
    assert!(data.events.is_empty(), "a robot at rest writes no events");
    assert!(
        last.contacts.iter().all(|c| c.state == StateCode::St2),
        "every foot sticks"
    );
    assert_exact("stand", [body, turn, com, law], weight);
}

#[test]
fn lab_hexapod_landing_tumbles_within_the_laws() {
    let (model, mut q0, _) = lab_stand();
    // Dropped from 6 cm higher, tilted, spinning and sliding sideways,
    // the joints held by PD at the standing angles: feet touch down one by
    // one, slide and stick.
    q0[1] += 0.06;
    q0[3] = 0.15;
    q0[5] = -0.1;
    let text = lab_config(&q0, [0.4, 0.0, -0.2], [0.0, 86.0, 0.0], [0.5, 0.4], 0.6);
    let (sim, rows, data, [body, turn, com, law]) = check(&text);
    let weight = model.mass() * 9.81;
    let slides = rows
        .iter()
        .flat_map(|r| &r.contacts)
        .filter(|c| c.state == StateCode::St3)
        .count();
    let touched = (0..sim.contacts())
        .filter(|&c| rows.iter().any(|r| r.contacts[c].state != StateCode::St1))
        .count();
    eprintln!(
        "landing: {} events, {} limit events, {} retries, {slides} sliding rows, {touched} feet touched, {} iterations",
        data.events.len(),
        data.limit_events.len(),
        data.retries.len(),
        data.newton_iterations
    );
    assert_eq!(touched, 6, "every foot lands");
    assert!(slides > 0, "some foot slides");
    assert!(data.events.len() < 100, "events stay bounded");
    assert_exact("landing", [body, turn, com, law], weight);
}

/// The lab hexapod walking in a tripod gait (`examples/robots/
/// lab_hexapod_walk.toml`, 3 s): every row within the laws, recomputed
/// from `trajectory.csv`; it walks forward (along −Z) at about its command
/// once the ramp is over, level, every foot lifting off once a period.
#[test]
fn lab_hexapod_walks_in_a_tripod_gait_within_the_laws() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("examples/robots/lab_hexapod_walk.toml"))
        .unwrap()
        .replace(
            "urdf = \"lab_hexapod.urdf\"",
            &format!(
                "urdf = \"{}\"",
                root.join("examples/robots/lab_hexapod.urdf").display()
            ),
        );
    let (sim, rows, data, [body, turn, com, law]) = check(&text);
    let weight = sim.mech.total_mass() * 9.81;
    assert_exact("walk", [body, turn, com, law], weight);
    // From t = 1.5 s (after the start-up and the ramp) to 3 s at 0.1 m/s.
    let at = |t: f64| rows.iter().find(|r| (r.t - t).abs() < 1e-9).unwrap();
    let (a, b) = (at(1.5), at(3.0));
    let speed = -(b.q[2] - a.q[2]) / 1.5;
    let sideways = (b.q[0] - a.q[0]).abs();
    eprintln!(
        "walk: {speed:.4} m/s forward, {sideways:.4} m sideways, {} events",
        data.events.len()
    );
    assert!((0.07..0.13).contains(&speed), "{speed} m/s");
    assert!(sideways < 0.02, "{sideways} m");
    assert!(
        rows.iter()
            .all(|r| r.q[3].abs() < 0.1 && r.q[5].abs() < 0.1),
        "level"
    );
    // Every foot lifts off at every step of its tripod: (3.0 − 0.5)/0.8
    // periods, one lift-off each.
    for c in 0..sim.contacts() {
        let liftoffs = data
            .events
            .iter()
            .filter(|e| e.contact == c && e.to == fbd_contact::StateCode::St1)
            .count();
        assert!(
            (3..=4).contains(&liftoffs),
            "foot {c}: {liftoffs} lift-offs"
        );
    }
}
