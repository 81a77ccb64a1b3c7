//! `fbd run` of an imported robot in flight: the lab hexapod tossed upward
//! and tumbling with passive joints (examples/robots/lab_hexapod_flight.toml).

mod common;

use std::path::Path;

use common::{example, fbd, s, stderr, write};
use fbd_robot::nalgebra::Vector3;

const G: f64 = 9.81;

/// The example's text with its URDF given by an absolute path, so that it
/// can be written elsewhere.
fn flight_text() -> String {
    let text = std::fs::read_to_string(example("robots/lab_hexapod_flight.toml")).unwrap();
    text.replace(
        "urdf = \"lab_hexapod.urdf\"",
        &format!("urdf = \"{}\"", example("robots/lab_hexapod.urdf")),
    )
}

fn run_ok(config: &str, out: &Path) {
    let o = fbd(&["run", config, "--out", s(out)]);
    assert!(o.status.success(), "{}", stderr(&o));
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap()
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&read(&dir.join("summary.json"))).unwrap()
}

/// The header and the rows of a trajectory without contact states.
fn table(dir: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let (header, rows) = common::trajectory(dir);
    assert!(
        rows.iter().flatten().all(|v| !v.is_nan()),
        "a number in every cell"
    );
    (header, rows)
}

#[test]
fn a_tumbling_flight_writes_every_file_and_its_centre_of_mass_falls_at_g() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("flight");
    run_ok(&example("robots/lab_hexapod_flight.toml"), &out);
    for f in [
        "trajectory.csv",
        "events.csv",
        "summary.json",
        "config.toml",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    assert_eq!(read(&out.join("events.csv")).lines().count(), 1);
    let sm = summary(&out);
    assert_eq!(sm["status"], "ok");
    assert_eq!(sm["model"], "robot");
    assert_eq!(sm["robot"], "lab_hexapod");
    assert!(sm["error"].is_null());
    assert_eq!(sm["steps"], 501);
    assert_eq!(sm["events"], serde_json::json!([]));
    assert!(sm["newton_iterations"].as_u64().unwrap() > 0);

    let (header, rows) = table(&out);
    assert_eq!(rows.len(), 501);
    assert_eq!(
        &header[..8],
        [
            "t",
            "rx",
            "ry",
            "rz",
            "phi_x",
            "phi_y",
            "phi_z",
            "lf_coxa_joint"
        ]
    );
    assert!(header.contains(&"rr_tibia_joint_mz".to_owned()));
    assert_eq!(
        &header[header.len() - 3..],
        ["kinetic", "potential", "newton_iterations"]
    );
    assert!(rows.iter().all(|r| r.len() == header.len()));

    // The whole robot's centre of mass, recomputed from each row's root
    // pose and joint angles, falls at exactly g: the scheme's momentum law
    // (M·(C[k+1] − 2C[k] + C[k−1])/Δt² = M·g), to Newton's tolerance.
    let model = fbd_robot::urdf::load(
        Path::new(&example("robots/lab_hexapod.urdf")),
        fbd_robot::Up::Z,
        &fbd_robot::ContactChoice::CollisionSpheres,
    )
    .unwrap();
    let nj = model.joints.len();
    for (j, joint) in model.joints.iter().enumerate() {
        assert_eq!(header[7 + j], joint.name);
    }
    let mut data = fbd_robot::RobotData::new(&model);
    let com: Vec<Vector3<f64>> = rows
        .iter()
        .map(|r| {
            let base = fbd_robot::forward::base_frame([r[1], r[2], r[3]], [r[4], r[5], r[6]]);
            fbd_robot::forward(&model, &base, &r[7..7 + nj], &mut data);
            data.total_com(&model)
        })
        .collect();
    let dt = rows[1][0] - rows[0][0];
    let mut worst: f64 = 0.0;
    for k in 1..rows.len() - 1 {
        let a = (com[k + 1] - 2.0 * com[k] + com[k - 1]) / (dt * dt);
        worst = worst.max((a + Vector3::new(0.0, G, 0.0)).norm());
    }
    eprintln!("centre of mass: |a + g| up to {worst:e} m/s²");
    assert!(worst < 1e-6, "|a + g| up to {worst} m/s²");
    // It tumbles, its joints swing, and they stay within their limits.
    let last = rows.last().unwrap();
    assert!(
        (last[5] - rows[0][5]).abs() > 0.3,
        "φy {} → {}",
        rows[0][5],
        last[5]
    );
    let swing = (0..nj)
        .map(|j| {
            let (lo, hi) = rows.iter().fold((f64::MAX, f64::MIN), |(lo, hi), r| {
                (lo.min(r[7 + j]), hi.max(r[7 + j]))
            });
            hi - lo
        })
        .fold(0.0, f64::max);
    assert!(swing > 0.3, "largest joint swing {swing} rad");
    // The kinetic and potential energies: the total is kept to O(Δt²).
    let ek = header.len() - 3;
    let e0 = rows[1][ek] + rows[1][ek + 1];
    for r in &rows[1..] {
        assert!((r[ek] + r[ek + 1] - e0).abs() < 1e-3 * e0.abs().max(1.0));
    }
}

#[test]
fn a_flight_repeats_byte_for_byte_also_from_its_config_toml() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = example("robots/lab_hexapod_flight.toml");
    let (a, b, c) = (
        dir.path().join("a"),
        dir.path().join("b"),
        dir.path().join("c"),
    );
    run_ok(&cfg, &a);
    run_ok(&cfg, &b);
    let traj = read(&a.join("trajectory.csv"));
    assert_eq!(traj, read(&b.join("trajectory.csv")));
    assert_eq!(read(&a.join("config.toml")), read(&b.join("config.toml")));
    // The copy names every key, the description by an absolute path.
    let copy = read(&a.join("config.toml"));
    for key in [
        "dt = 0.001",
        "duration = 0.5",
        "kind = \"none\"",
        "stride = 1",
        "gravity = 9.81",
    ] {
        assert!(copy.contains(key), "{key} in {copy}");
    }
    let urdf = std::fs::canonicalize(example("robots/lab_hexapod.urdf")).unwrap();
    assert!(
        copy.contains(&format!("urdf = \"{}\"", urdf.display())),
        "{copy}"
    );
    run_ok(s(&a.join("config.toml")), &c);
    assert_eq!(traj, read(&c.join("trajectory.csv")));
    assert_eq!(copy, read(&c.join("config.toml")));
}

#[test]
fn every_stride_th_step_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full");
    run_ok(&example("robots/lab_hexapod_flight.toml"), &full);
    let cfg = write(
        dir.path(),
        "stride.toml",
        &format!("{}\n[output]\nstride = 7\n", flight_text()),
    );
    let out = dir.path().join("stride");
    run_ok(s(&cfg), &out);
    let all = read(&full.join("trajectory.csv"));
    let all: Vec<&str> = all.lines().collect();
    let some = read(&out.join("trajectory.csv"));
    let some: Vec<&str> = some.lines().collect();
    // 501 steps: rows 0, 7, …, 497.
    assert_eq!(some.len() - 1, 501usize.div_ceil(7));
    assert_eq!(some[0], all[0]);
    for (i, line) in some[1..].iter().enumerate() {
        assert_eq!(*line, all[1 + 7 * i]);
    }
    assert_eq!(summary(&out)["steps"], 501);
}

#[test]
fn bad_keys_and_a_robot_below_ground_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            flight_text().replace("kind = \"none\"", "kind = \"flatt\""),
            "terrain.kind",
        ),
        (
            flight_text()
                .replace("position = [0.0, 0.3, 0.0]", "position = [0.0, 0.05, 0.0]")
                .replace("kind = \"none\"", "kind = \"flat\""),
            "below the terrain",
        ),
        (
            format!("{}\n[control]\nkind = \"pid\"\n", flight_text()),
            "kind",
        ),
        (
            format!(
                "{}\n[control]\nkind = \"pd\"\nkp = 1.0\ntarget_deg = {{ lf_coxa_jiont = 3.0 }}\n",
                flight_text()
            ),
            "control.target_deg.lf_coxa_jiont: no such joint",
        ),
        (
            format!(
                "{}\n[control]\nkind = \"pd\"\nkp = 20.0\nkd = 5.0\n",
                flight_text()
            ),
            "control.kd: makes the explicit joint torques unstable",
        ),
        (
            format!("{}\n[control]\nkind = \"gait\"\n", flight_text()),
            "a gait walks on a terrain",
        ),
        (
            format!(
                "{}\n[control]\nkind = \"gait\"\n[gait]\npattern = \"tripod\"\nsped = 0.1\n",
                flight_text()
            ),
            "unknown field `sped`",
        ),
        (
            format!("{}\n[gait]\npattern = \"tripod\"\n", flight_text()),
            "gait: a [gait] table needs [control] kind = \"gait\"",
        ),
        (flight_text().replace("dt = 0.001", "dt = 0.0"), "time.dt"),
        (
            flight_text().replace("duration = 0.5", "duration = -1.0"),
            "time.duration",
        ),
        (
            format!("{}\n[output]\nstride = 0\n", flight_text()),
            "output.stride",
        ),
    ];
    for (i, (text, want)) in cases.iter().enumerate() {
        let cfg = write(dir.path(), &format!("bad{i}.toml"), text);
        let out = dir.path().join(format!("out{i}"));
        let o = fbd(&["run", s(&cfg), "--out", s(&out)]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        let e = stderr(&o);
        assert_eq!(e.lines().count(), 1, "{e}");
        assert!(e.contains(want), "{e}");
        assert!(!out.join("trajectory.csv").exists());
    }
}

#[test]
fn a_joint_driven_onto_its_limit_is_held_by_its_stop() {
    let dir = tempfile::tempdir().unwrap();
    let text = flight_text().replace("lf_coxa_joint = 40.0", "lf_coxa_joint = 2000.0");
    let cfg = write(dir.path(), "wild.toml", &text);
    let out = dir.path().join("out");
    let o = fbd(&["run", s(&cfg), "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let sm = summary(&out);
    assert_eq!(sm["status"], "ok");
    let events = read(&out.join("events.csv"));
    // 2000°/s from 0 reaches the 60° limit after about 30 ms.
    let arrival = events
        .lines()
        .find(|l| l.contains("lf_coxa_joint_limit,free,max"))
        .unwrap_or_else(|| panic!("no limit event in\n{events}"));
    let t: f64 = arrival.split(',').next().unwrap().parse().unwrap();
    assert!((0.02..0.05).contains(&t), "{t}");
    let (head, rows) = table(&out);
    let c = head.iter().position(|h| h == "lf_coxa_joint").unwrap();
    let upper = 60f64.to_radians();
    assert!(rows.iter().all(|r| r[c] <= upper + 1e-9));
    assert!(rows.iter().any(|r| r[c] > upper - 1e-9));
}

#[test]
fn sigint_stops_a_flight_and_writes_every_file() {
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};
    let dir = tempfile::tempdir().unwrap();
    // At rest in free fall: the joints stay at 0 for as long as it runs.
    let text = format!(
        "model = \"robot\"\n[robot]\nurdf = \"{}\"\n[time]\nduration = 100000.0\n[terrain]\nkind = \"none\"\n[output]\nstride = 1000\n",
        example("robots/lab_hexapod.urdf")
    );
    let cfg = write(dir.path(), "long.toml", &text);
    let out = dir.path().join("out");
    let child = Command::new(env!("CARGO_BIN_EXE_fbd"))
        .args(["run", s(&cfg), "--out", s(&out)])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let temporaries = |d: &Path| {
        std::fs::read_dir(d).map_or(0, |r| {
            r.filter(|e| {
                e.as_ref()
                    .unwrap()
                    .file_name()
                    .to_string_lossy()
                    .ends_with(".tmp")
            })
            .count()
        })
    };
    let start = Instant::now();
    while temporaries(&out) == 0 {
        assert!(start.elapsed() < Duration::from_secs(60), "never started");
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(300));
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    assert!(stderr(&o).contains("interrupted after "), "{}", stderr(&o));
    assert_eq!(temporaries(&out), 0);
    let sm = summary(&out);
    assert_eq!(sm["status"], "interrupted");
    assert!(sm["error"].as_str().unwrap().contains("interrupted"));
    let steps = sm["steps"].as_u64().unwrap() as usize;
    assert!(steps > 0);
    let (_, rows) = table(&out);
    assert_eq!(rows.len(), (steps - 1) / 1000 + 1);
    assert!(out.join("config.toml").is_file() && out.join("events.csv").is_file());
}

/// The lab hexapod dropped onto flat ground (examples/robots/
/// lab_hexapod_drop.toml) with `extra` appended, run into `out`.
fn drop_run(dir: &Path, name: &str, extra: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string(example("robots/lab_hexapod_drop.toml"))
        .unwrap()
        .replace(
            "urdf = \"lab_hexapod.urdf\"",
            &format!("urdf = \"{}\"", example("robots/lab_hexapod.urdf")),
        );
    let cfg = write(dir, &format!("{name}.toml"), &format!("{text}{extra}"));
    let out = dir.join(name);
    run_ok(s(&cfg), &out);
    out
}

/// The largest value of `f(row)` over the rows.
fn peak(rows: &[Vec<f64>], f: impl Fn(&Vec<f64>) -> f64) -> f64 {
    rows.iter().map(f).fold(0.0, f64::max)
}

#[test]
fn a_landing_robots_summary_has_every_figure_of_the_trajectory_and_events() {
    let dir = tempfile::tempdir().unwrap();
    let out = drop_run(dir.path(), "drop", "");
    let sm = summary(&out);
    let (header, rows) = common::trajectory(&out);
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name}"))
    };
    // The keys a robot's summary has always had.
    for key in [
        "status",
        "error",
        "model",
        "robot",
        "dt",
        "duration",
        "steps",
        "steps_planned",
        "stride",
        "rows_written",
        "contact_points",
        "distance",
        "final_height",
        "peak_torque_max",
        "peak_normal_force",
        "first_touchdown",
        "newton_iterations",
        "newton_iterations_per_step",
        "wall_seconds",
        "steps_per_second",
        "symbolic_factorizations",
        "events",
        "retried_steps",
        "substeps",
        "resolved_cycles",
        "max_law_violation",
    ] {
        assert!(sm.get(key).is_some(), "no {key} in {sm}");
    }
    // The hexapod's own keys are not a robot's.
    for key in ["legs", "run", "control"] {
        assert!(sm.get(key).is_none(), "{key} in a robot's summary");
    }
    // The start-up stability check's wall time is timed as the hexapod's.
    let check = sm["stability_check_seconds"].as_f64().unwrap();
    assert!((0.0..1.0).contains(&check), "stability check {check} s");
    assert_eq!(sm["status"], "ok");
    assert_eq!(sm["rows_written"].as_u64().unwrap() as usize, rows.len());
    assert_eq!(sm["steps"], 601);

    // Per contact point: the peak normal force is the largest of its `_n`
    // column, the tangential peak that of |f − n·ŷ| on flat ground.
    let points: Vec<String> = sm["contact_points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_str().unwrap().to_owned())
        .collect();
    assert!(!points.is_empty());
    let mut all_n: f64 = 0.0;
    for p in &points {
        let [fx, fy, fz, n] = ["fx", "fy", "fz", "n"].map(|a| col(&format!("{p}_{a}")));
        let want_n = peak(&rows, |r| r[n].abs());
        let want_fa = peak(&rows, |r| {
            (r[fx] * r[fx] + (r[fy] - r[n]) * (r[fy] - r[n]) + r[fz] * r[fz]).sqrt()
        });
        let got = &sm["peak_contact_force"][p];
        assert_eq!(got["n"].as_f64().unwrap(), want_n, "{p}");
        assert!(
            (got["fa"].as_f64().unwrap() - want_fa).abs() <= 1e-12 * want_n,
            "{p}"
        );
        // Coulomb: the tangential force never beats μs times the normal.
        assert!(want_fa <= 0.5 * want_n + 1e-4, "{p}");
        all_n = all_n.max(want_n);
    }
    assert!(all_n > 10.0, "the robot lands: peak normal {all_n} N");
    assert_eq!(sm["peak_normal_force"].as_f64().unwrap(), all_n);

    // First touchdown and first slip per point: events.csv's first ST1 →
    // ST2/ST3 and first → ST3 of that point.
    let events = read(&out.join("events.csv"));
    let first = |p: &str, pred: &dyn Fn(&str, &str) -> bool| -> Option<f64> {
        events.lines().skip(1).find_map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[1] == p && pred(f[2], f[3])).then(|| f[0].parse().unwrap())
        })
    };
    let mut touched = 0;
    for p in &points {
        let down = first(p, &|from, to| from == "ST1" && (to == "ST2" || to == "ST3"));
        let slip = first(p, &|_, to| to == "ST3");
        assert_eq!(sm["first_touchdown"][p].as_f64(), down, "{p}");
        assert_eq!(sm["first_slip"][p].as_f64(), slip, "{p}");
        touched += usize::from(down.is_some());
    }
    assert!(touched > 0);

    // Per reaction (named by its joint, as its columns): the largest force
    // magnitude; per joint the largest |τ| and |τ·θ̇|, θ̇ the backward
    // difference of the rows (the joints start at rest).
    let reactions = sm["peak_joint_force"].as_object().unwrap();
    assert!(!reactions.is_empty());
    let mut all_f: f64 = 0.0;
    for (joint, got) in reactions {
        let [fx, fy, fz] = ["fx", "fy", "fz"].map(|a| col(&format!("{joint}_{a}")));
        let want = peak(&rows, |r| {
            (r[fx] * r[fx] + r[fy] * r[fy] + r[fz] * r[fz]).sqrt()
        });
        assert_eq!(got.as_f64().unwrap(), want, "{joint}");
        all_f = all_f.max(want);
    }
    assert_eq!(sm["peak_joint_force_max"].as_f64().unwrap(), all_f);
    let dt = sm["dt"].as_f64().unwrap();
    let (mut all_tau, mut all_p): (f64, f64) = (0.0, 0.0);
    let joints = sm["peak_actuation"].as_array().unwrap();
    assert_eq!(
        joints.len(),
        header.iter().filter(|h| h.starts_with("tau_")).count()
    );
    for j in joints {
        assert!(j.get("leg").is_none());
        let name = j["joint"].as_str().unwrap();
        let (tau, q) = (col(&format!("tau_{name}")), col(name));
        let want_tau = peak(&rows, |r| r[tau].abs());
        let want_p = (1..rows.len())
            .map(|k| (rows[k][tau] * ((rows[k][q] - rows[k - 1][q]) / dt)).abs())
            .fold(0.0, f64::max);
        assert_eq!(j["torque"].as_f64().unwrap(), want_tau, "{name}");
        let got_p = j["power"].as_f64().unwrap();
        assert!(
            (got_p - want_p).abs() <= 1e-9 * want_p.max(1.0),
            "{name}: {got_p} {want_p}"
        );
        all_tau = all_tau.max(want_tau);
        all_p = all_p.max(got_p);
    }
    assert!(all_tau > 0.0 && all_p > 0.0);
    assert_eq!(sm["peak_torque_max"].as_f64().unwrap(), all_tau);
    assert_eq!(sm["peak_power_max"].as_f64().unwrap(), all_p);
    let per_step = &sm["newton_iterations_per_step"];
    let iterations = col("newton_iterations");
    assert_eq!(
        per_step["max"].as_f64().unwrap(),
        peak(&rows, |r| r[iterations])
    );
    assert_eq!(
        sm["chord_iterations"].as_u64().unwrap() + sm["full_newton_iterations"].as_u64().unwrap(),
        sm["newton_iterations"].as_u64().unwrap()
    );

    // The root: from the first row to after the last step (one step past
    // the last row); the path over every row and that last stretch.
    let xyz = |v: &serde_json::Value| -> [f64; 3] {
        let a = v.as_array().unwrap();
        std::array::from_fn(|i| a[i].as_f64().unwrap())
    };
    let (rx, ry, rz) = (col("rx"), col("ry"), col("rz"));
    let start = xyz(&sm["initial_position"]);
    assert_eq!(start, [rows[0][rx], rows[0][ry], rows[0][rz]]);
    let end = xyz(&sm["final_position"]);
    let last = rows.last().unwrap();
    let from_last = (end[0] - last[rx]).hypot(end[2] - last[rz]);
    assert!(from_last < 0.01 && (end[1] - last[ry]).abs() < 0.01);
    let d = xyz(&sm["displacement"]);
    for a in 0..3 {
        assert_eq!(d[a], end[a] - start[a]);
    }
    assert_eq!(sm["distance"].as_f64().unwrap(), d[0].hypot(d[2]));
    assert_eq!(sm["final_height"].as_f64().unwrap(), end[1]);
    let path = (1..rows.len())
        .map(|k| (rows[k][rx] - rows[k - 1][rx]).hypot(rows[k][rz] - rows[k - 1][rz]))
        .sum::<f64>()
        + from_last;
    let got_path = sm["path_length"].as_f64().unwrap();
    assert!((got_path - path).abs() < 1e-12, "{got_path} {path}");
    assert!(got_path >= sm["distance"].as_f64().unwrap() - 1e-12);
    let energy = &sm["final_energy"];
    assert_eq!(energy["t"].as_f64().unwrap(), last[0]);
    let (ek, ep) = (col("kinetic"), col("potential"));
    assert_eq!(energy["kinetic"].as_f64().unwrap(), last[ek]);
    assert_eq!(energy["potential"].as_f64().unwrap(), last[ep]);
    assert_eq!(energy["total"].as_f64().unwrap(), last[ek] + last[ep]);

    // Every third row, without the plots (which make the run record every
    // step): the peaks are those of the written rows, the events and the
    // end of the run those of every step.
    let strided = drop_run(
        dir.path(),
        "strided",
        "\n[output]\nstride = 3\nplots = false\n",
    );
    let ss = summary(&strided);
    let (_, rows3) = common::trajectory(&strided);
    assert_eq!(ss["rows_written"].as_u64().unwrap() as usize, rows3.len());
    for key in ["first_touchdown", "first_slip", "final_position", "events"] {
        assert_eq!(ss[key], sm[key], "{key}");
    }
    let mut n3: f64 = 0.0;
    for p in &points {
        let n = col(&format!("{p}_n"));
        let want = peak(&rows3, |r| r[n].abs());
        assert_eq!(ss["peak_contact_force"][p]["n"].as_f64().unwrap(), want);
        n3 = n3.max(want);
    }
    assert_eq!(ss["peak_normal_force"].as_f64().unwrap(), n3);
    assert!(n3 <= all_n);
}
