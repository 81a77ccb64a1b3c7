//! `viewer.html` and the plots of `fbd run`, end to end: the page embeds
//! what `trajectory.csv` says (positions, states, forces), `fbd view DIR`
//! rebuilds the same page from the files, long runs are decimated keeping
//! every state change, and the plots show every contact point that
//! touched. The drawing itself is tested in a real browser by
//! `scripts/test-browser.sh`.

mod common;

use common::{example, fbd, s, scene, stderr, write};
use std::collections::HashMap;
use std::path::Path;

/// `trajectory.csv` as a header index and rows of fields.
fn csv(dir: &Path) -> (HashMap<String, usize>, Vec<Vec<String>>) {
    let (header, rows) = common::trajectory_fields(dir);
    let header = header
        .into_iter()
        .enumerate()
        .map(|(i, h)| (h, i))
        .collect();
    (header, rows)
}

fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap()
}

/// Index of the drawn point `name` in the scene.
fn point(scene: &serde_json::Value, name: &str) -> usize {
    scene["points"]
        .as_array()
        .unwrap()
        .iter()
        .position(|p| p == name)
        .unwrap_or_else(|| panic!("no drawn point {name}"))
}

/// Drawn position of point `i` at frame `k`.
fn at(scene: &serde_json::Value, k: usize, i: usize) -> [f64; 3] {
    let p = &scene["p"][k];
    [f(&p[3 * i]), f(&p[3 * i + 1]), f(&p[3 * i + 2])]
}

/// Checks the page against the CSV for a planar run; returns the frames.
fn check_planar(dir: &Path) -> usize {
    let sc = scene(dir);
    let (h, rows) = csv(dir);
    let n = sc["t"].as_array().unwrap().len();
    assert_eq!(sc["rows"].as_u64().unwrap() as usize, rows.len());
    let contacts: Vec<(String, usize)> = sc["contacts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            (
                c["name"].as_str().unwrap().to_owned(),
                c["point"].as_u64().unwrap() as usize,
            )
        })
        .collect();
    let (tip3, tip4, body) = (point(&sc, "tip3"), point(&sc, "tip4"), point(&sc, "body"));
    let col = |row: &[String], name: &str| -> f64 { row[h[name]].parse().unwrap() };
    for k in 0..n {
        let r = sc["row"][k].as_u64().unwrap() as usize;
        let row = &rows[r];
        let t = col(row, "t");
        assert!((f(&sc["t"][k]) - t).abs() < 1e-9, "frame {k}: time");
        for (p, x, y) in [
            (tip3, "tip3_x", "tip3_y"),
            (tip4, "tip4_x", "tip4_y"),
            (body, "rx", "ry"),
        ] {
            let d = at(&sc, k, p);
            assert!(
                (d[0] - col(row, x)).abs() < 1e-6 && (d[1] - col(row, y)).abs() < 1e-6,
                "frame {k} (row {r}): {x} drawn at {d:?}, trajectory.csv has ({}, {})",
                col(row, x),
                col(row, y)
            );
        }
        // States and forces of every contact point: the drawn force,
        // projected on the flat ground's tangent and normal, is (fa, n).
        let states = sc["state"][k].as_str().unwrap().as_bytes();
        for (c, (name, _)) in contacts.iter().enumerate() {
            let (s, fa, nn) = match name.strip_prefix("tip") {
                Some(l) => (format!("state{l}"), format!("fa{l}"), format!("n{l}")),
                None => (
                    format!("{name}_state"),
                    format!("{name}_fa"),
                    format!("{name}_n"),
                ),
            };
            assert_eq!(
                format!("ST{}", states[c] as char),
                row[h[&s]],
                "frame {k}: state of {name}"
            );
            let fx = f(&sc["fc"][k][3 * c]);
            let fy = f(&sc["fc"][k][3 * c + 1]);
            assert!(
                (fx - col(row, &fa)).abs() < 1e-5 && (fy - col(row, &nn)).abs() < 1e-5,
                "frame {k}: force on {name} drawn ({fx}, {fy}), trajectory.csv ({}, {})",
                col(row, &fa),
                col(row, &nn)
            );
        }
    }
    n
}

#[test]
fn default_run_page_shows_every_row_as_the_csv_has_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = fbd(&["run", "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, rows) = csv(&out);
    assert_eq!(check_planar(&out), rows.len());
    let sc = scene(&out);
    // Every contact event of events.csv is marked, at its frame.
    let events = std::fs::read_to_string(out.join("events.csv")).unwrap();
    let contact_events = events
        .lines()
        .skip(1)
        .filter(|l| l.split(',').nth(2).is_some_and(|s| s.starts_with("ST")))
        .count();
    assert_eq!(sc["events"].as_array().unwrap().len(), contact_events);
    for e in sc["events"].as_array().unwrap() {
        let k = e["frame"].as_u64().unwrap() as usize;
        assert!((f(&sc["t"][k]) - f(&e["t"])).abs() < 1e-9, "{e}");
    }
    // The page is self-contained: no external script, style or fetch.
    let page = std::fs::read_to_string(out.join("viewer.html")).unwrap();
    // (The browser test checks that it makes no request at all.)
    for bad in ["<script src", "<link", "<img", "<iframe", "@import"] {
        assert!(!page.contains(bad), "viewer.html contains {bad}");
    }
}

#[test]
fn fbd_view_rebuilds_the_same_page_from_the_files() {
    let dir = tempfile::tempdir().unwrap();
    for (args, name) in [
        (vec!["run"], "planar"),
        (vec!["run", &example("pd_stand.toml")], "pd"),
        (vec!["run", &example("hexapod_tripod.toml")], "hexapod"),
    ] {
        let out = dir.path().join(name);
        let mut a = args.clone();
        a.extend(["--out", s(&out)]);
        let o = fbd(&a);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let written = std::fs::read(out.join("viewer.html")).unwrap();
        std::fs::remove_file(out.join("viewer.html")).unwrap();
        let o = fbd(&["view", s(&out)]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let rebuilt = std::fs::read(out.join("viewer.html")).unwrap();
        assert!(
            written == rebuilt,
            "{name}: fbd view wrote a different page"
        );
    }
}

/// The names of the scene's capsules, `a–b`, sorted.
fn capsules(sc: &serde_json::Value) -> Vec<String> {
    let names = sc["points"].as_array().unwrap();
    let mut out: Vec<String> = sc["lines"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| {
            let name = |k: &str| names[l[k].as_u64().unwrap() as usize].as_str().unwrap();
            format!("{}–{}", name("a"), name("b"))
        })
        .collect();
    out.sort();
    out
}

/// The hexapod's page is the one 3D scene of every robot: the generic
/// robot fields (capsules of a radius, the plate, the labels, the heading)
/// of its D-H model, the drawn points where `trajectory.csv` puts them.
fn check_hexapod_scene(sc: &serde_json::Value, legs: &[usize]) {
    assert_eq!(sc["model"], "robot");
    let radius = f(&sc["radius"]);
    assert!(radius > 0.0 && radius < 0.05, "capsule radius {radius} m");
    // The body hexagon as the root's outline, filled.
    let plate: Vec<usize> = sc["plate"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap() as usize)
        .collect();
    let corners: Vec<usize> = (1..=6).map(|k| point(sc, &format!("corner{k}"))).collect();
    assert_eq!(plate, corners);
    assert_eq!(sc["heading"].as_u64(), Some(point(sc, "corner2") as u64));
    assert_eq!(point(sc, "base"), 0);
    // A leg number beside each hip (the joint θ1 of the leg).
    let labels: Vec<(String, usize)> = sc["labels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| {
            (
                l["text"].as_str().unwrap().to_owned(),
                l["point"].as_u64().unwrap() as usize,
            )
        })
        .collect();
    let want: Vec<(String, usize)> = legs
        .iter()
        .map(|n| (n.to_string(), point(sc, &format!("theta1_{n}"))))
        .collect();
    assert_eq!(labels, want);
    // The capsules: the hexagon, and per leg the upper link (θ2's origin,
    // the hip, to θ3's, the knee) and the lower link (knee to foot); the
    // coxa (θ1 to θ2, one point) has no length.
    let mut want: Vec<String> = (1..=6)
        .map(|k| format!("corner{k}–corner{}", k % 6 + 1))
        .collect();
    for n in legs {
        want.push(format!("theta2_{n}–theta3_{n}"));
        want.push(format!("theta3_{n}–tip{n}"));
    }
    want.sort();
    assert_eq!(capsules(sc), want);
}

#[test]
fn hexapod_page_draws_the_feet_where_the_csv_has_them() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("hexapod");
    let o = fbd(&["run", &example("hexapod_tripod.toml"), "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let sc = scene(&out);
    check_hexapod_scene(&sc, &[1, 2, 3, 4, 5, 6]);
    // A kinematic gait: swing and stance, no forces.
    assert_eq!(sc["state_names"], serde_json::json!(["swing", "stance"]));
    assert!(sc.get("dynamic").is_none());
    let (h, rows) = csv(&out);
    let n = sc["t"].as_array().unwrap().len();
    assert_eq!(n, rows.len());
    let col = |row: &[String], name: &str| -> f64 { row[h[name]].parse().unwrap() };
    let feet: Vec<usize> = (1..=6).map(|l| point(&sc, &format!("tip{l}"))).collect();
    let contacts: Vec<usize> = sc["contacts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["point"].as_u64().unwrap() as usize)
        .collect();
    assert_eq!(contacts, feet);
    for k in 0..n {
        let row = &rows[k];
        let base = at(&sc, k, 0);
        for (a, c) in ["rx", "ry", "rz"].iter().enumerate() {
            assert!((base[a] - col(row, c)).abs() < 6e-7, "frame {k}: base {c}");
        }
        let com = &sc["com"][k];
        for (a, c) in ["com_x", "com_y", "com_z"].iter().enumerate() {
            assert!((f(&com[a]) - col(row, c)).abs() < 6e-7, "frame {k}: {c}");
        }
        for (l, &p) in feet.iter().enumerate() {
            let d = at(&sc, k, p);
            for (a, axis) in ["x", "y", "z"].iter().enumerate() {
                let want = col(row, &format!("foot{}_{axis}", l + 1));
                assert!(
                    (d[a] - want).abs() < 1e-6,
                    "frame {k}: foot{} {axis} drawn {} (trajectory.csv {want})",
                    l + 1,
                    d[a]
                );
            }
            let stance = row[h[&format!("stance{}", l + 1)]] == "1";
            let drawn = sc["state"][k].as_str().unwrap().as_bytes()[l] == b'2';
            assert_eq!(stance, drawn, "frame {k}: stance of leg {}", l + 1);
        }
    }
    let panels: Vec<&str> = sc["panels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["title"].as_str().unwrap())
        .collect();
    assert_eq!(
        panels,
        [
            "Body height Ry (m)",
            "Hip-lift angles θ2 (°)",
            "Knee angles θ3 (°)",
            "Stability margin (m)"
        ]
    );
}

/// A dynamic hexapod configuration of legs 3 and 4 dropped onto the
/// ground, feet, knees and hips contact points.
const DROP: &str = "model = \"hexapod\"\nlegs = [3, 4]\n[time]\ndt = 0.001\nduration = 0.15\n\
[initial]\nposition = [0.0, 0.4, 0.0]\n[initial.leg3]\ntheta_deg = [0.0, 0.0, 250.0]\n\
[initial.leg4]\ntheta_deg = [0.0, 0.0, 250.0]\n";

#[test]
fn dynamic_hexapod_page_is_the_robot_scene_of_its_model() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "drop.toml", DROP);
    let out = dir.path().join("drop");
    let o = fbd(&["run", s(&cfg), "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let page = std::fs::read(out.join("viewer.html")).unwrap();
    let sc = scene(&out);
    check_hexapod_scene(&sc, &[3, 4]);
    assert_eq!(sc["dynamic"], true);
    assert!(sc.get("state_names").is_none());
    // The contact points: the feet, then leg by leg the knee and the hip.
    let names: Vec<&str> = sc["contacts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["tip3", "tip4", "knee3", "hip3", "knee4", "hip4"]);
    let joints: Vec<&str> = sc["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert_eq!(joints, ["hip3", "knee3", "hip4", "knee4"]);
    let (h, rows) = csv(&out);
    let n = sc["t"].as_array().unwrap().len();
    assert_eq!(n, rows.len());
    let col = |row: &[String], name: &str| -> f64 { row[h[name]].parse().unwrap() };
    let columns = [
        ("tip3", "state3", "foot3"),
        ("tip4", "state4", "foot4"),
        ("knee3", "kneepoint3_state", "kneepoint3"),
        ("hip3", "hippoint3_state", "hippoint3"),
        ("knee4", "kneepoint4_state", "kneepoint4"),
        ("hip4", "hippoint4_state", "hippoint4"),
    ];
    let mut touched = 0;
    for k in 0..n {
        let row = &rows[k];
        let state = sc["state"][k].as_str().unwrap().as_bytes();
        for (c, (name, st, force)) in columns.iter().enumerate() {
            assert_eq!(
                row[h[*st]],
                format!("ST{}", state[c] as char),
                "frame {k}: {name}"
            );
            for (a, axis) in ["fx", "fy", "fz"].iter().enumerate() {
                let want = col(row, &format!("{force}_{axis}"));
                let drawn = f(&sc["fc"][k][3 * c + a]);
                assert!((drawn - want).abs() < 1e-6, "frame {k}: {name} {axis}");
            }
        }
        touched += state.iter().filter(|&&s| s != b'1').count();
        for (l, leg) in [3, 4].iter().enumerate() {
            let d = at(&sc, k, point(&sc, &format!("tip{leg}")));
            for (a, axis) in ["x", "y", "z"].iter().enumerate() {
                let want = col(row, &format!("foot{leg}_{axis}"));
                assert!((d[a] - want).abs() < 1e-6, "frame {k}: foot {leg} {axis}");
            }
            // The joint-force arrows: the hip's and the knee's forces.
            for (j, joint) in ["hip", "knee"].iter().enumerate() {
                for (a, axis) in ["fx", "fy", "fz"].iter().enumerate() {
                    let want = col(row, &format!("{joint}{leg}_{axis}"));
                    let drawn = f(&sc["fj"][k][3 * (2 * l + j) + a]);
                    assert!(
                        (drawn - want).abs() < 1e-6,
                        "frame {k}: {joint}{leg} {axis}"
                    );
                }
            }
        }
    }
    assert!(touched > 0, "no contact point touched the ground");
    // `fbd view` writes the same page from the files.
    std::fs::remove_file(out.join("viewer.html")).unwrap();
    let o = fbd(&["view", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read(out.join("viewer.html")).unwrap() == page);
}

#[test]
fn long_runs_are_decimated_keeping_every_state_change() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "long.toml", "[time]\nduration = 25.0\n");
    let out = dir.path().join("out");
    let o = fbd(&["run", s(&cfg), "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let sc = scene(&out);
    let (h, rows) = csv(&out);
    assert!(
        rows.len() > fbd_cli::viewer::MAX_FRAMES,
        "{} rows",
        rows.len()
    );
    let frames: Vec<usize> = sc["row"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r.as_u64().unwrap() as usize)
        .collect();
    assert!(frames.len() <= fbd_cli::viewer::MAX_FRAMES);
    assert_eq!(frames.last(), Some(&(rows.len() - 1)));
    let states: Vec<usize> = h
        .iter()
        .filter(|(k, _)| k.starts_with("state") || k.ends_with("_state"))
        .map(|(_, v)| *v)
        .collect();
    for r in 1..rows.len() {
        if states.iter().any(|&c| rows[r][c] != rows[r - 1][c]) {
            assert!(
                frames.binary_search(&r).is_ok(),
                "row {r}: a state changes and the frame was dropped"
            );
        }
    }
    check_planar(&out);
}

#[test]
fn plots_show_every_contact_point_that_touched() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = fbd(&["run", "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (h, rows) = csv(&out);
    let forces = std::fs::read_to_string(out.join("forces.svg")).unwrap();
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    for name in summary["contact_points"].as_array().unwrap() {
        let name = name.as_str().unwrap();
        let state = match name.strip_prefix("tip") {
            Some(l) => format!("state{l}"),
            None => format!("{name}_state"),
        };
        let touched = rows.iter().any(|r| r[h[&state]] != "ST1");
        assert_eq!(
            forces.contains(&format!(">\nn {name}\n<")),
            touched,
            "forces.svg and the contact of {name}"
        );
    }
    for f in ["joints.svg", "energy.svg"] {
        let svg = std::fs::read_to_string(out.join(f)).unwrap();
        assert!(svg.starts_with("<svg"), "{f}");
    }
    // Passive: no torques.svg.
    assert!(!out.join("torques.svg").exists());
    let pd = dir.path().join("pd");
    let o = fbd(&["run", &example("pd_stand.toml"), "--out", s(&pd)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(pd.join("torques.svg").is_file());
}

#[test]
fn view_of_a_folder_without_a_run_is_a_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    let o = fbd(&["view", s(dir.path())]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(e.contains("config.toml"), "{e}");
    assert!(!dir.path().join("viewer.html").exists());

    // A trajectory without the columns of its configuration.
    let out = dir.path().join("out");
    assert!(fbd(&["run", "--out", s(&out)]).status.success());
    std::fs::write(out.join("trajectory.csv"), "t,rx\n0,0\n").unwrap();
    std::fs::remove_file(out.join("viewer.html")).unwrap();
    let o = fbd(&["view", s(&out)]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(e.contains("trajectory.csv") && e.contains("ry"), "{e}");
    assert!(!out.join("viewer.html").exists());

    let o = fbd(&["view", s(&dir.path().join("missing"))]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}
