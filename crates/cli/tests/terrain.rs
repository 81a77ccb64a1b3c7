//! Rough terrain end to end: the heightfield file formats read alike (rows
//! along +X, columns along +Z); bad heightfield files get one clear error
//! naming the file and the key; the three terrain examples do what their
//! comments say, and the rough walk obeys Coulomb's law and every body's
//! Newton equation on every row; `fbd export mjcf` writes the height map as
//! a MuJoCo hfield.

mod common;

use std::path::Path;
use std::process::Output;
use std::sync::atomic::AtomicBool;

use common::{example, examples, fbd, s};
use fbd_cli::Config;
use fbd_cli::spatial;
use fbd_contact::spatial::frame;
use fbd_contact::{StateCode, friction_at};
use fbd_dynamics::PointKind;
use fbd_kinematics::hexapod::{HexapodConfig, HexapodData, NQ, forward};
use fbd_sim::robot::RobotRecord;
use fbd_sim::spatial::SpatialParams;

/// The plane the test files sample.
fn plane(x: f64, z: f64) -> f64 {
    0.02 + 0.1 * x - 0.05 * z
}

/// The test grid: 5 rows along X over [−1, 1], 4 columns along Z over
/// [−0.6, 0.6] (size [2, 1.2], centre [0, 0]).
fn sample() -> (usize, usize, Vec<f64>) {
    let (nr, nc) = (5, 4);
    let mut h = Vec::new();
    for i in 0..nr {
        for j in 0..nc {
            h.push(plane(-1.0 + 0.5 * i as f64, -0.6 + 0.4 * j as f64));
        }
    }
    (nr, nc, h)
}

fn npy(nr: usize, nc: usize, h: &[f64]) -> Vec<u8> {
    let mut header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({nr}, {nc}), }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut b = b"\x93NUMPY\x01\x00".to_vec();
    b.extend((header.len() as u16).to_le_bytes());
    b.extend(header.as_bytes());
    for v in h {
        b.extend(v.to_le_bytes());
    }
    b
}

fn mujoco(nr: usize, nc: usize, h: &[f64]) -> Vec<u8> {
    let mut b = (nr as i32).to_le_bytes().to_vec();
    b.extend((nc as i32).to_le_bytes());
    for v in h {
        b.extend((*v as f32).to_le_bytes());
    }
    b
}

fn csv_grid(nc: usize, h: &[f64]) -> String {
    h.chunks(nc)
        .map(|r| r.iter().map(f64::to_string).collect::<Vec<_>>().join(","))
        .collect::<Vec<_>>()
        .join("\n")
}

fn png16(nr: usize, nc: usize, h: &[f64], lo: f64, hi: f64) -> Vec<u8> {
    let mut out = Vec::new();
    let mut e = png::Encoder::new(&mut out, nc as u32, nr as u32);
    e.set_color(png::ColorType::Grayscale);
    e.set_depth(png::BitDepth::Sixteen);
    let mut w = e.write_header().unwrap();
    let data: Vec<u8> = h
        .iter()
        .flat_map(|v| {
            let g = ((v - lo) / (hi - lo) * 65535.0).round() as u16;
            g.to_be_bytes()
        })
        .collect();
    w.write_image_data(&data).unwrap();
    drop(w);
    out
}

const HEAD: &str = "model = \"hexapod\"\n[time]\ndt = 0.001\nduration = 0.01\n";

fn terrain_toml(file: &str, extra: &str) -> String {
    format!(
        "{HEAD}[terrain]\nkind = \"heightfield\"\nfile = \"{file}\"\nsize = [2.0, 1.2]\n{extra}"
    )
}

#[test]
fn every_heightfield_format_reads_the_same_plane() {
    let dir = tempfile::tempdir().unwrap();
    let (nr, nc, h) = sample();
    let [lo, hi] = [
        h.iter().cloned().fold(f64::INFINITY, f64::min),
        h.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
    ];
    let files: [(&str, Vec<u8>, String); 4] = [
        ("g.npy", npy(nr, nc, &h), String::new()),
        ("g.csv", csv_grid(nc, &h).into_bytes(), String::new()),
        (
            "g.bin",
            mujoco(nr, nc, &h),
            format!("elevation = [{lo}, {hi}]\n"),
        ),
        (
            "g.png",
            png16(nr, nc, &h, lo, hi),
            format!("elevation = [{lo}, {hi}]\n"),
        ),
    ];
    for (name, bytes, extra) in files {
        std::fs::write(dir.path().join(name), bytes).unwrap();
        let cfg = dir.path().join(format!("{name}.toml"));
        std::fs::write(&cfg, terrain_toml(name, &extra)).unwrap();
        let Config::Hexapod(c) = fbd_cli::config::load(&cfg).unwrap() else {
            panic!("hexapod")
        };
        let surf = c.terrain.surface();
        // 16-bit quantisation of the image: 1/65535 of the range.
        let tol = if name.ends_with("png") {
            (hi - lo) / 65535.0
        } else if name.ends_with("bin") {
            1e-7
        } else {
            1e-12
        };
        for (x, z) in [(0.0, 0.0), (-0.8, 0.5), (0.37, -0.21), (0.9, 0.55)] {
            let got = surf.height(x, z);
            assert!(
                (got - plane(x, z)).abs() <= tol,
                "{name}: ϱ({x}, {z}) = {got}, the plane {}",
                plane(x, z)
            );
        }
        // config.toml repeats the run: the file is absolute.
        assert!(Path::new(c.terrain.file.as_deref().unwrap()).is_absolute());
    }
}

/// Checks a one-line configuration error (exit 2) mentioning `needles`.
fn check_error(o: &Output, needles: &[&str]) {
    let e = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "stderr: {e:?}");
    assert_eq!(e.lines().count(), 1, "stderr is not one line: {e:?}");
    assert!(e.starts_with("error: ") && !e.contains("panicked"), "{e:?}");
    for n in needles {
        assert!(e.contains(n), "{e:?} does not mention {n:?}");
    }
}

#[test]
fn bad_heightfield_files_get_one_clear_error_naming_the_file_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let (nr, nc, h) = sample();
    let run = |name: &str, bytes: Option<Vec<u8>>, extra: &str| -> Output {
        if let Some(b) = bytes {
            std::fs::write(dir.path().join(name), b).unwrap();
        }
        let cfg = dir.path().join("c.toml");
        std::fs::write(&cfg, terrain_toml(name, extra)).unwrap();
        let out = dir.path().join("out");
        let o = fbd(&["run", s(&cfg), "--out", s(&out)]);
        assert!(!out.join("trajectory.csv").exists());
        o
    };
    // Missing.
    check_error(
        &run("nowhere.npy", None, ""),
        &["terrain.file", "nowhere.npy", "no such file"],
    );
    // Wrong size: the data of 5 × 4 under a header of 5 × 5.
    let mut b = mujoco(nr, nc, &h);
    b[4..8].copy_from_slice(&5i32.to_le_bytes());
    check_error(
        &run("short.bin", Some(b), "elevation = [0.0, 0.1]\n"),
        &["terrain.file", "short.bin", "expected 100"],
    );
    let ragged = "0,0,0\n0,0\n".to_owned();
    check_error(
        &run("ragged.csv", Some(ragged.into_bytes()), ""),
        &["terrain.file", "ragged.csv", "line 2"],
    );
    let mut bad = npy(nr, nc, &h);
    bad.truncate(bad.len() - 8);
    check_error(
        &run("cut.npy", Some(bad), ""),
        &["terrain.file", "cut.npy", "bytes"],
    );
    // NaN heights.
    let mut hn = h.clone();
    hn[6] = f64::NAN;
    check_error(
        &run("nan.npy", Some(npy(nr, nc, &hn)), ""),
        &["terrain.file", "nan.npy", "row 1, column 2", "not finite"],
    );
    // Extent ≤ 0.
    std::fs::write(dir.path().join("ok.csv"), csv_grid(nc, &h)).unwrap();
    let cfg = dir.path().join("z.toml");
    std::fs::write(
        &cfg,
        format!("{HEAD}[terrain]\nkind = \"heightfield\"\nfile = \"ok.csv\"\nsize = [2.0, 0.0]\n"),
    )
    .unwrap();
    check_error(&fbd(&["run", s(&cfg)]), &["terrain.size", "positive"]);
    // An image needs its elevation.
    check_error(
        &run("e.png", Some(png16(nr, nc, &h, 0.0, 1.0)), ""),
        &["terrain.elevation", "e.png"],
    );
    // A patch with μD > μS.
    std::fs::write(
        &cfg,
        format!(
            "{HEAD}[[terrain.patch]]\nx = [0.0, 1.0]\nz = [0.0, 1.0]\nmu_static = 0.1\nmu_dynamic = 0.2\n"
        ),
    )
    .unwrap();
    check_error(&fbd(&["run", s(&cfg)]), &["terrain.patch[0].mu_dynamic"]);
}

/// Runs an example in-process; returns its parameters, rows and summary.
fn run_example(name: &str) -> (SpatialParams, Vec<RobotRecord>, fbd_sim::RunSummary) {
    let path = examples().join(name);
    let Config::Hexapod(c) = fbd_cli::config::load(&path).unwrap() else {
        panic!("hexapod")
    };
    let p = c.spatial_params(name).unwrap();
    let mut rows = Vec::new();
    let r = spatial::simulate(&p, "", name, None, &AtomicBool::new(false), &mut |r| {
        rows.push(r.clone())
    })
    .unwrap();
    assert!(r.run.error.is_none(), "{name}: {:?}", r.run.error);
    (p, rows, r.run)
}

/// The centres of mass of the body and of each leg's upper and lower link.
type Centres = ([f64; 3], Vec<[[f64; 3]; 2]>);

/// Coulomb's law (with the friction under the point) on every row and
/// Newton's second law of every body on every interior row but those of the
/// steps in `substepped` (solved in substeps: their recorded forces are the
/// first substep's, over Δt/n, not a whole step's; `events.csv` names them).
fn check_rows(p: &SpatialParams, rows: &[RobotRecord], substepped: &[usize]) -> f64 {
    let model = p.kinematic_model();
    let coms: Vec<Centres> = rows
        .iter()
        .map(|r| {
            let mut q = [0.0; NQ];
            q[..6].copy_from_slice(&r.q[..6]);
            for (i, &n) in p.legs.iter().enumerate() {
                q[6 + 3 * (n - 1)..9 + 3 * (n - 1)].copy_from_slice(&r.q[6 + 3 * i..9 + 3 * i]);
            }
            let mut d = HexapodData::new();
            forward(&model, &HexapodConfig::from_q(&q), &mut d);
            let v = |x: fbd_kinematics::nalgebra::Vector3<f64>| [x.x, x.y, x.z];
            let links = p
                .legs
                .iter()
                .map(|&n| [v(d.legs[n - 1].upper_com), v(d.legs[n - 1].lower_com)])
                .collect();
            (v(d.body_com), links)
        })
        .collect();
    let g = [0.0, -p.gravity, 0.0];
    let dt = p.dt;
    let index = p.record_index();
    let mut worst = 0.0f64;
    for (k, r) in rows.iter().enumerate() {
        for (c, &(leg, _)) in r.contacts.iter().zip(&index.contacts) {
            let f = c.force;
            let fnorm = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
            let tol = 1e-6 * (1.0 + fnorm);
            let mu = friction_at(p.terrain.patches(), &p.friction, c.point[0], c.point[2]);
            let n = c.normal;
            let [_, nv, _] = frame(&p.terrain, c.point[0], c.point[2]);
            let ftn = (0..3)
                .map(|i| (f[i] - n * nv[i]).powi(2))
                .sum::<f64>()
                .sqrt();
            match c.state {
                StateCode::St1 => assert!(fnorm < 1e-9, "t = {}: a free point pushed", r.t),
                StateCode::St2 => assert!(
                    n > -tol && ftn <= mu.mu_static * n + tol,
                    "t = {} leg {leg}: sticking outside the cone",
                    r.t,
                ),
                StateCode::St3 => assert!(
                    n > -tol && (ftn - mu.mu_dynamic * n).abs() < tol,
                    "t = {} leg {leg}: sliding |Ft| {ftn} ≠ μD·N",
                    r.t,
                ),
            }
        }
        if k == 0 || k + 1 == rows.len() || substepped.contains(&k) {
            continue;
        }
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
                    "{body}, t = {}, axis {i}: m·a = {} but Σ F = {sum}",
                    r.t,
                    m * a[i]
                );
            }
        };
        let mut on_body = Vec::new();
        for (i, li) in index.legs.iter().enumerate() {
            let leg = li.row(r);
            let ground = |kind: PointKind| {
                r.contacts
                    .iter()
                    .zip(&index.contacts)
                    .filter(|(_, id)| **id == (leg.leg, kind))
                    .fold([0.0; 3], |s, (c, _)| {
                        std::array::from_fn(|a| s[a] + c.force[a])
                    })
            };
            check(
                &format!("lower link {}", leg.leg),
                p.lower_mass,
                acc(&|j| coms[j].1[i][1]),
                &[
                    leg.knee_force,
                    ground(PointKind::Tip),
                    ground(PointKind::Knee),
                ],
            );
            check(
                &format!("upper link {}", leg.leg),
                p.upper_mass,
                acc(&|j| coms[j].1[i][0]),
                &[leg.hip_force, leg.knee_force.map(|x| -x)],
            );
            on_body.push(leg.hip_force.map(|x| -x));
            on_body.push(ground(PointKind::Hip));
        }
        check("body", p.body_mass, acc(&|j| coms[j].0), &on_body);
    }
    worst
}

#[test]
fn the_rough_walk_covers_its_metre_obeying_coulomb_and_newton_on_every_row() {
    let (p, rows, run) = run_example("hexapod_rough.toml");
    let substepped: Vec<usize> = run.retries.iter().map(|r| r.step).collect();
    assert!(
        substepped.len() * 100 < rows.len(),
        "few steps need substeps: {substepped:?}"
    );
    let worst = check_rows(&p, &rows, &substepped);
    let (first, last) = (&rows[0], rows.last().unwrap());
    let moved = last.q[2] - first.q[2];
    println!("moved {moved} m along Z, largest relative imbalance {worst:e}");
    assert!(moved < -0.95, "walks 1 m along −Z: {moved}");
    common::readme::doc("README.md").figure(
        "the body ends ",
        " m along −Z",
        -moved,
        "the rough walk's distance",
    );
    // Every foot touched down on the surface, whose height varies.
    let touchdowns: Vec<_> = run
        .events
        .iter()
        .filter(|e| e.from == StateCode::St1 && e.point == PointKind::Tip)
        .collect();
    assert!(touchdowns.len() > 60);
    let heights: Vec<f64> = touchdowns
        .iter()
        .map(|e| {
            let c = p
                .record_index()
                .contacts
                .iter()
                .position(|id| *id == (e.leg, PointKind::Tip))
                .map(|c| &rows[e.step + 1].contacts[c])
                .unwrap();
            assert!(
                (c.point[1] - p.terrain.height(c.point[0], c.point[2])).abs() < 1e-9,
                "a touchdown off the surface"
            );
            c.point[1]
        })
        .collect();
    let spread = heights.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
        - heights.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(spread > 0.03, "the feet landed at heights {spread} m apart");
}

#[test]
fn the_stairs_example_climbs_three_steps() {
    let (p, rows, _) = run_example("hexapod_stairs.toml");
    let (first, last) = (&rows[0], rows.last().unwrap());
    for (c, &(leg, kind)) in last.contacts.iter().zip(&p.record_index().contacts) {
        if kind != PointKind::Tip {
            continue;
        }
        assert!(
            (c.point[1] - 0.15).abs() < 1e-6,
            "leg {leg} ends at y = {}, not on the top step",
            c.point[1]
        );
    }
    let climbed = last.q[1] - first.q[1];
    println!(
        "body climbed {climbed} m, moved {} m along Z",
        last.q[2] - first.q[2]
    );
    assert!(climbed > 0.13, "climbed {climbed}");
    common::readme::doc("README.md").figure(
        "all six feet end on the top step, the body ",
        " m higher",
        climbed,
        "the stairs' climb",
    );
}

#[test]
fn on_the_ice_patch_the_feet_slip_and_off_it_they_stick() {
    let (_, rows, _) = run_example("hexapod_ice_patch.toml");
    // The README's bound on the feet that slide off the ice.
    let readme = common::readme::doc("README.md");
    let unloaded = common::readme::parse(
        &readme.quoted("off it only nearly unloaded feet (N < ", " N) slide"),
    );
    let (mut on_ice, mut off_ice, mut off_loaded) = (0, 0, 0);
    for r in &rows {
        for c in r.contacts.iter().filter(|c| c.state == StateCode::St3) {
            if c.point[2] >= 0.0 {
                on_ice += 1;
            } else {
                off_ice += 1;
                off_loaded += usize::from(c.normal > unloaded);
            }
        }
    }
    println!("sliding rows: {on_ice} on the ice, {off_ice} off it ({off_loaded} loaded)");
    assert!(on_ice > 1000, "the feet on the ice slip");
    assert_eq!(off_loaded, 0, "a loaded foot off the ice slid");
    assert!(off_ice * 10 < on_ice);
    readme.count(
        "(`[[terrain.patch]]`, μ = 0.1, on ground of μS = 0.8): ",
        " sliding rows on the ice",
        on_ice,
        "sliding rows on the ice",
    );
}

#[test]
fn export_mjcf_writes_the_height_map_as_an_hfield() {
    let o = fbd(&["export", "mjcf", &example("hexapod_rough.toml")]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let x = String::from_utf8(o.stdout).unwrap();
    // 1.6 m × 2.4 m at 1 cm: 161 rows along X (MuJoCo's columns), 241
    // along Z (MuJoCo's rows).
    assert!(
        x.contains("<hfield name=\"terrain\" nrow=\"241\" ncol=\"161\" size=\"0.8 1.2 "),
        "{}",
        &x[..2000.min(x.len())]
    );
    assert!(x.contains("type=\"hfield\"") && x.contains("xyaxes=\"1 0 0 0 0 -1\""));
    let o = fbd(&["export", "mjcf", &example("hexapod_ice_patch.toml")]);
    check_error(&o, &["terrain.patch"]);
}
