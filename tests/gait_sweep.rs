//! `fbd sweep` over a hexapod base configuration: every run is the
//! kinematic gait, `index.csv` has the walk's columns (distance, margin,
//! peak joint rates), and the distance scales with the commanded speed.

use fbd_cli::sweep::{HEXAPOD_COLUMNS, SweepArgs, sweep_command};

const BASE: &str =
    "model = \"hexapod\"\n[time]\nduration = 4.0\n[gait]\nperiod = 1.0\nramp = 0.5\n";

#[test]
fn a_hexapod_sweep_writes_the_walk_columns() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("base.toml"), BASE).unwrap();
    let sweep = dir.path().join("sweep.toml");
    std::fs::write(
        &sweep,
        "base = \"base.toml\"\n[vary]\n\"gait.forward_speed\" = [0.05, 0.1]\n\"gait.kind\" = [\"tripod\", \"wave\"]\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let mut text = Vec::new();
    sweep_command(
        SweepArgs {
            command: None,
            sweep: Some(sweep),
            out: out.clone(),
            jobs: Some(1),
            shard: None,
            resume: false,
            plot: "touchdown".into(),
            viewer: false,
            plots: false,
        },
        &mut text,
    )
    .unwrap();
    let index = std::fs::read_to_string(out.join("index.csv")).unwrap();
    let mut lines = index.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let mut want = vec!["run", "status", "gait.forward_speed", "gait.kind"];
    want.extend(HEXAPOD_COLUMNS);
    assert_eq!(header, want);
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 4);
    let mut distance = [[0.0; 2]; 2];
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r[col("status")], "ok", "{r:?}");
        let d: f64 = r[col("distance")].parse().unwrap();
        distance[i / 2][i % 2] = d;
        // 3 s of walking less the two half-ramps: 2.5 s at the speed.
        let v: f64 = r[col("gait.forward_speed")].parse().unwrap();
        assert!((d - 2.5 * v).abs() < 1e-9, "{r:?}");
        let margin: f64 = r[col("min_margin")].parse().unwrap();
        assert!(margin > 0.1 && margin < 0.4, "{r:?}");
        assert!(r[col("max_joint_rate")].parse::<f64>().unwrap() > 0.0);
        assert_eq!(r[col("steps")], "401");
        // One lift-off per leg and period: 3 periods of tripod or wave.
        assert_eq!(r[col("liftoffs")], "18", "{r:?}");
    }
    // The wave keeps five feet down: a larger minimum margin than the
    // tripod's three at the same speed.
    let margin = |i: usize| rows[i][col("min_margin")].parse::<f64>().unwrap();
    assert!(margin(1) > margin(0) && margin(3) > margin(2));
    assert!(out.join("sweep.svg").is_file());
    // Per-run plots only with `plots: true` (`--plots`).
    assert!(out.join("runs/3/trajectory.csv").is_file());
    assert!(!out.join("runs/3/gait.svg").exists());
}
