//! Writes a hexapod run folder for the viewer's tests: `DIR/config.toml`
//! (the standing hexapod of `examples/hexapod_stand.toml`) and
//! `DIR/trajectory.csv` of a kinematic tripod gait along +X, in the columns
//! of a hexapod run (`t, rx, ry, rz, phi_x, phi_y, phi_z, theta{j}_{n},
//! foot{n}_x/y/z, stance{n}, com_x/y/z`). Joint angles come from the
//! leg inverse kinematics, so the stance feet stay where they landed.
//!
//! `cargo run -p fbd-cli --example hexapod_fixture -- DIR`, then
//! `fbd view DIR`.

use std::fmt::Write as _;
use std::path::PathBuf;

use fbd_kinematics::hexapod::{HexapodConfig, HexapodData, NQ, forward, joint_index};
use fbd_kinematics::ik::{KneeBranch, leg_ik_body};
use fbd_kinematics::nalgebra::Vector3;
use fbd_kinematics::pose::BodyPose;

/// Body speed (m/s), gait period (s), step height (m), body height (m).
const SPEED: f64 = 0.1;
const PERIOD: f64 = 1.0;
const LIFT: f64 = 0.05;
const HEIGHT: f64 = 0.35;
const DT: f64 = 0.01;
const DURATION: f64 = 3.0;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .ok_or("usage: hexapod_fixture DIR")?,
    );
    std::fs::create_dir_all(&dir)?;
    let config_text = include_str!("../../../examples/hexapod_stand.toml")
        .replace("duration = 0.45", &format!("duration = {DURATION}"));
    let config = match fbd_cli::config::parse_str(&config_text, "hexapod_stand.toml", &[])? {
        fbd_cli::Config::Hexapod(c) => c,
        fbd_cli::Config::Planar(_) => return Err("not a hexapod configuration".into()),
    };
    let model = fbd_cli::viewer::view::hexapod_model(&config);
    // Nominal feet (body frame): the standing pose of the configuration.
    let stand = HexapodConfig {
        pose: BodyPose::new([0.0; 3], [0.0; 3]),
        joints: config.joints_rad(),
    };
    let mut data = HexapodData::new();
    forward(&model, &stand, &mut data);
    let nominal: Vec<Vector3<f64>> = data.legs.iter().map(|l| l.tip).collect();
    // Tripods: legs 1, 4, 5 swing first, then 2, 3, 6.
    let swing_start = [0.0, 0.5, 0.5, 0.0, 0.0, 0.5].map(|f| f * PERIOD);

    let mut csv = String::from("t,rx,ry,rz,phi_x,phi_y,phi_z");
    for n in 1..=6 {
        for j in 1..=3 {
            write!(csv, ",theta{j}_{n}")?;
        }
    }
    for n in 1..=6 {
        write!(csv, ",foot{n}_x,foot{n}_y,foot{n}_z")?;
    }
    for n in 1..=6 {
        write!(csv, ",stance{n}")?;
    }
    csv.push_str(",com_x,com_y,com_z\n");
    let steps = (DURATION / DT).round() as usize;
    for k in 0..=steps {
        let t = k as f64 * DT;
        let body = Vector3::new(SPEED * t, HEIGHT, 0.0);
        let mut q = [0.0; NQ];
        q[..3].copy_from_slice(body.as_slice());
        let mut stance = [true; 6];
        for leg in 0..6 {
            let u = (t - swing_start[leg]) / PERIOD;
            let cycle = u.floor();
            let frac = u - cycle;
            let x0 = nominal[leg].x + SPEED * swing_start[leg] - 0.25 * SPEED * PERIOD;
            let (x, y) = if frac < 0.5 {
                let p = frac / 0.5;
                let s = 0.5 * (1.0 - (std::f64::consts::PI * p).cos());
                stance[leg] = false;
                (
                    x0 + (cycle + s) * SPEED * PERIOD,
                    LIFT * (std::f64::consts::PI * p).sin(),
                )
            } else {
                (x0 + (cycle + 1.0) * SPEED * PERIOD, 0.0)
            };
            let foot = Vector3::new(x, y, nominal[leg].z);
            let theta = leg_ik_body(&model, leg, &(foot - body), KneeBranch::Up)?;
            q[joint_index(leg, 0)..joint_index(leg, 0) + 3].copy_from_slice(&theta);
        }
        forward(&model, &HexapodConfig::from_q(&q), &mut data);
        write!(csv, "{t}")?;
        for v in q {
            write!(csv, ",{v}")?;
        }
        for l in &data.legs {
            write!(csv, ",{},{},{}", l.tip.x, l.tip.y, l.tip.z)?;
        }
        for s in stance {
            write!(csv, ",{}", u8::from(s))?;
        }
        writeln!(csv, ",{},{},{}", body.x, body.y, body.z)?;
    }
    std::fs::write(dir.join("config.toml"), config_text)?;
    std::fs::write(dir.join("trajectory.csv"), csv)?;
    println!("{}", dir.display());
    Ok(())
}
