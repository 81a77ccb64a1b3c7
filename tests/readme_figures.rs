//! The figures README.md (and docs/*.md) quote from runs of the examples
//! are those the runs produce: this test runs each example, reads the
//! figure from the document's text and fails, naming the document's line,
//! when they disagree (a stale figure; `tests/common/readme.rs`). Timings
//! are not checked (they are quoted as ranges with the machine and the
//! command); every other figure below is.
//!
//! Checked here: the default experiment's events table (touchdowns, slips,
//! the event count at 10 ms), when the hips land, hip 4 reaches its stop
//! and the robot comes to rest, the tips' heights and free-fall times; the
//! tripod gait's printed report, the turn's and the wave gait's margins and
//! distance, the default gait's walk and stance; the dynamic walk's printed
//! report (steps, Newton iterations, distance, height), its first slips
//! and the force under its sliding feet, the sizes of its CSV and Parquet
//! files; the walk on ice's distance against the walk's; the peer
//! benchmark's standing and walking hexapod (fbd's side); the friction
//! sweep of the standing hexapod (docs/sweep.md); the two 1000-run landing
//! sweeps (completed runs, substeps, cycles, runs still moving, events).
//! Elsewhere: the
//! Δt table (`tests/dt_convergence.rs`), the terrain examples
//! (`crates/cli/tests/terrain.rs`), run 872 of the 1 ms landings
//! (`tests/landing_chatter.rs`).

mod common;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use common::readme::doc;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn readme() -> String {
    std::fs::read_to_string(root().join("README.md")).unwrap()
}

/// A finished run: its printed report, `summary.json` and its folder.
struct Run {
    report: String,
    summary: serde_json::Value,
    dir: tempfile::TempDir,
}

impl Run {
    /// The rows of `trajectory.csv` as maps from column names to values.
    fn rows(&self) -> Vec<HashMap<String, String>> {
        let mut r = csv::Reader::from_path(self.dir.path().join("trajectory.csv")).unwrap();
        let names: Vec<String> = r.headers().unwrap().iter().map(str::to_owned).collect();
        r.records()
            .map(|rec| {
                names
                    .iter()
                    .cloned()
                    .zip(rec.unwrap().iter().map(str::to_owned))
                    .collect()
            })
            .collect()
    }

    /// Bytes of the file `name` the run wrote.
    fn size(&self, name: &str) -> u64 {
        std::fs::metadata(self.dir.path().join(name)).unwrap().len()
    }
}

/// A value of a `trajectory.csv` row.
fn at(row: &HashMap<String, String>, column: &str) -> f64 {
    row[column].parse().unwrap()
}

/// Runs `fbd run CONFIG` (the built-in default without one) into a
/// temporary folder: the printed report and `summary.json`.
fn run(config: Option<&str>) -> (String, serde_json::Value) {
    let r = run_in(config.map(|c| root().join(c)).as_deref());
    (r.report, r.summary)
}

/// Runs `fbd run CONFIG` into a temporary folder, which the result keeps.
fn run_in(path: Option<&Path>) -> Run {
    let dir = tempfile::tempdir().unwrap();
    let mut out = Vec::new();
    fbd_cli::run::run_command(path, dir.path(), &mut out).unwrap();
    let summary = std::fs::read_to_string(dir.path().join("summary.json")).unwrap();
    Run {
        report: String::from_utf8(out).unwrap(),
        summary: serde_json::from_str(&summary).unwrap(),
        dir,
    }
}

/// Runs the configuration `text` (written to a temporary file).
fn run_text(text: &str) -> Run {
    let cfg = tempfile::tempdir().unwrap();
    let path = cfg.path().join("config.toml");
    std::fs::write(&path, text).unwrap();
    run_in(Some(&path))
}

/// An example's text.
fn example(name: &str) -> String {
    std::fs::read_to_string(root().join(name)).unwrap()
}

/// Fails unless README.md contains `want`, showing the README's nearest
/// line (the one starting like `want`).
fn has(readme: &str, want: &str, what: &str) {
    if readme.contains(want) {
        return;
    }
    let key: String = want.chars().take(24).collect();
    let near: Vec<&str> = readme.lines().filter(|l| l.contains(key.trim())).collect();
    panic!(
        "README.md is stale ({what}): expected\n  {want}\nREADME lines starting alike:\n  {}",
        near.join("\n  ")
    );
}

/// The printed report's line starting with `prefix`.
fn line<'a>(report: &'a str, prefix: &str) -> &'a str {
    report
        .lines()
        .find(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no line `{prefix}…` in\n{report}"))
}

/// `solved 3001 steps, 4060 Newton iterations, 0.089 s` without the time.
fn without_time(l: &str) -> &str {
    l.rsplit_once(", ").map_or(l, |(a, _)| a)
}

#[test]
fn default_experiment_events_table() {
    let r = readme();
    let (_, s) = run(None);
    let t = |k: &str, leg: &str| s[k][leg].as_f64().unwrap();
    let (td4, td3) = (t("first_touchdown", "leg4"), t("first_touchdown", "leg3"));
    let dt = s["dt"].as_f64().unwrap();
    has(
        &r,
        &format!(
            "| leg 4 reaches the soil | 0.20 s | step {td4} → tip on the ground at **{:.2} s** |",
            td4 + dt
        ),
        "leg 4 touchdown",
    );
    has(
        &r,
        &format!(
            "| leg 3 reaches the soil | 0.02 s after leg 4 | step {td3} → on the ground at **{:.2} s** |",
            td3 + dt
        ),
        "leg 3 touchdown",
    );
    let (s3, s4) = (t("first_slip", "leg3"), t("first_slip", "leg4"));
    assert_eq!(s3, s4, "the README says both legs slip at once");
    has(
        &r,
        &format!("| both legs start slipping | around 0.24 s | **{s3:.2} s** (both) |"),
        "slips",
    );
    let events = s["events"].as_array().unwrap().len();
    has(
        &r,
        &format!("| 10 ms | 0.19–0.20 s | 0.21–0.22 s | {s3:.2} s | {s4:.2} s | {events} |"),
        "events at 10 ms",
    );
}

/// "all 81 neighbours with ±10 % body mass, ±33 % upper-link mass, …
/// reproduce the same event times to within one step": the README's
/// percentages, each parameter at −, 0 and +, every combination (the link
/// inertias m·a²/12 scale with their masses).
#[test]
fn default_parameters_are_robust_as_quoted() {
    let r = doc("README.md");
    let pct = |after: &str| common::readme::parse(&r.quoted("±", after)) / 100.0;
    let (body, upper, lower, inertia) = (
        pct(" % body mass"),
        pct(" % upper-link mass"),
        pct(" % lower-link mass"),
        pct(" % body inertia"),
    );
    let (_, reference) = run(None);
    let times = |s: &serde_json::Value| -> Vec<f64> {
        ["first_touchdown", "first_slip"]
            .iter()
            .flat_map(|k| ["leg3", "leg4"].map(|l| s[k][l].as_f64().unwrap()))
            .collect()
    };
    let dt = reference["dt"].as_f64().unwrap();
    let want = times(&reference);
    let mut n = 0;
    for b in [-body, 0.0, body] {
        for u in [-upper, 0.0, upper] {
            for l in [-lower, 0.0, lower] {
                for i in [-inertia, 0.0, inertia] {
                    let (mu, ml) = (0.3 * (1.0 + u), 1.1 * (1.0 + l));
                    let config = format!(
                        "[body]\nmass = {}\ninertia = {}\n[leg]\nupper_mass = {mu}\nupper_inertia = {}\nlower_mass = {ml}\nlower_inertia = {}\n[output]\nviewer = false\nplots = false\n",
                        10.0 * (1.0 + b),
                        0.3 * (1.0 + i),
                        mu * 0.2f64.powi(2) / 12.0,
                        ml * 0.42f64.powi(2) / 12.0,
                    );
                    let got = times(&run_text(&config).summary);
                    for (g, w) in got.iter().zip(&want) {
                        assert!(
                            (g - w).abs() <= dt + 1e-9,
                            "README.md is stale: body mass {b:+}, upper {u:+}, lower {l:+}, inertia {i:+}: events at {got:?}, the default's at {want:?}"
                        );
                    }
                    n += 1;
                }
            }
        }
    }
    r.count("(all ", " neighbours with ±", n, "neighbours");
}

#[test]
fn tripod_gait_report() {
    let r = readme();
    let (report, _) = run(Some("examples/hexapod_tripod.toml"));
    has(
        &r,
        without_time(line(&report, "computed ")),
        "tripod: steps",
    );
    has(&r, line(&report, "distance walked "), "tripod: distance");
    has(
        &r,
        line(&report, "minimum stability margin "),
        "tripod: margin",
    );
}

#[test]
fn dynamic_walk_and_walk_on_ice() {
    let r = readme();
    let walk = run_in(Some(&root().join("examples/hexapod_walk.toml")));
    // Every ST3 row of the walk is a foot about to lift off, nearly
    // unloaded: under the README's bound.
    let mut sliding = 0.0f64;
    for row in walk.rows() {
        for n in 1..=6 {
            if row[&format!("state{n}")] == "ST3" {
                sliding = sliding.max(at(&row, &format!("foot{n}_n")));
            }
        }
    }
    let bound = common::readme::parse(
        &doc("README.md").quoted("a foot's last milliseconds before ST1, under ", " N)"),
    );
    assert!(
        sliding < bound,
        "README.md is stale: a sliding foot of the walk carries {sliding} N, the README says under {bound} N"
    );
    let (report, s) = (walk.report, walk.summary);
    has(
        &r,
        without_time(line(&report, "solved ")),
        "walk: steps and Newton iterations",
    );
    has(
        &r,
        line(&report, "body moved "),
        "walk: distance and height",
    );
    // The first ST3 of each foot that slips: the README names them.
    let slips: Vec<String> = s["first_slip"]
        .as_object()
        .unwrap()
        .iter()
        .filter_map(|(leg, t)| Some(format!("{leg} {}", t.as_f64()?)))
        .collect();
    has(
        &r,
        &format!("`first_slip`: {}", slips.join(", ")),
        "walk: first slips",
    );

    let ice_run = run_in(Some(&root().join("examples/hexapod_walk_ice.toml")));
    // The share of the loaded stance rows (above the README's load) that
    // slide.
    let readme_doc = doc("README.md");
    let load = common::readme::parse(
        &readme_doc.quoted("the stance feet carrying more than ", " N slip in"),
    );
    let (mut loaded, mut sliding) = (0usize, 0usize);
    for row in ice_run.rows() {
        for n in 1..=6 {
            let state = &row[&format!("state{n}")];
            if state != "ST1" && at(&row, &format!("foot{n}_n")) > load {
                loaded += 1;
                sliding += usize::from(state == "ST3");
            }
        }
    }
    readme_doc.figure(
        " N slip in ",
        " % of their rows",
        100.0 * sliding as f64 / loaded as f64,
        "walk on ice: sliding rows",
    );
    let ice = ice_run.summary;
    let d = |s: &serde_json::Value| s["displacement"][0].as_f64().unwrap();
    let (walk, on_ice) = (d(&s), d(&ice));
    let figures = format!("{on_ice:.3} m against {walk:.3} m");
    has(
        &r,
        &format!("the robot ends {on_ice:.3} m up it against {walk:.3} m"),
        "walk on ice: distances",
    );
    has(
        &r,
        &format!(
            "walks {:.0} % less far ({figures})",
            (1.0 - on_ice / walk) * 100.0
        ),
        "walk on ice: per cent",
    );
    has(
        &r,
        &format!("the {:.0} mm lost", (walk - on_ice) * 1e3),
        "walk on ice: millimetres",
    );
}

#[test]
fn default_experiment_after_the_papers_events() {
    let r = doc("README.md");
    let run = run_in(None);
    let s = &run.summary;
    let dt = s["dt"].as_f64().unwrap();
    let events = s["events"].as_array().unwrap();
    let when = |point: &str, leg: u64, from: &str| {
        events
            .iter()
            .find(|e| e["point"] == point && e["leg"] == leg && e["from"] == from)
            .unwrap_or_else(|| panic!("no {point} {leg} event from {from}"))["t"]
            .as_f64()
            .unwrap()
    };
    let (hip3, hip4) = (when("hip", 3, "ST1"), when("hip", 4, "ST1"));
    assert_eq!(hip3, hip4, "the README says both hips land at once");
    r.figure(
        "After the paper's events the body lands on both hips at ",
        " s",
        hip3,
        "hips landing",
    );
    r.figure(
        "hip 4 reaches its limit (θ2 = −120°) at ",
        " s",
        when("hip_limit", 4, "free"),
        "hip 4 at its stop",
    );
    // At rest from the step after the last event.
    let last = events.last().unwrap()["t"].as_f64().unwrap() + dt;
    r.figure(
        "and from ",
        " s the robot lies at rest",
        last,
        "at rest from",
    );
    r.figure(
        "the robot at rest (from ",
        " s, on both feet",
        last,
        "at rest from (table)",
    );
    // The tips' initial heights and their free-fall times.
    let rows = run.rows();
    let (h3, h4) = (at(&rows[0], "tip3_y"), at(&rows[0], "tip4_y"));
    let g = 9.81;
    r.figure("the tips (at ", " m and ", h4, "tip 4's height");
    r.figure(
        " m and ",
        " m) reach the ground after",
        h3,
        "tip 3's height",
    );
    r.figure(
        "the free-fall times √(2h/g) = ",
        " s and ",
        (2.0 * h4 / g).sqrt(),
        "tip 4's free fall",
    );
    r.figure(
        " s and ",
        " s; the slips converge",
        (2.0 * h3 / g).sqrt(),
        "tip 3's free fall",
    );
}

#[test]
fn kinematic_gaits() {
    let r = doc("README.md");
    let margin = |s: &serde_json::Value| s["min_margin"]["value"].as_f64().unwrap();
    let (_, turn) = run(Some("examples/hexapod_turn.toml"));
    r.figure(
        "turns in place 90° (tripod, 15°/s; minimum margin ",
        " m)",
        margin(&turn),
        "turn: margin",
    );
    r.figure(
        "turns in place ",
        "° (tripod",
        turn["heading_change_deg"].as_f64().unwrap(),
        "turn: angle",
    );
    let (_, wave) = run(Some("examples/hexapod_wave_slope.toml"));
    r.figure(
        "`examples/hexapod_wave_slope.toml` climbs ",
        " m up a 10° slope",
        wave["distance"].as_f64().unwrap(),
        "wave gait: distance",
    );
    r.figure(
        "(one leg in the air at a time; minimum margin ",
        " m)",
        margin(&wave),
        "wave gait: margin",
    );
    // The defaults: a stance, and an empty [gait] walks.
    let walk = run_text("model = \"hexapod\"\ndynamics = \"kinematic\"\n[gait]\n");
    let s = &walk.summary;
    r.figure(
        "for 5 periods and stand for one more (",
        " s, 0.",
        s["duration"].as_f64().unwrap(),
        "default gait: duration",
    );
    r.figure(
        " s, ",
        " m with the start-up and stop)",
        s["distance"].as_f64().unwrap(),
        "default gait: distance",
    );
    let rows = walk.rows();
    let r0 = &rows[0];
    let (dx, dz) = (
        at(r0, "foot1_x") - at(r0, "rx"),
        at(r0, "foot1_z") - at(r0, "rz"),
    );
    r.figure(
        "the body ",
        " m above its feet",
        at(r0, "ry") - at(r0, "foot1_y"),
        "default stance: height",
    );
    r.figure(
        "the feet ",
        " m from the body centre",
        dx.hypot(dz),
        "default stance: reach",
    );
    let reference = doc("docs/reference.md");
    reference.figure(
        "— ",
        " m above flat ground with",
        at(r0, "ry") - at(r0, "foot1_y"),
        "default stance: height",
    );
    reference.figure(
        "`d + a + c·cos 65°` (",
        " m) from the body",
        dx.hypot(dz),
        "default stance: reach",
    );
}

/// The CSV and Parquet sizes of the walk (README, "Output files", and the
/// table of docs/reference.md).
#[test]
fn walk_file_sizes() {
    let text = example("examples/hexapod_walk.toml");
    assert!(!text.contains("[output]"), "the walk sets no [output]");
    let walk = run_in(Some(&root().join("examples/hexapod_walk.toml")));
    let csv = walk.size("trajectory.csv") as f64;
    // docs/reference.md's attitude columns: the walk starts pitched up its
    // 3.5° slope, heading −π/2.
    let first = &walk.rows()[0];
    let reference = doc("docs/reference.md");
    reference.figure(
        "`examples/hexapod_walk.toml` starts at pitch = ",
        " rad",
        at(first, "pitch"),
        "the walk's initial pitch",
    );
    assert!((at(first, "heading") + std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    assert!(at(first, "roll").abs() < 1e-12);
    let parquet = run_text(&format!("{text}\n[output]\nformat = \"parquet\"\n"))
        .size("trajectory.parquet") as f64;
    let r = doc("README.md");
    r.figure(
        "`examples/hexapod_walk.toml` (",
        " MB against ",
        parquet / 1e6,
        "parquet size",
    );
    r.figure(" MB against ", " MB) and read", csv / 1e6, "csv size");
    r.figure(
        "`trajectory.parquet`, ",
        " times smaller",
        csv / parquet,
        "ratio",
    );
    reference.figure(
        "| `csv` | `trajectory.csv` | ",
        " MB |",
        csv / 1e6,
        "csv size",
    );
    reference.figure(
        "| `parquet` | `trajectory.parquet` | ",
        " MB |",
        parquet / 1e6,
        "parquet size",
    );
}

/// fbd's side of bench/peer's hexapod cases (the README's paragraph after
/// the scaling table).
#[test]
fn peer_hexapod_figures() {
    let r = doc("README.md");
    let stand = run_in(Some(&root().join("bench/peer/hexapod_stand.toml")));
    let rows = stand.rows();
    let last = rows.last().unwrap();
    let n: Vec<f64> = (1..=6).map(|k| at(last, &format!("foot{k}_n"))).collect();
    let mean = n.iter().sum::<f64>() / 6.0;
    for f in &n {
        assert!((f - mean).abs() < 5e-4, "the feet carry {n:?}: not alike");
    }
    r.figure(
        "The standing hexapod's feet carry ",
        " N each in both",
        mean,
        "peer: stand, each foot",
    );
    r.figure(
        "in both (Σ ",
        " N, the weight)",
        n.iter().sum(),
        "peer: stand, sum",
    );
    let walk = run_in(Some(&root().join("bench/peer/hexapod_walk.toml")));
    let rows = walk.rows();
    let (a, b) = (&rows[0], rows.last().unwrap());
    let moved = (at(b, "rx") - at(a, "rx")).hypot(at(b, "rz") - at(a, "rz"));
    r.figure(
        "over 5 s of walking the body moves ",
        " m in fbd",
        moved,
        "peer: walk distance",
    );
}

/// The landings the README names by their run number (the 1000-run sweeps
/// themselves: [`landing_sweeps_of_1000_runs`]): their events.
#[test]
fn landing_runs_named_in_the_readme() {
    let r = doc("README.md");
    let events = |sweep: &str, run: usize| {
        let plan = fbd_cli::sweep::plan(&root().join(sweep)).unwrap();
        let config = plan.configs[run].to_toml();
        run_text(&config).summary["events"]
            .as_array()
            .unwrap()
            .len()
    };
    let quoted_run =
        |before: &str, after: &str| common::readme::parse(&r.quoted(before, after)) as usize;
    let worst10 = quoted_run(" at 10 ms (run ", ")");
    r.count(
        "the most events a run writes is ",
        " at 10 ms (run",
        events("examples/sweep_landing_1000.toml", worst10),
        "the most events at 10 ms",
    );
    let worst1 = quoted_run(" at 1 ms (run ", ")");
    r.count(
        ") and ",
        " at 1 ms (run",
        events("examples/sweep_landing_1000_1ms.toml", worst1),
        "the most events at 1 ms",
    );
    // The earlier 100-run sweep: every landing completes.
    let stress = fbd_cli::sweep::plan(&root().join("examples/sweep_landing_stress.toml")).unwrap();
    let completed = stress
        .configs
        .iter()
        .filter(|c| {
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("config.toml");
            std::fs::write(&path, c.to_toml()).unwrap();
            let mut out = Vec::new();
            fbd_cli::run::run_command(Some(&path), &dir.path().join("out"), &mut out).is_ok()
        })
        .count();
    r.count(
        "(`examples/sweep_landing_stress.toml`) completes ",
        " of ",
        completed,
        "the 100 landings: completed",
    );
    r.count(
        " of ",
        " (it was",
        stress.configs.len(),
        "the 100 landings: runs",
    );
    r.count(
        "(run 872: 387 events, now ",
        ")",
        events("examples/sweep_landing_1000_1ms.toml", 872),
        "run 872",
    );
}

#[test]
fn the_readme_is_where_this_test_looks() {
    assert!(Path::new(&root().join("README.md")).exists());
}

/// docs/sweep.md's friction sweep of the standing hexapod
/// (`examples/sweep_hexapod_friction.toml`, run as `fbd sweep` runs it):
/// the feet's |Ft|/N standing and at the touchdown's impact, and which μS
/// slide (`foot_slips` of index.csv).
#[test]
fn hexapod_friction_sweep() {
    let d = doc("docs/sweep.md");
    let out = tempfile::tempdir().unwrap();
    let args = fbd_cli::sweep::SweepArgs {
        command: None,
        sweep: Some(root().join("examples/sweep_hexapod_friction.toml")),
        out: out.path().to_path_buf(),
        jobs: Some(2),
        shard: None,
        resume: false,
        plot: "foot_slips".into(),
        viewer: false,
        plots: false,
    };
    fbd_cli::sweep::sweep_command(args, &mut Vec::new()).unwrap();
    let mut index = csv::Reader::from_path(out.path().join("index.csv")).unwrap();
    let names: Vec<String> = index.headers().unwrap().iter().map(str::to_owned).collect();
    let col = |rec: &csv::StringRecord, c: &str| -> f64 {
        rec[names.iter().position(|n| n == c).unwrap()]
            .parse()
            .unwrap()
    };
    let (mut standing, mut impact) = (Vec::new(), 0.0f64);
    let mut mus = Vec::new();
    for rec in index.records() {
        let rec = rec.unwrap();
        let (run, mu, slips) = (
            col(&rec, "run"),
            col(&rec, "terrain.mu_static"),
            col(&rec, "foot_slips"),
        );
        mus.push(mu);
        // "with μS 0.05 and 0.1 the feet slide at touchdown (foot_slips >
        // 0), with 0.2 and 0.8 they stick (0)": every foot slides.
        if mu < 0.15 {
            assert!(slips >= 6.0, "run {run}: μS {mu}, {slips} slips");
            continue;
        }
        assert_eq!(slips, 0.0, "run {run}: μS {mu}");
        // The feet that stick: |Ft|/N of every foot on every row (the
        // impact's largest) and on the last row (standing).
        let mut r =
            csv::Reader::from_path(out.path().join(format!("runs/{run}/trajectory.csv"))).unwrap();
        let h: Vec<String> = r.headers().unwrap().iter().map(str::to_owned).collect();
        let at = |rec: &csv::StringRecord, c: &str| -> String {
            rec[h.iter().position(|n| n == c).unwrap()].to_owned()
        };
        let rows: Vec<csv::StringRecord> = r.records().map(Result::unwrap).collect();
        let ratio = |rec: &csv::StringRecord, n: usize| -> Option<f64> {
            let f = |a: &str| at(rec, &format!("foot{n}_{a}")).parse::<f64>().unwrap();
            (at(rec, &format!("state{n}")) == "ST2" && f("n") > 1e-6)
                .then(|| f("fx").hypot(f("fz")) / f("n"))
        };
        for rec in &rows {
            for n in 1..=6 {
                impact = impact.max(ratio(rec, n).unwrap_or(0.0));
            }
        }
        let last = rows.last().unwrap();
        for n in 1..=6 {
            standing.push(ratio(last, n).expect("every foot stands at the end"));
        }
    }
    assert_eq!(mus, [0.05, 0.05, 0.1, 0.1, 0.2, 0.2, 0.8, 0.8]);
    // Every standing foot of every run rounds to the quoted figure.
    for s in &standing {
        d.figure("sideways with |Ft|/N ≈ ", ", and", *s, "standing feet");
    }
    d.figure(
        "with up to |Ft|/N ≈ ",
        " in the touchdown's impact",
        impact,
        "the impact's largest |Ft|/N of a sticking foot",
    );
    // The impact's ratio lies between the μS that slide and those that
    // stick.
    assert!(0.1 < impact && impact < 0.2, "{impact}");
    // The README's table of examples says it too.
    let r = doc("README.md");
    r.figure(
        "the feet slide at touchdown below μS ≈ ",
        " (the impact's |Ft|/N; ",
        impact,
        "the impact's |Ft|/N",
    );
    for s in &standing {
        r.figure(
            "(the impact's |Ft|/N; ",
            " standing), stick above",
            *s,
            "standing feet",
        );
    }
}

/// What the runs of a sweep's `summary.json` say, as
/// `scripts/landing-figures.py` prints it.
struct Landings {
    /// Each run's summary.json.
    summaries: Vec<serde_json::Value>,
    runs: usize,
    completed: usize,
    retried_runs: usize,
    retried_steps: u64,
    cycle_runs: usize,
    cycle_steps: u64,
    moving: usize,
    most_events: usize,
    most_events_run: usize,
    median_events: f64,
    /// The bytes `fbd sweep` says it wrote.
    bytes: u64,
}

/// Runs the 1000-run landing sweep `name` as `fbd sweep` runs it (some
/// 70 MB in a temporary folder) and tabulates it.
fn landings(name: &str) -> Landings {
    let dir = tempfile::tempdir().unwrap();
    let text = example(&format!("examples/{name}"));
    // The base configuration by its absolute path (the sweep file is copied).
    let line = text
        .lines()
        .find(|l| l.starts_with("base = \""))
        .expect("a base line");
    let base = root()
        .join("examples")
        .join(line.trim_start_matches("base = ").trim_matches('"'));
    let text = text.replace(line, &format!("base = {:?}", base.display().to_string()));
    let sweep = dir.path().join(name);
    std::fs::write(&sweep, text).unwrap();
    let out = dir.path().join("out");
    let args = fbd_cli::sweep::SweepArgs {
        command: None,
        sweep: Some(sweep),
        out: out.clone(),
        jobs: None,
        shard: None,
        resume: false,
        plot: "touchdown".into(),
        viewer: false,
        plots: false,
    };
    let mut said = Vec::new();
    fbd_cli::sweep::sweep_command(args, &mut said).unwrap();
    let bytes = fbd_cli::sweep::dir_bytes(&out);
    let said = String::from_utf8(said).unwrap();
    assert!(
        said.contains(&format!("({};", fbd_cli::sweep::human_bytes(bytes))),
        "{said}"
    );
    let total = fbd_cli::sweep::plan(&root().join("examples").join(name))
        .unwrap()
        .configs
        .len();
    let s: Vec<serde_json::Value> = (0..total)
        .map(|i| {
            let p = out.join(format!("runs/{i}/summary.json"));
            serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
        })
        .collect();
    let n = |j: &serde_json::Value, k: &str| j[k].as_u64().unwrap();
    let mut events: Vec<usize> = s
        .iter()
        .map(|j| j["events"].as_array().unwrap().len())
        .collect();
    let most_events = *events.iter().max().unwrap();
    let most_events_run = events.iter().position(|e| *e == most_events).unwrap();
    events.sort_unstable();
    let m = events.len();
    let median_events = if m % 2 == 1 {
        events[m / 2] as f64
    } else {
        (events[m / 2 - 1] + events[m / 2]) as f64 / 2.0
    };
    Landings {
        summaries: s.clone(),
        runs: s.len(),
        completed: s.iter().filter(|j| j["status"] == "ok").count(),
        retried_runs: s.iter().filter(|j| n(j, "retried_steps") > 0).count(),
        retried_steps: s.iter().map(|j| n(j, "retried_steps")).sum(),
        cycle_runs: s.iter().filter(|j| n(j, "resolved_cycles") > 0).count(),
        cycle_steps: s.iter().map(|j| n(j, "resolved_cycles")).sum(),
        moving: s
            .iter()
            .filter(|j| j["final_energy"]["kinetic"].as_f64().unwrap() > 1e-6)
            .count(),
        most_events,
        most_events_run,
        median_events,
        bytes,
    }
}

/// The README's paragraph on the two 1000-run landing sweeps ("How robust
/// this is"): both sweeps run here (some 20 s of both cores).
#[test]
fn landing_sweeps_of_1000_runs() {
    let r = doc("README.md");
    let (a, b) = (
        landings("sweep_landing_1000.toml"),
        landings("sweep_landing_1000_1ms.toml"),
    );
    assert_eq!((a.runs, b.runs), (1000, 1000));
    r.has(
        "How robust this is: **1000 of 1000** random passive landings complete at Δt = 10 ms",
        "the runs of the 10 ms sweep",
    );
    r.count(
        "How robust this is: **",
        " of 1000** random",
        a.completed,
        "completed at 10 ms",
    );
    r.count(
        "(`examples/sweep_landing_1000.toml`) and **",
        " of 1000** at Δt = 1 ms",
        b.completed,
        "completed at 1 ms",
    );
    r.count(
        "At Δt = 10 ms, ",
        " runs needed substeps",
        a.retried_runs,
        "10 ms: runs in substeps",
    );
    r.count(
        "runs needed substeps for at least one step (",
        " steps in all)",
        a.retried_steps as usize,
        "10 ms: steps in substeps",
    );
    r.count(
        " steps in all) and ",
        " runs closed a cycling",
        a.cycle_runs,
        "10 ms: cycle runs",
    );
    r.count(
        "least inconsistent combination (",
        " steps); at Δt = 1 ms",
        a.cycle_steps as usize,
        "10 ms: cycle steps",
    );
    r.count(
        "at Δt = 1 ms, ",
        " runs used substeps",
        b.retried_runs,
        "1 ms: runs in substeps",
    );
    r.count(
        " runs used substeps (",
        " steps) and",
        b.retried_steps as usize,
        "1 ms: steps in substeps",
    );
    r.count(
        " steps) and ",
        " runs closed cycling searches",
        b.cycle_runs,
        "1 ms: cycle runs",
    );
    r.count(
        "runs closed cycling searches that way (",
        " steps)",
        b.cycle_steps as usize,
        "1 ms: cycle steps",
    );
    r.count(
        "What is not guaranteed: ",
        " of the 1000",
        a.moving,
        "10 ms: still moving",
    );
    r.count(
        " landings at 10 ms and ",
        " at 1 ms still move",
        b.moving,
        "1 ms: still moving",
    );
    r.count(
        "the most events a run writes is ",
        " at 10 ms (run",
        a.most_events,
        "10 ms: most events",
    );
    r.count(
        " at 10 ms (run ",
        ")",
        a.most_events_run,
        "10 ms: the run with the most events",
    );
    r.count(
        ") and ",
        " at 1 ms (run",
        b.most_events,
        "1 ms: most events",
    );
    r.count(
        " at 1 ms (run ",
        ") (median",
        b.most_events_run,
        "1 ms: the run with the most events",
    );
    r.figure("(median ", " and ", a.median_events, "10 ms: median events");
    r.figure(
        " and ",
        "). Before the search",
        b.median_events,
        "1 ms: median events",
    );
    // What the two sweeps write (`fbd sweep` prints it).
    let (mb10, mb1) = (a.bytes as f64 / 1e6, b.bytes as f64 / 1e6);
    r.figure(
        "`examples/sweep_landing_1000.toml` writes ",
        " MB, ",
        mb10,
        "10 ms sweep size",
    );
    r.figure(
        "`examples/sweep_landing_1000_1ms.toml` ",
        " MB with its `[set]",
        mb1,
        "1 ms sweep size",
    );
    let s = doc("docs/sweep.md");
    s.figure(
        "`examples/sweep_landing_1000.toml` writes ",
        " MB by default",
        mb10,
        "10 ms sweep size",
    );
    s.figure(
        "`examples/sweep_landing_1000_1ms.toml` ",
        " MB (its `[set]",
        mb1,
        "1 ms sweep size",
    );
}

/// The README's paragraph on all 1000 runs of
/// `examples/sweep_hexapod_landing_1000.toml` (3D landings on feet, knees
/// and hips): the sweep runs here as the example file writes it (every
/// 50th row, some 85 MB; about two minutes of both cores), and every
/// figure of the paragraph but the timings and the stride-1 CSV check
/// (`scripts/sweep-laws.py`, which exits 1 on a row that breaks a law) is
/// recomputed from the runs' summary.json.
#[test]
fn hexapod_landing_sweep_of_1000_runs() {
    let r = doc("README.md");
    let l = landings("sweep_hexapod_landing_1000.toml");
    let s = &l.summaries;
    assert_eq!(l.runs, 1000);
    let what = "3D landings";
    r.count("**", " of 1000 3D landings complete**", l.completed, what);
    let steps: u64 = s.iter().map(|j| j["steps"].as_u64().unwrap()).sum();
    r.count(
        "every one of their **",
        " steps** passes",
        steps as usize,
        "3D landings: steps",
    );
    let worst = s
        .iter()
        .map(|j| j["max_law_violation"].as_f64().unwrap())
        .fold(0.0, f64::max);
    r.approx(
        "run's own law audit (worst ",
        " N; the tolerance",
        worst,
        "3D landings: worst audited step",
    );
    let weight = 180.504;
    assert!(worst <= 1e-6 * weight, "{worst} N");
    let mut per_step: Vec<f64> = s
        .iter()
        .map(|j| j["newton_iterations"].as_f64().unwrap() / j["steps"].as_f64().unwrap())
        .collect();
    per_step.sort_by(f64::total_cmp);
    r.figure(
        "The median run takes ",
        "\nNewton iterations a step",
        (per_step[499] + per_step[500]) / 2.0,
        "3D landings: iterations a step",
    );
    let total: u64 = s
        .iter()
        .map(|j| j["newton_iterations"].as_u64().unwrap())
        .sum();
    r.count(
        "retried in substeps included: ",
        " in the sweep",
        total as usize,
        "3D landings: Newton iterations in all",
    );
    r.figure(
        "Newton iterations a step and writes ",
        " events",
        l.median_events,
        "3D landings: median events",
    );
    r.count(
        "stops; ",
        " the most, run",
        l.most_events,
        "3D landings: most events",
    );
    r.count(
        " the most, run ",
        "); ",
        l.most_events_run,
        "3D landings: the run with most events",
    );
    r.count(
        "); ",
        " steps were retried",
        l.retried_steps as usize,
        "3D landings: retried steps",
    );
    r.count(
        "retried in substeps, in\n",
        " runs (",
        l.retried_runs,
        "3D landings: retried runs",
    );
    // No step needs the reference LU (the last retry); one closes only
    // below Δt/64.
    let reference: Vec<usize> = s
        .iter()
        .enumerate()
        .filter(|(_, j)| j["reference_lu_retries"].as_u64().unwrap() > 0)
        .map(|(i, _)| i)
        .collect();
    assert!(
        reference.is_empty(),
        "runs with reference-LU retries: {reference:?}"
    );
    let deep: Vec<(usize, u64)> = s
        .iter()
        .enumerate()
        .flat_map(|(i, j)| {
            j["events"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|e| e["point"] == "substeps")
                .map(move |e| (i, e["to"].as_str().unwrap().parse::<u64>().unwrap()))
        })
        .filter(|&(_, n)| n > 64)
        .collect();
    let runs: Vec<String> = deep.iter().map(|d| d.0.to_string()).collect();
    match runs.split_last() {
        None => r.has(
            "(none of them below Δt/64:",
            "3D landings: no run closed below Δt/64",
        ),
        Some((last, first)) => {
            let finest = deep.iter().map(|d| d.1).max().unwrap();
            let list = if first.is_empty() {
                format!("run {last}")
            } else {
                format!("runs {} and {last}", first.join(", "))
            };
            r.has(
                &format!("({} of them, {list}, only at Δt/{finest}:", deep.len()),
                "3D landings: the runs closed below Δt/64",
            );
        }
    }
    r.count(
        "cannot-be-closed));\n",
        " steps, in ",
        l.cycle_steps as usize,
        "3D landings: cycle steps",
    );
    r.count(
        " steps, in ",
        " runs, closed a cycling",
        l.cycle_runs,
        "3D landings: cycle runs",
    );
    r.count(
        "tolerance); ",
        " runs still move\nat 1.5 s",
        l.moving,
        "3D landings: still moving",
    );
}
