//! The files of a dynamic (3D FBD) hexapod run: the columns of
//! `trajectory.csv` for six legs and for `legs = [3, 4]`, every file
//! written, an interrupted run keeping its rows, byte-identical repeated
//! runs, and Newton's second law of every body checked from the written
//! columns alone (the check an outside tester would make).

use std::collections::HashMap;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

use fbd_cli::spatial::{self, FILES, Layout, columns};
use fbd_kinematics::hexapod::{HexapodConfig, HexapodData, NQ, forward};
use fbd_sim::spatial::SpatialParams;

/// A short drop onto flat ground: the body 0.4 m up (the feet 5 mm above
/// the ground with the default legs), 0.12 s at Δt = 1 ms: flight, then
/// every foot lands.
fn drop(legs: &[usize]) -> SpatialParams {
    let mut p = SpatialParams {
        duration: 0.12,
        dt: 1e-3,
        legs: legs.to_vec(),
        ..SpatialParams::default()
    };
    let mut q0 = vec![0.0, 0.4, 0.0, 0.0, 0.0, 0.0];
    for _ in legs {
        q0.extend([0.0, 0.0, 250f64.to_radians()]);
    }
    p.qdot0 = vec![0.0; q0.len()];
    p.q0 = q0;
    p
}

const TOML: &str = "# test\n";

fn run_into(p: &SpatialParams, dir: &Path) -> spatial::SpatialRun {
    spatial::simulate(
        p,
        TOML,
        "test.toml",
        Some(dir),
        &AtomicBool::new(false),
        &mut |_| {},
    )
    .expect("the run starts")
}

/// `trajectory.csv` as a header index and rows of strings.
struct Csv {
    col: HashMap<String, usize>,
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Csv {
    fn read(path: &Path) -> Self {
        let mut r = csv::Reader::from_path(path).unwrap();
        let header: Vec<String> = r.headers().unwrap().iter().map(str::to_owned).collect();
        let col = header
            .iter()
            .enumerate()
            .map(|(i, h)| (h.clone(), i))
            .collect();
        let rows = r
            .records()
            .map(|x| x.unwrap().iter().map(str::to_owned).collect())
            .collect();
        Self { col, header, rows }
    }

    fn f(&self, row: usize, name: &str) -> f64 {
        let c = *self
            .col
            .get(name)
            .unwrap_or_else(|| panic!("no column {name}"));
        self.rows[row][c]
            .parse()
            .unwrap_or_else(|_| panic!("row {row} {name}: {}", self.rows[row][c]))
    }

    fn v3(&self, row: usize, prefix: &str, suffix: [&str; 3]) -> [f64; 3] {
        suffix.map(|s| self.f(row, &format!("{prefix}{s}")))
    }
}

/// The expected column list, written out independently of the writer.
fn expected_columns(legs: &[usize], knees: bool, hips: bool) -> Vec<String> {
    let mut c: Vec<String> = ["t", "rx", "ry", "rz", "phi_x", "phi_y", "phi_z"]
        .map(str::to_owned)
        .to_vec();
    for n in legs {
        c.extend([
            format!("theta1_{n}"),
            format!("theta2_{n}"),
            format!("theta3_{n}"),
        ]);
    }
    for n in legs {
        for s in [
            "foot{n}_x",
            "foot{n}_y",
            "foot{n}_z",
            "state{n}",
            "foot{n}_fx",
            "foot{n}_fy",
            "foot{n}_fz",
            "foot{n}_n",
            "hip{n}_fx",
            "hip{n}_fy",
            "hip{n}_fz",
            "hip{n}_mx",
            "hip{n}_my",
            "hip{n}_mz",
            "knee{n}_fx",
            "knee{n}_fy",
            "knee{n}_fz",
            "knee{n}_mx",
            "knee{n}_my",
            "knee{n}_mz",
            "tau1_{n}",
            "tau2_{n}",
            "tau3_{n}",
        ] {
            c.push(s.replace("{n}", &n.to_string()));
        }
    }
    for n in legs {
        for (on, p) in [(knees, "kneepoint"), (hips, "hippoint")] {
            if on {
                for s in ["state", "fx", "fy", "fz", "n"] {
                    c.push(format!("{p}{n}_{s}"));
                }
            }
        }
    }
    c.extend(["kinetic", "potential", "newton_iterations"].map(str::to_owned));
    c.extend(["roll", "pitch", "heading"].map(str::to_owned));
    c
}

#[test]
fn columns_of_six_legs_in_order() {
    let p = SpatialParams::default();
    let c = columns(&Layout::of(&p));
    assert_eq!(c, expected_columns(&[1, 2, 3, 4, 5, 6], true, true));
    assert_eq!(c.len(), 7 + 18 + 6 * 23 + 6 * 2 * 5 + 3 + 3);
}

#[test]
fn columns_of_legs_3_and_4_name_only_those() {
    let mut p = SpatialParams {
        legs: vec![3, 4],
        ..SpatialParams::default()
    };
    p.contact_points.hips = false;
    let c = columns(&Layout::of(&p));
    assert_eq!(c, expected_columns(&[3, 4], true, false));
    assert!(!c.iter().any(|n| n.ends_with("_1") || n.contains("foot1")));
}

#[test]
fn every_file_is_written_with_one_row_per_step() {
    let dir = tempfile::tempdir().unwrap();
    let p = drop(&[1, 2, 3, 4, 5, 6]);
    let r = run_into(&p, dir.path());
    assert!(r.io_error.is_none(), "{:?}", r.io_error);
    assert!(r.run.error.is_none(), "{:?}", r.run.error);
    for f in FILES {
        let path = dir.path().join(f);
        assert!(
            path.metadata().map(|m| m.len() > 0).unwrap_or(false),
            "{f} missing or empty"
        );
    }
    let csv = Csv::read(&dir.path().join("trajectory.csv"));
    assert_eq!(
        csv.header,
        expected_columns(&[1, 2, 3, 4, 5, 6], true, true)
    );
    assert_eq!(csv.rows.len(), 121);
    assert_eq!(csv.rows[0][0], "0.0");
    assert_eq!(csv.rows[120][0], "0.12");
    assert_eq!(csv.rows[35][0], "0.035");
    for row in &csv.rows {
        for n in 1..=6 {
            let s = &row[csv.col[&format!("state{n}")]];
            assert!(["ST1", "ST2", "ST3"].contains(&s.as_str()), "state {s}");
        }
    }
    // The feet land: some foot is on the ground at the end.
    let last = csv.rows.len() - 1;
    assert!(
        (1..=6).any(|n| csv.rows[last][csv.col[&format!("state{n}")]] != "ST1"),
        "no foot landed"
    );
    let events = std::fs::read_to_string(dir.path().join("events.csv")).unwrap();
    assert!(events.starts_with("t,leg,from,to,point\n"));
    assert!(events.lines().count() > 1, "no touchdown event: {events}");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(s["status"], "ok");
    assert_eq!(s["rows_written"], 121);
    assert_eq!(s["peak_actuation"].as_array().unwrap().len(), 18);
    assert_eq!(s["peak_actuation"][4]["leg"], 2);
    assert_eq!(s["peak_actuation"][4]["joint"], "theta2");
    assert!(s["newton_iterations_per_step"]["max"].as_u64().unwrap() >= 1);
    let h = s["final_height"].as_f64().unwrap();
    assert_eq!(h, csv.f(last, "ry"));
    assert_eq!(
        std::fs::read_to_string(dir.path().join("config.toml")).unwrap(),
        TOML
    );
}

#[test]
fn stride_writes_every_kth_step() {
    let dir = tempfile::tempdir().unwrap();
    let mut p = drop(&[3, 4]);
    p.stride = 10;
    let r = run_into(&p, dir.path());
    assert!(r.run.error.is_none(), "{:?}", r.run.error);
    let csv = Csv::read(&dir.path().join("trajectory.csv"));
    assert_eq!(csv.rows.len(), 13);
    assert_eq!(csv.rows[1][0], "0.01");
    assert_eq!(csv.header, expected_columns(&[3, 4], true, true));
}

#[test]
fn an_interrupted_run_keeps_its_rows() {
    let dir = tempfile::tempdir().unwrap();
    let p = drop(&[1, 2, 3, 4, 5, 6]);
    let stop = AtomicBool::new(false);
    let mut seen = 0;
    let r = spatial::simulate(&p, TOML, "test.toml", Some(dir.path()), &stop, &mut |_| {
        seen += 1;
        if seen == 20 {
            stop.store(true, Ordering::SeqCst);
        }
    })
    .unwrap();
    assert!(r.run.interrupted);
    assert!(r.io_error.is_none());
    let csv = Csv::read(&dir.path().join("trajectory.csv"));
    assert_eq!(csv.rows.len(), seen);
    assert!((20..30).contains(&seen), "{seen} rows");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(s["status"], "interrupted");
    assert_eq!(s["rows_written"], seen);
    for f in FILES {
        assert!(dir.path().join(f).exists(), "{f} missing");
    }
    let tmp: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .ends_with(".tmp")
        })
        .collect();
    assert!(tmp.is_empty(), "temporary files left");
}

#[test]
fn two_runs_are_byte_identical() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let p = drop(&[1, 2, 3, 4, 5, 6]);
    run_into(&p, a.path());
    run_into(&p, b.path());
    for f in FILES {
        let (x, y) = (
            std::fs::read(a.path().join(f)).unwrap(),
            std::fs::read(b.path().join(f)).unwrap(),
        );
        if f == "summary.json" {
            // Apart from the timing fields.
            let strip = |v: &[u8]| {
                let mut j: serde_json::Value = serde_json::from_slice(v).unwrap();
                j["wall_seconds"] = serde_json::Value::Null;
                j["steps_per_second"] = serde_json::Value::Null;
                j["stability_check_seconds"] = serde_json::Value::Null;
                j
            };
            assert_eq!(strip(&x), strip(&y), "{f} differs");
        } else if f == "viewer.html" {
            // The page title is the folder's name.
            let title = |v: &[u8], d: &Path| {
                String::from_utf8_lossy(v).replace(d.file_name().unwrap().to_str().unwrap(), "DIR")
            };
            assert!(title(&x, a.path()) == title(&y, b.path()), "{f} differs");
        } else {
            assert!(x == y, "{f} differs");
        }
    }
}

/// The centres of mass of the body, and of each leg's upper and lower
/// link, from the row's coordinates by the D-H forward kinematics.
fn centres(csv: &Csv, p: &SpatialParams, row: usize) -> ([f64; 3], Vec<[[f64; 3]; 2]>) {
    let model = p.kinematic_model();
    let mut q = [0.0; NQ];
    for (k, name) in ["rx", "ry", "rz", "phi_x", "phi_y", "phi_z"]
        .iter()
        .enumerate()
    {
        q[k] = csv.f(row, name);
    }
    for &n in &p.legs {
        for j in 0..3 {
            q[6 + 3 * (n - 1) + j] = csv.f(row, &format!("theta{}_{n}", j + 1));
        }
    }
    let mut d = HexapodData::new();
    forward(&model, &HexapodConfig::from_q(&q), &mut d);
    let v = |x: fbd_kinematics::nalgebra::Vector3<f64>| [x.x, x.y, x.z];
    let links = p
        .legs
        .iter()
        .map(|&n| {
            let l = &d.legs[n - 1];
            [v(l.upper_com), v(l.lower_com)]
        })
        .collect();
    (v(d.body_com), links)
}

/// Newton's second law of every body, `Σ F = m·a` with `a` the central
/// difference of its centre of mass, from the columns of
/// `trajectory.csv` alone: the lower link carries the knee force (upper on
/// lower), the ground force on its foot and on its knee point, and its
/// weight; the upper link the hip force (body on upper), minus the knee
/// force, and its weight; the body minus every hip force, the ground force
/// on its hip points, and its weight.
#[test]
fn every_body_obeys_newtons_second_law_from_the_csv() {
    let dir = tempfile::tempdir().unwrap();
    let p = drop(&[1, 2, 3, 4, 5, 6]);
    let r = run_into(&p, dir.path());
    assert!(r.run.error.is_none(), "{:?}", r.run.error);
    let csv = Csv::read(&dir.path().join("trajectory.csv"));
    let dt = p.dt;
    let g = [0.0, -p.gravity, 0.0];
    let xyz = ["fx", "fy", "fz"];
    let mut contact_rows = 0;
    let mut worst = 0.0f64;
    let com: Vec<_> = (0..csv.rows.len()).map(|k| centres(&csv, &p, k)).collect();
    for k in 1..csv.rows.len() - 1 {
        let acc = |f: &dyn Fn(usize) -> [f64; 3]| -> [f64; 3] {
            let (a, b, c) = (f(k - 1), f(k), f(k + 1));
            std::array::from_fn(|i| (a[i] - 2.0 * b[i] + c[i]) / (dt * dt))
        };
        let mut check = |body: &str, m: f64, a: [f64; 3], forces: &[[f64; 3]]| {
            for i in 0..3 {
                let sum: f64 = forces.iter().map(|f| f[i]).sum::<f64>() + m * g[i];
                let scale: f64 = forces.iter().map(|f| f[i].abs()).sum::<f64>() + m * p.gravity;
                let err = (m * a[i] - sum).abs();
                worst = worst.max(err / scale);
                assert!(
                    err <= 1e-6 * scale + 1e-6,
                    "{body}, row {k} (t = {}), axis {i}: m·a = {} but Σ F = {sum} (error {err:e} N)",
                    csv.rows[k][0],
                    m * a[i]
                );
            }
        };
        let mut hips_on_body = Vec::new();
        for (i, &n) in p.legs.iter().enumerate() {
            let hip = csv.v3(k, &format!("hip{n}_"), xyz);
            let knee = csv.v3(k, &format!("knee{n}_"), xyz);
            let foot = csv.v3(k, &format!("foot{n}_"), xyz);
            let kneepoint = if p.contact_points.knees {
                csv.v3(k, &format!("kneepoint{n}_"), xyz)
            } else {
                [0.0; 3]
            };
            if csv.rows[k][csv.col[&format!("state{n}")]] != "ST1" {
                contact_rows += 1;
            }
            let a_lower = acc(&|r| com[r].1[i][1]);
            check(
                &format!("lower link {n}"),
                p.lower_mass,
                a_lower,
                &[knee, foot, kneepoint],
            );
            let a_upper = acc(&|r| com[r].1[i][0]);
            check(
                &format!("upper link {n}"),
                p.upper_mass,
                a_upper,
                &[hip, knee.map(|x| -x)],
            );
            hips_on_body.push(hip.map(|x| -x));
            if p.contact_points.hips {
                hips_on_body.push(csv.v3(k, &format!("hippoint{n}_"), xyz));
            }
        }
        let a_body = acc(&|r| com[r].0);
        check("body", p.body_mass, a_body, &hips_on_body);
    }
    assert!(
        contact_rows > 0,
        "no foot touched: the check saw no contact"
    );
    eprintln!("largest relative force imbalance: {worst:e}");
}

/// A dynamic hexapod configuration of legs 3 and 4 dropped 5 mm.
const SMALL: &str = "model = \"hexapod\"\nlegs = [3, 4]\n[time]\ndt = 0.001\nduration = 0.08\n\
[initial]\nposition = [0.0, 0.4, 0.0]\n[initial.leg3]\ntheta_deg = [0.0, 0.0, 250.0]\n\
[initial.leg4]\ntheta_deg = [0.0, 0.0, 250.0]\n";

fn fbd(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_fbd"))
        .args(args)
        .output()
        .expect("the fbd binary runs")
}

fn arg(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn fbd_run_of_a_dynamic_config_writes_its_files_and_view_repeats_the_page() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("small.toml");
    std::fs::write(&cfg, SMALL).unwrap();
    let out = dir.path().join("out");
    // An earlier kinematic run's plot in the same folder is removed.
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("gait.svg"), "<svg/>").unwrap();
    let o = fbd(&["run", arg(&cfg), "--out", arg(&out)]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(stdout.contains("solved 81 steps"), "{stdout}");
    assert!(stdout.contains(&FILES.join(" ")), "{stdout}");
    for f in FILES {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    assert!(!out.join("gait.svg").exists(), "stale gait.svg kept");
    let csv = Csv::read(&out.join("trajectory.csv"));
    assert_eq!(csv.header, expected_columns(&[3, 4], true, true));
    // `fbd view` writes the same page from the files.
    let page = std::fs::read(out.join("viewer.html")).unwrap();
    let o = fbd(&["view", arg(&out)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::read(out.join("viewer.html")).unwrap() == page);
    // config.toml repeats the run byte for byte.
    let again = dir.path().join("again");
    let o = fbd(&["run", arg(&out.join("config.toml")), "--out", arg(&again)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["trajectory.csv", "events.csv", "feet.svg", "torques.svg"] {
        assert!(
            std::fs::read(out.join(f)).unwrap() == std::fs::read(again.join(f)).unwrap(),
            "{f} differs when rerun from config.toml"
        );
    }
    // A planar run into the same folder removes the dynamic run's plots.
    let o = fbd(&["run", "--out", arg(&out)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["feet.svg", "body.svg"] {
        assert!(!out.join(f).exists(), "{f} of the earlier run kept");
    }
}

#[test]
fn sigint_stops_a_dynamic_run_and_keeps_its_rows() {
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("long.toml");
    std::fs::write(
        &cfg,
        SMALL.replace("duration = 0.08", "duration = 100000.0") + "[output]\nstride = 100\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let child = Command::new(env!("CARGO_BIN_EXE_fbd"))
        .args(["run", arg(&cfg), "--out", arg(&out)])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Stepping once the trajectory's temporary file exists.
    let start = Instant::now();
    let stepping = || {
        std::fs::read_dir(&out).is_ok_and(|d| {
            d.flatten()
                .any(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        })
    };
    while !stepping() {
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
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("error: interrupted after "), "{stderr}");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["status"], "interrupted");
    let steps = s["steps"].as_u64().unwrap();
    assert!(steps > 0);
    let csv = Csv::read(&out.join("trajectory.csv"));
    assert_eq!(csv.rows.len() as u64, (steps - 1) / 100 + 1);
    assert_eq!(csv.rows.len() as u64, s["rows_written"].as_u64().unwrap());
    for f in FILES {
        assert!(out.join(f).is_file(), "{f} missing");
    }
}

/// The hip and knee moments of `trajectory.csv` carry the actuator
/// torques about the joint axes (the constraint moments are perpendicular
/// to them): `hip·z0 = τ1`, `hip·z1 = τ2`, `knee·z2 = τ3`, with the D-H
/// axes from the row's coordinates — checked on the walking example, whose
/// joints stay inside their limits.
#[test]
fn the_joint_moments_carry_the_torques_about_the_joint_axes() {
    let dir = tempfile::tempdir().unwrap();
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/hexapod_walk.toml");
    let source = file.display().to_string();
    let fbd_cli::Config::Hexapod(h) = fbd_cli::config::load(&file).unwrap() else {
        panic!("not a hexapod configuration");
    };
    let p = h.spatial_params(&source).unwrap();
    let r = run_into(&p, dir.path());
    assert!(r.run.error.is_none(), "{:?}", r.run.error);
    assert!(r.run.limit_events.is_empty(), "a joint reached its limit");
    let csv = Csv::read(&dir.path().join("trajectory.csv"));
    let model = p.kinematic_model();
    let mut d = HexapodData::new();
    let mut largest = 0.0f64;
    for k in 0..csv.rows.len() {
        let mut q = [0.0; NQ];
        for (i, name) in ["rx", "ry", "rz", "phi_x", "phi_y", "phi_z"]
            .iter()
            .enumerate()
        {
            q[i] = csv.f(k, name);
        }
        for &n in &p.legs {
            for j in 0..3 {
                q[6 + 3 * (n - 1) + j] = csv.f(k, &format!("theta{}_{n}", j + 1));
            }
        }
        forward(&model, &HexapodConfig::from_q(&q), &mut d);
        for &n in &p.legs {
            let l = &d.legs[n - 1];
            let hip = csv.v3(k, &format!("hip{n}_"), ["mx", "my", "mz"]);
            let knee = csv.v3(k, &format!("knee{n}_"), ["mx", "my", "mz"]);
            let dot = |m: [f64; 3], a: fbd_kinematics::nalgebra::Vector3<f64>| {
                m[0] * a.x + m[1] * a.y + m[2] * a.z
            };
            for (j, got) in [
                dot(hip, l.hip_axis),
                dot(hip, l.upper_versor),
                dot(knee, l.lower_versor),
            ]
            .into_iter()
            .enumerate()
            {
                let tau = csv.f(k, &format!("tau{}_{n}", j + 1));
                largest = largest.max(tau.abs());
                assert!(
                    (got - tau).abs() <= 1e-6 * (1.0 + tau.abs()),
                    "row {k} (t = {}), leg {n}: moment about the θ{} axis {got} N·m, τ{} = {tau}",
                    csv.rows[k][0],
                    j + 1,
                    j + 1
                );
            }
        }
    }
    assert!(largest > 1.0, "the walk applied no torque ({largest} N·m)");
}

/// The rotational half of every body's six equations, from the written
/// columns alone: `(L[k+½] − L[k−½])/Δt = ΣM[k]` about the body's centre of
/// mass at k, with `L[k+½]` the discrete angular momentum of the scheme
/// (`R[k]·exp(ψ/2)·I·ψ/Δt`, `ψ = log(R[k]ᵀR[k+1])`, rotations and points
/// from the q columns), the moments of the written hip, knee and contact
/// forces at their points plus the written hip and knee moments — on a
/// PD-held robot landing and settling (torques, sticking and sliding feet,
/// knee and hip contact points).
#[test]
fn every_body_obeys_eulers_equations_from_the_csv() {
    use fbd_dynamics::spatial::{SpatialKin, half_momentum, lower_body, upper_body};
    use fbd_kinematics::nalgebra::Vector3;
    use fbd_sim::spatial::{SpatialControl, SpatialModel};
    let dir = tempfile::tempdir().unwrap();
    let mut p = drop(&[1, 2, 3, 4, 5, 6]);
    p.duration = 0.3;
    p.control = SpatialControl::Pd {
        kp: 150.0,
        kd: 4.0,
        torque_limit: Some(40.0),
        target: vec![[0.1, -0.2, 4.6]; 6],
    };
    let r = run_into(&p, dir.path());
    assert!(r.run.error.is_none(), "{:?}", r.run.error);
    let csv = Csv::read(&dir.path().join("trajectory.csv"));
    let model = SpatialModel::new(&p).unwrap();
    // The closed-form hexapod: an independent reference for the balance.
    let hexapod = fbd_sim::spatial::closed_form(&p);
    let mech = &hexapod;
    let xyz = ["fx", "fy", "fz"];
    let mxyz = ["mx", "my", "mz"];
    let v = |a: [f64; 3]| Vector3::new(a[0], a[1], a[2]);
    let kin_at = |row: usize| {
        let mut q = vec![0.0; model.nq()];
        for (k, name) in ["rx", "ry", "rz", "phi_x", "phi_y", "phi_z"]
            .iter()
            .enumerate()
        {
            q[k] = csv.f(row, name);
        }
        for (s, &n) in p.legs.iter().enumerate() {
            for j in 0..3 {
                q[6 + 3 * s + j] = csv.f(row, &format!("theta{}_{n}", j + 1));
            }
        }
        let mut kin = SpatialKin::new(mech);
        kin.eval(mech, &q);
        kin
    };
    let kins: Vec<_> = (0..csv.rows.len()).map(kin_at).collect();
    let (mut worst, mut sliding) = (0.0f64, 0);
    for k in 1..csv.rows.len() - 1 {
        let (kp, kk, kn) = (&kins[k - 1], &kins[k], &kins[k + 1]);
        let mut moment = vec![Vector3::zeros(); mech.bodies.len()];
        let mut scale = vec![0.0; mech.bodies.len()];
        let mut add = |b: usize, point: Vector3<f64>, f: Vector3<f64>, m: Vector3<f64>| {
            let arm = point - kk.com[b];
            moment[b] += arm.cross(&f) + m;
            scale[b] += arm.norm() * f.norm() + m.norm();
        };
        for (s, &n) in p.legs.iter().enumerate() {
            let l = &kk.fk.legs[n - 1];
            let (u, lo) = (upper_body(s), lower_body(s));
            let hf = v(csv.v3(k, &format!("hip{n}_"), xyz));
            let hm = v(csv.v3(k, &format!("hip{n}_"), mxyz));
            let kf = v(csv.v3(k, &format!("knee{n}_"), xyz));
            let km = v(csv.v3(k, &format!("knee{n}_"), mxyz));
            add(u, l.hip, hf, hm);
            add(0, l.hip, -hf, -hm);
            add(lo, l.knee, kf, km);
            add(u, l.knee, -kf, -km);
            let foot = v(csv.v3(k, &format!("foot{n}_"), xyz));
            add(lo, l.tip, foot, Vector3::zeros());
            add(
                lo,
                l.knee,
                v(csv.v3(k, &format!("kneepoint{n}_"), xyz)),
                Vector3::zeros(),
            );
            add(
                0,
                l.hip,
                v(csv.v3(k, &format!("hippoint{n}_"), xyz)),
                Vector3::zeros(),
            );
            sliding += usize::from(csv.rows[k][csv.col[&format!("state{n}")]] == "ST3");
        }
        for (b, body) in mech.bodies.iter().enumerate() {
            let l_prev = half_momentum(&kp.rot[b], &kk.rot[b], &body.inertia, p.dt).0;
            let l_next = half_momentum(&kk.rot[b], &kn.rot[b], &body.inertia, p.dt).0;
            let lhs = (l_next - l_prev) / p.dt;
            let err = (lhs - moment[b]).norm();
            let tol = 1e-6 * (scale[b] + 1.0);
            worst = worst.max(err / (scale[b] + 1.0));
            assert!(
                err <= tol,
                "{}, row {k} (t = {}): dL/dt = {lhs:?} but ΣM = {:?} (error {err:e} N·m)",
                body.name,
                csv.rows[k][0],
                moment[b]
            );
        }
    }
    assert!(
        sliding > 0,
        "no foot slid: the check should see sliding rows"
    );
    eprintln!("largest relative moment imbalance: {worst:e}");
}
