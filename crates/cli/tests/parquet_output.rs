//! `[output] format = "parquet"`: `trajectory.parquet` holds the columns of
//! `trajectory.csv`, with the same names, in the same order, with the same
//! values (numbers bit for bit, states as strings, `newton_iterations` as
//! integers), for the planar model, the kinematic gait, the 3D dynamics and
//! an imported robot;
//! and the run writes no `trajectory.csv` beside it.

use std::fs::File;
use std::path::Path;

use fbd_cli::config::{Override, load_with_overrides, parse_str};
use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::record::Field;

/// A cell of either file, compared by value.
#[derive(Debug, PartialEq)]
enum Cell {
    Num(u64),
    Str(String),
}

fn run(config_text: &str, dir: &Path, format: &str) {
    let mut config = parse_str(
        config_text,
        "test.toml",
        &[Override::new("output.format", format)],
    )
    .unwrap();
    if let fbd_cli::Config::Hexapod(h) = &mut config {
        // Short runs: the files, not the walk, are under test.
        h.time.duration = h.time.duration.min(0.3);
    }
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join("in.toml");
    std::fs::write(&path, config.to_toml()).unwrap();
    fbd_cli::run::run_command(Some(&path), dir, &mut std::io::sink()).unwrap();
}

fn csv_cells(path: &Path) -> (Vec<String>, Vec<Vec<Cell>>) {
    let mut r = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(str::to_owned).collect();
    let rows = r
        .records()
        .map(|rec| {
            rec.unwrap()
                .iter()
                .map(|c| match c.parse::<f64>() {
                    Ok(x) => Cell::Num(x.to_bits()),
                    Err(_) => Cell::Str(c.to_owned()),
                })
                .collect()
        })
        .collect();
    (header, rows)
}

fn parquet_cells(path: &Path) -> (Vec<String>, Vec<Vec<Cell>>) {
    let reader = SerializedFileReader::new(File::open(path).unwrap()).unwrap();
    let schema = reader.metadata().file_metadata().schema_descr();
    let header = schema
        .columns()
        .iter()
        .map(|c| c.name().to_owned())
        .collect();
    let rows = reader
        .get_row_iter(None)
        .unwrap()
        .map(|row| {
            row.unwrap()
                .get_column_iter()
                .map(|(_, f)| match f {
                    Field::Double(x) => Cell::Num(x.to_bits()),
                    // Counts are integers in Parquet; the CSV reads them as
                    // numbers.
                    Field::Long(n) => Cell::Num((*n as f64).to_bits()),
                    Field::Str(s) => Cell::Str(s.clone()),
                    other => panic!("unexpected field {other:?}"),
                })
                .collect()
        })
        .collect();
    (header, rows)
}

fn same_table(config_text: &str, what: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let (c, p) = (tmp.path().join("csv"), tmp.path().join("parquet"));
    run(config_text, &c, "csv");
    run(config_text, &p, "parquet");
    assert!(
        !p.join("trajectory.csv").exists(),
        "{what}: a CSV beside the Parquet"
    );
    assert!(!c.join("trajectory.parquet").exists(), "{what}");
    let (ch, crows) = csv_cells(&c.join("trajectory.csv"));
    let (ph, prows) = parquet_cells(&p.join("trajectory.parquet"));
    assert_eq!(ch, ph, "{what}: columns");
    assert_eq!(crows.len(), prows.len(), "{what}: rows");
    assert!(!crows.is_empty(), "{what}: no rows");
    for (k, (a, b)) in crows.iter().zip(&prows).enumerate() {
        for (j, (x, y)) in a.iter().zip(b).enumerate() {
            // NaN cells: both NaN (the bits of a parsed "NaN" and a written
            // NaN may differ in the payload).
            let nan = |c: &Cell| matches!(c, Cell::Num(b) if f64::from_bits(*b).is_nan());
            assert!(
                x == y || (nan(x) && nan(y)),
                "{what}: row {k}, column {}: CSV {x:?}, Parquet {y:?}",
                ch[j]
            );
        }
    }
    // The summary counts the rows of either file.
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(p.join("summary.json")).unwrap()).unwrap();
    assert_eq!(
        s["rows_written"].as_u64(),
        Some(prows.len() as u64),
        "{what}"
    );
}

#[test]
fn planar_parquet_equals_the_csv() {
    // The default experiment with knees and hips: state columns of every
    // kind, joint-limit stops, NaN-free.
    same_table("", "planar");
}

#[test]
fn dynamic_hexapod_parquet_equals_the_csv() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/hexapod_walk.toml"),
    )
    .unwrap();
    same_table(&text, "hexapod walk");
}

#[test]
fn kinematic_gait_parquet_equals_the_csv() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/hexapod_tripod.toml");
    // Load once to check the example parses, then run its text.
    load_with_overrides(&path, &[]).unwrap();
    same_table(&std::fs::read_to_string(&path).unwrap(), "tripod gait");
}

#[test]
fn robot_parquet_equals_the_csv() {
    // An imported robot landing (contact states of every kind), through
    // the writer of every model on the tree equations; the description by
    // its absolute path, so that the text runs from elsewhere.
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/robots");
    let text = std::fs::read_to_string(examples.join("lab_hexapod_drop.toml"))
        .unwrap()
        .replace(
            "urdf = \"lab_hexapod.urdf\"",
            &format!(
                "urdf = \"{}\"",
                examples
                    .join("lab_hexapod.urdf")
                    .canonicalize()
                    .unwrap()
                    .display()
            ),
        )
        .replace("duration = 0.6", "duration = 0.3");
    let tmp = tempfile::tempdir().unwrap();
    let (c, p) = (tmp.path().join("csv"), tmp.path().join("parquet"));
    for (dir, format) in [(&c, "csv"), (&p, "parquet")] {
        std::fs::create_dir_all(dir).unwrap();
        let path = dir.join("in.toml");
        std::fs::write(
            &path,
            format!("{text}\n[output]\nformat = \"{format}\"\nviewer = false\n"),
        )
        .unwrap();
        fbd_cli::run::run_command(Some(&path), dir, &mut std::io::sink()).unwrap();
    }
    assert!(
        !p.join("trajectory.csv").exists(),
        "a CSV beside the Parquet"
    );
    let (ch, crows) = csv_cells(&c.join("trajectory.csv"));
    let (ph, prows) = parquet_cells(&p.join("trajectory.parquet"));
    assert_eq!(ch, ph, "columns");
    assert_eq!(crows, prows, "rows");
    assert!(ch.iter().any(|h| h == "lf_foot_sphere_state"), "{ch:?}");
    assert!(
        crows
            .iter()
            .any(|r| r.contains(&Cell::Str("ST2".to_owned()))),
        "a point sticks"
    );
    // The plots of every model on the tree equations, in the robot's names.
    for f in ["feet.svg", "torques.svg", "body.svg", "energy.svg"] {
        let svg = std::fs::read_to_string(p.join(f)).unwrap();
        assert!(
            svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
            "{f}"
        );
    }
    let torques = std::fs::read_to_string(p.join("torques.svg")).unwrap();
    for d in 1..=3 {
        assert!(torques.contains(&format!("Depth {d} from the root")), "{d}");
    }
    assert!(!torques.contains("Depth 4 from the root"));
    assert!(torques.contains("lf_tibia_joint"));
    let feet = std::fs::read_to_string(p.join("feet.svg")).unwrap();
    assert!(feet.contains("rr_foot_sphere") && feet.contains("ground under"));
    assert!(!p.join("viewer.html").exists());
}
