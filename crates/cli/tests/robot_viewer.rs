//! `fbd view` of an imported robot's run: the lab hexapod in flight
//! (examples/robots/lab_hexapod_flight.toml), its bodies drawn as capsules
//! whose ends are the forward kinematics of `trajectory.csv`.

mod common;

use std::collections::HashMap;
use std::path::Path;

use common::{example, fbd, s, scene, stderr, stdout};
use fbd_robot::forward::{RobotData, base_frame, forward};
use fbd_robot::nalgebra::Vector3;

/// `trajectory.csv`: column index by name, rows of numbers (NaN for text).
fn table(dir: &Path) -> (HashMap<String, usize>, Vec<Vec<f64>>) {
    let (header, rows) = common::trajectory(dir);
    let header = header
        .into_iter()
        .enumerate()
        .map(|(i, h)| (h, i))
        .collect();
    (header, rows)
}

fn flight(out: &Path) {
    let o = fbd(&[
        "run",
        &example("robots/lab_hexapod_flight.toml"),
        "--out",
        s(out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn fbd_view_draws_a_flying_robot_as_capsules_at_its_forward_kinematics() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("flight");
    flight(&out);
    let _ = std::fs::remove_file(out.join("viewer.html"));
    let o = fbd(&["view", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        stdout(&o).trim(),
        out.join("viewer.html").display().to_string()
    );
    let sc = scene(&out);
    assert_eq!(sc["model"], "robot");

    // The model, independently: the run's own config.toml.
    let robot = fbd_cli::config::robot::load(&out.join("config.toml")).unwrap();
    let model = &robot.model;
    let (col, rows) = table(&out);
    // 0.5 s at 1 ms: 501 rows, every one a frame (fewer than MAX_FRAMES).
    assert_eq!(rows.len(), 501);
    assert_eq!(sc["rows"].as_u64(), Some(rows.len() as u64));
    let frames = sc["t"].as_array().unwrap().len();
    assert_eq!(frames, rows.len());
    assert_eq!(sc["p"].as_array().unwrap().len(), frames);

    // Each drawn point's position by kind, from the CSV row alone.
    let names: Vec<String> = sc["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap().to_owned())
        .collect();
    let lines: Vec<(usize, usize)> = sc["lines"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| {
            (
                l["a"].as_u64().unwrap() as usize,
                l["b"].as_u64().unwrap() as usize,
            )
        })
        .collect();
    // The lab hexapod: 6 legs × (coxa, femur, tibia); the root's ring
    // through the 6 coxa joints; coxa–femur, femur–tibia, tibia–foot per
    // leg (the feet are its contact points).
    assert_eq!(model.joints.len(), 18);
    assert_eq!(model.contacts.len(), 6);
    assert_eq!(lines.len(), 6 + 3 * 6, "{lines:?}");
    let radius = sc["radius"].as_f64().unwrap();
    assert!(radius > 0.0 && radius < 0.05, "capsule radius {radius} m");

    let mut data = RobotData::new(model);
    let mut worst = 0.0f64;
    for f in [0, frames / 3, 2 * frames / 3, frames - 1] {
        let r = sc["row"][f].as_u64().unwrap() as usize;
        let row = &rows[r];
        let v = |c: &str| row[col[c]];
        let base = base_frame(
            [v("rx"), v("ry"), v("rz")],
            [v("phi_x"), v("phi_y"), v("phi_z")],
        );
        let q: Vec<f64> = model.joints.iter().map(|j| v(&j.name)).collect();
        forward(model, &base, &q, &mut data);
        let want = |name: &str| -> Vector3<f64> {
            if name == "base" {
                return Vector3::new(v("rx"), v("ry"), v("rz"));
            }
            if let Some(j) = model.joint_index(name) {
                return data.frames[model.joints[j].child].translation.vector;
            }
            if let Some(k) = model.contacts.iter().position(|c| c.name == name) {
                return data.contacts[k];
            }
            let body = name.strip_suffix("_com").expect("a known point");
            data.com(model, model.body_index(body).unwrap())
        };
        let p = sc["p"][f].as_array().unwrap();
        let at = |i: usize| {
            Vector3::new(
                p[3 * i].as_f64().unwrap(),
                p[3 * i + 1].as_f64().unwrap(),
                p[3 * i + 2].as_f64().unwrap(),
            )
        };
        for &(a, b) in &lines {
            for i in [a, b] {
                let e = (at(i) - want(&names[i])).norm();
                worst = worst.max(e);
                assert!(e < 1e-6, "frame {f} point {}: off by {e} m", names[i]);
            }
        }
        // The whole robot's centre of mass.
        let com = data.total_com(model);
        for (a, w) in com.iter().enumerate() {
            let got = sc["com"][f][a].as_f64().unwrap();
            assert!((got - w).abs() < 1e-6, "frame {f} com {a}: {got} vs {w}");
        }
        // The time of the row.
        assert!((sc["t"][f].as_f64().unwrap() - v("t")).abs() < 1e-9);
    }
    eprintln!("largest capsule end error {worst:e} m");
    // Capsule ends: every leg's tibia reaches its foot, and every segment
    // keeps its length (both ends are fixed in one body).
    let len = |f: usize, (a, b): (usize, usize)| {
        let p = sc["p"][f].as_array().unwrap();
        let g = |i: usize, k: usize| p[3 * i + k].as_f64().unwrap();
        (0..3)
            .map(|k| (g(a, k) - g(b, k)).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    for &l in &lines {
        assert!(len(0, l) > 1e-6, "zero-length capsule {l:?}");
        assert!(
            (len(0, l) - len(frames - 1, l)).abs() < 3e-6,
            "capsule {l:?} changed length"
        );
    }
    for c in &model.contacts {
        let k = names.iter().position(|n| *n == c.name).unwrap();
        assert!(
            lines.iter().any(|&(_, b)| b == k),
            "no capsule ends at {}",
            c.name
        );
    }
}

#[test]
fn fbd_view_of_a_robot_without_its_trajectory_or_a_joint_column_is_one_line_error() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("flight");
    flight(&out);
    // A joint column missing.
    let text = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    std::fs::write(
        out.join("trajectory.csv"),
        text.replacen("lf_femur_joint,", "lf_femur_joint_renamed,", 1),
    )
    .unwrap();
    let o = fbd(&["view", s(&out)]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert_eq!(e.trim().lines().count(), 1, "{e}");
    assert!(e.contains("no column `lf_femur_joint`"), "{e}");
    // No trajectory at all.
    std::fs::remove_file(out.join("trajectory.csv")).unwrap();
    let o = fbd(&["view", s(&out)]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert_eq!(e.trim().lines().count(), 1, "{e}");
    assert!(e.contains("trajectory.csv: missing"), "{e}");
}

#[test]
fn fbd_view_of_a_robot_on_the_ground_colours_its_contacts_and_draws_their_forces() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("pd");
    let o = fbd(&[
        "run",
        &example("robots/lab_hexapod_pd.toml"),
        "--out",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = fbd(&["view", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let sc = scene(&out);
    assert_eq!(sc["model"], "robot");
    assert_eq!(sc["dynamic"], true);
    // A flat ground under the robot (y = 0).
    assert_eq!(sc["terrain"]["kind"], "grid");
    assert!(
        sc["terrain"]["y"]
            .as_array()
            .unwrap()
            .iter()
            .all(|y| y.as_f64() == Some(0.0))
    );
    let robot = fbd_cli::config::robot::load(&out.join("config.toml")).unwrap();
    let names: Vec<&str> = robot
        .model
        .contacts
        .iter()
        .map(|c| c.name.as_str())
        .collect();
    assert_eq!(names.len(), 6);
    let text = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let mut lines = text.lines();
    let col: HashMap<&str, usize> = lines
        .next()
        .unwrap()
        .split(',')
        .enumerate()
        .map(|(i, h)| (h, i))
        .collect();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let frames = sc["t"].as_array().unwrap().len();
    assert_eq!(frames, rows.len());
    let mut loaded = 0;
    for f in 0..frames {
        let row = &rows[sc["row"][f].as_u64().unwrap() as usize];
        let want: String = names
            .iter()
            .map(|c| &row[col[format!("{c}_state").as_str()]][2..])
            .collect();
        assert_eq!(sc["state"][f], want.as_str(), "frame {f}");
        for (k, c) in names.iter().enumerate() {
            for (a, axis) in ["fx", "fy", "fz"].iter().enumerate() {
                let w: f64 = row[col[format!("{c}_{axis}").as_str()]].parse().unwrap();
                let got = sc["fc"][f][3 * k + a].as_f64().unwrap();
                assert!(
                    (got - w).abs() <= 5e-7,
                    "frame {f} {c}_{axis}: {got} vs {w}"
                );
                if a == 1 && w > 1.0 {
                    loaded += 1;
                }
            }
        }
    }
    // The robot stands: its feet carry its weight.
    assert!(loaded > frames, "{loaded} loaded foot-frames of {frames}");
}
