//! The sweep format's `[set]` table: keys set to one value in every run,
//! in every mode, not columns of `index.csv`, no random draws.

mod common;

use common::{examples, fbd, s};
use fbd_cli::sweep::{SweepFile, expand, plan};
use fbd_scenario::Config;
use std::path::Path;

const RANDOM: &str = r#"mode = "random"
samples = 4
seed = 15
[vary]
"terrain.mu_static" = { min = 0.2, max = 1.2 }
"initial.phi_z_deg" = { min = -30.0, max = 30.0 }
"initial.leg3.theta_deg" = { min = [-20.0, 225.0], max = [20.0, 265.0] }
[derive]
"terrain.mu_dynamic" = { from = "terrain.mu_static", scale = 0.75 }
"#;

const SET: &str = "[set]\n\"output.stride\" = 7\n\"time.duration\" = 0.1\n";

/// A sweep file in `dir` on examples/paper.toml.
fn write(dir: &Path, name: &str, body: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    let base = examples().join("paper.toml").display().to_string();
    std::fs::write(&p, format!("base = {base:?}\n{body}")).unwrap();
    p
}

fn stride_and_duration(c: &fbd_cli::sweep::RunConfig) -> (usize, f64) {
    match c {
        fbd_cli::sweep::RunConfig::Model(Config::Planar(p)) => (p.output.stride, p.time.duration),
        fbd_cli::sweep::RunConfig::Model(Config::Hexapod(h)) => (h.output.stride, h.time.duration),
        fbd_cli::sweep::RunConfig::Robot(r) => (r.config.output.stride, r.config.time.duration),
    }
}

#[test]
fn set_reaches_every_run_in_every_mode_and_draws_nothing() {
    let t = tempfile::tempdir().unwrap();
    for body in [
        RANDOM.to_owned(),
        "mode = \"grid\"\n[vary]\n\"terrain.mu_static\" = [0.3, 0.5]\n\"initial.drop_height\" = [0.3, 0.4]\n"
            .to_owned(),
        "mode = \"zip\"\n[vary]\n\"terrain.mu_static\" = [0.3, 0.5]\n\"initial.drop_height\" = [0.3, 0.4]\n"
            .to_owned(),
    ] {
        let without = plan(&write(t.path(), "a.toml", &body)).unwrap();
        let with = plan(&write(t.path(), "b.toml", &format!("{body}{SET}"))).unwrap();
        // The same runs with the same values (random: the same draws)…
        assert_eq!(with.values, without.values, "{body}");
        assert_eq!(with.keys, without.keys, "[set] keys are not varied keys");
        assert!(!with.keys.iter().any(|k| k == "output.stride"));
        // …and every run has the set values.
        assert_eq!(with.configs.len(), without.configs.len());
        for c in &with.configs {
            assert_eq!(stride_and_duration(c), (7, 0.1), "{body}");
        }
        for c in &without.configs {
            assert_ne!(stride_and_duration(c), (7, 0.1), "{body}");
        }
    }
    // expand() alone (the draws) does not see [set].
    let a: SweepFile = toml::from_str(RANDOM).unwrap();
    let b: SweepFile = toml::from_str(&format!("{RANDOM}{SET}")).unwrap();
    assert_eq!(expand(&a, "a").unwrap(), expand(&b, "b").unwrap());
    // The 1000-run examples keep their draws: the values of their [vary]
    // and [derive] tables with and without their [set] table.
    for name in [
        "sweep_landing_1000_1ms.toml",
        "sweep_hexapod_landing_1000.toml",
    ] {
        let text = std::fs::read_to_string(examples().join(name)).unwrap();
        let full: SweepFile = toml::from_str(&text).unwrap();
        assert!(!full.set.is_empty(), "{name} has a [set] table");
        let mut bare = full.clone();
        bare.set = Default::default();
        assert_eq!(expand(&full, name).unwrap(), expand(&bare, name).unwrap());
    }
}

#[test]
fn set_keys_are_in_config_and_sweep_json_not_in_index() {
    let t = tempfile::tempdir().unwrap();
    let with = write(t.path(), "with.toml", &format!("{RANDOM}{SET}"));
    let without = write(t.path(), "without.toml", RANDOM);
    let dw = t.path().join("w");
    let o = fbd(&["sweep", s(&with), "--out", s(&dw), "--jobs", "2"]);
    assert!(o.status.success(), "{o:?}");
    // The varied values are those of the sweep without [set] (no draws
    // consumed), checked on the plan: running it is not needed.
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dw.join("sweep.json")).unwrap()).unwrap();
    let planned = plan(&without).unwrap();
    let runs: Vec<Vec<String>> = planned
        .values
        .iter()
        .map(|v| v.iter().map(fbd_cli::sweep::format_value).collect())
        .collect();
    assert_eq!(j["runs"], serde_json::to_value(&runs).unwrap());
    // sweep.json records the table (as [vary]: pairs in file order);
    // index.csv has no column for it.
    assert_eq!(
        j["definition"]["set"],
        serde_json::json!([["output.stride", 7], ["time.duration", 0.1]])
    );
    let idx = std::fs::read_to_string(dw.join("index.csv")).unwrap();
    let header = idx.lines().next().unwrap();
    assert_eq!(
        header,
        "run,status,terrain.mu_static,initial.phi_z_deg,initial.leg3.theta_deg,terrain.mu_dynamic,\
         touchdown3,touchdown4,slip3,slip4,peak_n3,peak_n4,peak_fa3,peak_fa4,peak_joint_force,\
         steps,wall_seconds,error"
    );
    assert_eq!(idx.lines().count(), 5);
    for i in 0..4 {
        let d = dw.join("runs").join(i.to_string());
        let c: toml::Table =
            toml::from_str(&std::fs::read_to_string(d.join("config.toml")).unwrap()).unwrap();
        assert_eq!(c["output"]["stride"].as_integer(), Some(7), "run {i}");
        assert_eq!(c["time"]["duration"].as_float(), Some(0.1), "run {i}");
        // 0.1 s at the paper's Δt = 10 ms: 11 states, rows 0, 7.
        let rows = std::fs::read_to_string(d.join("trajectory.csv"))
            .unwrap()
            .lines()
            .count();
        assert_eq!(rows, 1 + 2, "run {i}");
    }
}

#[test]
fn bad_set_keys_are_one_line_errors_naming_the_file_and_key() {
    let t = tempfile::tempdir().unwrap();
    let grid = "mode = \"grid\"\n[vary]\n\"terrain.mu_static\" = [0.3]\n[derive]\n\"terrain.mu_dynamic\" = { from = \"terrain.mu_static\", scale = 0.75 }\n";
    for (set, needle) in [
        ("\"output.strid\" = 10", "set.\"output.strid\": "),
        ("\"output.stride\" = \"ten\"", "set.\"output.stride\": "),
        (
            "\"terrain.mu_static\" = 0.5",
            "set.\"terrain.mu_static\": the key is also in [vary]",
        ),
        (
            "\"terrain.mu_dynamic\" = 0.2",
            "set.\"terrain.mu_dynamic\": the key is also in [derive]",
        ),
        // A value out of range names the run and the key.
        ("\"output.stride\" = 0", "output.stride"),
    ] {
        let f = write(t.path(), "bad.toml", &format!("{grid}[set]\n{set}\n"));
        let out = t.path().join("out");
        let o = fbd(&["sweep", s(&f), "--out", s(&out)]);
        assert_eq!(o.status.code(), Some(2), "{set}: {o:?}");
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(e.trim_end().lines().count(), 1, "{e}");
        assert!(
            e.starts_with(&format!("error: {}: ", f.display())) && e.contains(needle),
            "{set}: {e}"
        );
        assert!(!out.exists(), "nothing written for a bad sweep file");
    }
}

/// The 1000-run examples write under 100 MB by default: their first 20
/// runs (the same draws) write under 100 kB a run, what `fbd sweep`
/// prints for them.
#[test]
fn the_1000_run_examples_write_under_100_mb() {
    let t = tempfile::tempdir().unwrap();
    for name in [
        "sweep_landing_1000.toml",
        "sweep_landing_1000_1ms.toml",
        "sweep_hexapod_landing_1000.toml",
    ] {
        let text = std::fs::read_to_string(examples().join(name)).unwrap();
        assert!(text.contains("\nsamples = 1000\n"), "{name}");
        // The copy sits beside the examples' base files in the temporary
        // directory.
        let dir = t.path().join(name.trim_end_matches(".toml"));
        std::fs::create_dir_all(&dir).unwrap();
        for base in ["paper.toml", "hexapod_drop.toml"] {
            std::fs::copy(examples().join(base), dir.join(base)).unwrap();
        }
        let sweep = dir.join("sweep.toml");
        std::fs::write(
            &sweep,
            text.replace("\nsamples = 1000\n", "\nsamples = 20\n"),
        )
        .unwrap();
        let out = dir.join("out");
        let o = fbd(&["sweep", s(&sweep), "--out", s(&out), "--jobs", "2"]);
        assert!(o.status.success(), "{name}: {o:?}");
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(!e.contains("warning"), "{name}: {e}");
        let bytes = fbd_cli::sweep::dir_bytes(&out);
        let said = format!(
            "files in {}: index.csv sweep.json sweep.svg runs/ ({};",
            out.display(),
            fbd_cli::sweep::human_bytes(bytes)
        );
        let so = String::from_utf8_lossy(&o.stdout);
        assert!(so.contains(&said), "{name}: {so}");
        assert!(
            bytes * 50 < 100_000_000,
            "{name}: 20 runs wrote {bytes} bytes, 1000 would write about {} MB",
            bytes * 50 / 1_000_000
        );
    }
}

/// docs/sweep.md: the 1 ms landings without their `[set]` table are
/// estimated at 951 MB, and the warning suggests a stride of 4 or Parquet.
#[test]
fn the_1ms_landings_without_set_warn_as_quoted() {
    let text = std::fs::read_to_string(examples().join("sweep_landing_1000_1ms.toml")).unwrap();
    // The [set] table is the file's last.
    let (without, set) = text.split_once("\n[set]\n").unwrap();
    assert!(!set.contains('['), "{set}");
    let t = tempfile::tempdir().unwrap();
    std::fs::copy(examples().join("paper.toml"), t.path().join("paper.toml")).unwrap();
    let bare = t.path().join("bare.toml");
    std::fs::write(&bare, without).unwrap();
    let p = plan(&bare).unwrap();
    let w = fbd_cli::output::sweep_size_warning(&p.trajectories, false, false).unwrap();
    let d = common::readme::doc("docs/sweep.md");
    let mb = common::readme::parse(&d.quoted(
        "landings without their `[set]` table are estimated at ",
        " MB",
    ));
    assert!(
        w.contains(&format!("will write about {mb:.1} MB")),
        "docs/sweep.md quotes {mb} MB: {w}"
    );
    d.has(
        "`[output] stride = 4` (or `[set] \"output.stride\" = 4`) or `format = \"parquet\"` is suggested",
        "the suggestion",
    );
    assert!(
        w.contains("`[output] stride = 4`") && w.contains("parquet"),
        "{w}"
    );
    // With the [set] table: no warning.
    let p = plan(&examples().join("sweep_landing_1000_1ms.toml")).unwrap();
    assert_eq!(
        fbd_cli::output::sweep_size_warning(&p.trajectories, false, false),
        None
    );
}
