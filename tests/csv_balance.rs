//! Every body's Newton–Euler equations balance with the forces written to
//! `trajectory.csv`: the file is produced by `fbd run`, read back, and the
//! translational and rotational balance of each body is recomputed from its
//! columns alone (configurations → accelerations by central differences;
//! joint forces, contact forces, torques and gravity → applied forces).

mod common;

use common::physics::worst_body_imbalance;
use fbd_contact::StateCode;
use fbd_dynamics::PointKind;
use fbd_sim::{Model, PlanarParams, RobotRecord};
use std::path::Path;

fn run_cli(config: Option<&str>, dir: &Path) {
    let mut args = vec!["fbd".to_string(), "run".to_string()];
    if let Some(text) = config {
        let path = dir.join("input.toml");
        std::fs::write(&path, text).unwrap();
        args.push(path.display().to_string());
    }
    args.extend(["--out".to_string(), dir.join("out").display().to_string()]);
    let code = fbd_cli::main_with_args(args);
    assert_eq!(
        format!("{code:?}"),
        format!("{:?}", std::process::ExitCode::SUCCESS)
    );
}

/// Reads `trajectory.csv` into records, using only the contract's columns, the
/// `<point>_state, <point>_fa, <point>_n` columns of the extra contact points
/// of `model` (in its contact order) and the torque columns.
fn read_rows(path: &Path, model: &Model) -> Vec<RobotRecord> {
    let mut rd = csv::Reader::from_path(path).unwrap();
    let head = rd.headers().unwrap().clone();
    let col = |name: &str| {
        head.iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name}"))
    };
    let f = |rec: &csv::StringRecord, name: &str| -> f64 { rec[col(name)].parse().unwrap() };
    let state = |s: &str| match s {
        "ST1" => StateCode::St1,
        "ST2" => StateCode::St2,
        "ST3" => StateCode::St3,
        other => panic!("bad state {other}"),
    };
    let q_cols = [
        "rx", "ry", "phi_z", "theta2_3", "theta3_3", "theta2_4", "theta3_4",
    ];
    let joints = ["hip3", "knee3", "hip4", "knee4"];
    rd.records()
        .enumerate()
        .map(|(k, rec)| {
            let rec = rec.unwrap();
            let lay = model.mech.layout();
            let mut r = RobotRecord::planar(lay.contacts, lay.joints);
            (r.step, r.t) = (k, f(&rec, "t"));
            let q: Vec<f64> = q_cols.iter().map(|c| f(&rec, c)).collect();
            r.set_plane_q(&q);
            // Each contact point's columns by its `{leg, kind}`: the
            // contract's `tip{leg}_x, state{leg}, fa{leg}, n{leg}` for a
            // tip, `{kind}{leg}_state, _fa, _n` for a knee or hip.
            for (c, spec) in model.mech.contacts.iter().enumerate() {
                let leg = spec.leg;
                let [s, fa, n] = if spec.kind == PointKind::Tip {
                    r.contacts[c].point = [
                        f(&rec, &format!("tip{leg}_x")),
                        f(&rec, &format!("tip{leg}_y")),
                        0.0,
                    ];
                    [format!("state{leg}"), format!("fa{leg}"), format!("n{leg}")]
                } else {
                    let kind = spec.kind.as_str();
                    ["state", "fa", "n"].map(|a| format!("{kind}{leg}_{a}"))
                };
                r.contacts[c].state = state(&rec[col(&s)]);
                r.contacts[c].tangential[0] = f(&rec, &fa);
                r.contacts[c].normal = f(&rec, &n);
            }
            for (j, name) in joints.iter().enumerate() {
                r.reaction_force[j] = [
                    f(&rec, &format!("{name}_fx")),
                    f(&rec, &format!("{name}_fy")),
                    0.0,
                ];
                r.torque[j] = f(&rec, &format!("tau_{name}"));
                r.stop[j] = f(&rec, &format!("stop_{name}"));
            }
            r
        })
        .collect()
}

#[test]
fn default_run_balances_from_the_csv() {
    let dir = tempfile::tempdir().unwrap();
    run_cli(None, dir.path());
    let model = Model::planar(&PlanarParams::default()).unwrap();
    let rows = read_rows(&dir.path().join("out/trajectory.csv"), &model);
    assert_eq!(rows.len(), 101);
    // The run exercises knee and hip contacts: they carry load at the end.
    let last = rows.last().unwrap();
    let n: Vec<f64> = last.contacts.iter().map(|c| c.normal).collect();
    assert!(n[2..6].iter().sum::<f64>() > 50.0, "{n:?}");
    let (worst, at) = worst_body_imbalance(&model, &rows);
    assert!(worst < 1e-6, "{at}");
    // The check has teeth: a 1 N error in one written force is caught.
    let mut broken = rows.clone();
    broken[25].reaction_force[1][0] += 1.0;
    assert!(worst_body_imbalance(&model, &broken).0 > 0.5);
}

#[test]
fn tumbling_flight_balances_from_the_csv() {
    let config = r#"
model = "planar"
[time]
dt = 0.005
duration = 0.5
[terrain]
kind = "none"
[initial]
position = [0.0, 0.6]
velocity = [0.7, 1.5]
phi_z_deg = 10.0
omega_z_deg = 120.0
[initial.leg3]
theta_deg = [10.0, 245.0]
rate_deg = [-170.0, 230.0]
[initial.leg4]
theta_deg = [-5.0, 255.0]
rate_deg = [140.0, -60.0]
"#;
    let dir = tempfile::tempdir().unwrap();
    run_cli(Some(config), dir.path());
    // The mechanism (bodies, joints, contact points) is what the balance
    // needs; the initial state is read from the file.
    let p = PlanarParams {
        dt: 0.005,
        terrain: fbd_contact::Terrain::None,
        ..PlanarParams::default()
    };
    let model = Model::planar(&p).unwrap();
    let rows = read_rows(&dir.path().join("out/trajectory.csv"), &model);
    // Joint forces are far from zero in a tumbling flight.
    let peak = rows
        .iter()
        .flat_map(|r| r.reaction_force.iter().copied())
        .map(|f| f[0].hypot(f[1]))
        .fold(0.0, f64::max);
    assert!(peak > 1.0, "peak joint force {peak} N");
    let (worst, at) = worst_body_imbalance(&model, &rows);
    assert!(worst < 1e-6, "{at}");
}
