//! `fbd view DIR`: (re)writes `DIR/viewer.html` of an existing output
//! folder from `DIR/config.toml`, `DIR/trajectory.csv` and, for the planar
//! model, `DIR/events.csv`. The page is the one `fbd run` writes.

use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use fbd_contact::StateCode;
use fbd_dynamics::PointKind;
use fbd_kinematics::body::LEG_COUNT;
use fbd_sim::{Event, Joint, LimitEvent, Model, RobotRecord};

use super::hexapod::{HexapodView, LegValues};
use super::planar::PlanarScene;
use crate::OutputError;
use crate::config::{self, Config};

/// The columns of a `trajectory.csv`, by name.
struct Table {
    file: PathBuf,
    columns: HashMap<String, usize>,
    rows: Vec<csv::StringRecord>,
}

impl Table {
    fn read(file: &Path) -> Result<Self, OutputError> {
        let mut reader = csv::Reader::from_path(file)
            .map_err(|e| OutputError::Io(format!("{}: {e}", file.display())))?;
        let columns = reader
            .headers()
            .map_err(|e| OutputError::Io(format!("{}: {e}", file.display())))?
            .iter()
            .enumerate()
            .map(|(i, h)| (h.to_owned(), i))
            .collect();
        let rows = reader
            .records()
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| OutputError::Io(format!("{}: {e}", file.display())))?;
        Ok(Self {
            file: file.to_owned(),
            columns,
            rows,
        })
    }

    fn column(&self, name: &str) -> Result<usize, OutputError> {
        self.columns.get(name).copied().ok_or_else(|| {
            OutputError::Io(format!(
                "{}: no column `{name}` (was it written by `fbd run` of this configuration?)",
                self.file.display()
            ))
        })
    }

    fn number(&self, row: &csv::StringRecord, r: usize, c: usize) -> Result<f64, OutputError> {
        let s = cell(row, c).trim();
        s.parse::<f64>().map_err(|_| {
            OutputError::Io(format!(
                "{}: line {}: `{s}` is not a number",
                self.file.display(),
                r + 2
            ))
        })
    }
}

/// Field `c` of `row` (empty when missing).
fn cell(row: &csv::StringRecord, c: usize) -> &str {
    row.get(c).unwrap_or("")
}

fn state(s: &str) -> Option<StateCode> {
    match s.trim() {
        "ST1" => Some(StateCode::St1),
        "ST2" => Some(StateCode::St2),
        "ST3" => Some(StateCode::St3),
        _ => None,
    }
}

/// The step records of a planar run's `trajectory.csv`.
fn planar_records(model: &Model, table: &Table) -> Result<Vec<RobotRecord>, OutputError> {
    let q_cols = [
        "rx", "ry", "phi_z", "theta2_3", "theta3_3", "theta2_4", "theta3_4",
    ]
    .map(|c| table.column(c));
    let q_cols: Vec<usize> = q_cols.into_iter().collect::<Result<_, _>>()?;
    let t_col = table.column("t")?;
    let contacts: Vec<[usize; 3]> = model
        .mech
        .contacts
        .iter()
        .map(|c| {
            let [s, fa, n] = crate::output::contact_columns(c.leg, c.kind);
            Ok([table.column(&s)?, table.column(&fa)?, table.column(&n)?])
        })
        .collect::<Result<_, OutputError>>()?;
    let joints: Vec<[usize; 3]> = model
        .mech
        .joints
        .iter()
        .map(|j| {
            Ok([
                table.column(&format!("{}_fx", j.name))?,
                table.column(&format!("{}_fy", j.name))?,
                table.column(&format!("tau_{}", j.name))?,
            ])
        })
        .collect::<Result<_, OutputError>>()?;
    let (kin, pot) = (table.column("kinetic")?, table.column("potential")?);
    let mut out = Vec::with_capacity(table.rows.len());
    for (r, row) in table.rows.iter().enumerate() {
        let t = table.number(row, r, t_col)?;
        let mut rec = RobotRecord::planar(contacts.len(), joints.len());
        (rec.step, rec.t) = (r, t);
        for (k, &c) in q_cols.iter().enumerate() {
            rec.q[fbd_sim::robot::plane_q_index(k)] = table.number(row, r, c)?;
        }
        for (c, cols) in contacts.iter().enumerate() {
            let s = cell(row, cols[0]);
            let point = &mut rec.contacts[c];
            point.state = state(s).ok_or_else(|| {
                OutputError::Io(format!(
                    "{}: line {}: `{s}` is not a contact state (ST1, ST2 or ST3)",
                    table.file.display(),
                    r + 2
                ))
            })?;
            point.tangential[0] = table.number(row, r, cols[1])?;
            point.normal = table.number(row, r, cols[2])?;
        }
        for (j, cols) in joints.iter().enumerate() {
            rec.reaction_force[j] = [
                table.number(row, r, cols[0])?,
                table.number(row, r, cols[1])?,
                0.0,
            ];
            rec.torque[j] = table.number(row, r, cols[2])?;
        }
        rec.kinetic = table.number(row, r, kin)?;
        rec.potential = table.number(row, r, pot)?;
        out.push(rec);
    }
    Ok(out)
}

/// The events of `events.csv` (empty when the file is missing).
fn planar_events(model: &Model, file: &Path) -> Result<Vec<Event>, OutputError> {
    if !file.exists() {
        return Ok(Vec::new());
    }
    let table = Table::read(file)?;
    let cols = ["t", "leg", "from", "to", "point"].map(|c| table.column(c));
    let [t, leg, from, to, point] = cols;
    let (t, leg, from, to, point) = (t?, leg?, from?, to?, point?);
    let mut out = Vec::with_capacity(table.rows.len());
    for (r, row) in table.rows.iter().enumerate() {
        let bad = |what: &str| {
            OutputError::Io(format!(
                "{}: line {}: bad `{what}`",
                table.file.display(),
                r + 2
            ))
        };
        let point = cell(row, point).trim();
        let Some(kind) = PointKind::ALL.into_iter().find(|k| k.as_str() == point) else {
            // Joint-limit and retried-step rows are not contact events.
            if point == crate::output::RETRY_POINT
                || Joint::ALL
                    .into_iter()
                    .any(|j| LimitEvent::point_of(j) == point)
            {
                continue;
            }
            return Err(bad("point"));
        };
        let n: usize = cell(row, leg).trim().parse().map_err(|_| bad("leg"))?;
        // The model's contact point of that `{leg, kind}`.
        let contact = model
            .mech
            .contacts
            .iter()
            .position(|c| c.leg == n && c.kind == kind)
            .ok_or_else(|| bad("point"))?;
        out.push(Event {
            t: table.number(row, r, t)?,
            step: 0,
            contact,
            point: model.mech.contacts[contact].kind,
            leg: model.mech.contacts[contact].leg,
            from: state(cell(row, from)).ok_or_else(|| bad("from"))?,
            to: state(cell(row, to)).ok_or_else(|| bad("to"))?,
        });
    }
    Ok(out)
}

/// Pushes the rows of a hexapod gait run's `trajectory.csv` (`table`) to
/// `view`:
/// `t, rx, ry, rz, phi_x, phi_y, phi_z, theta{j}_{n}, stance{n}` and, when
/// present, `com_x/y/z` and `margin`.
fn hexapod_rows(table: &Table, view: &mut HexapodView) -> Result<(), OutputError> {
    let t_col = table.column("t")?;
    let mut q_cols = Vec::with_capacity(6 + 3 * LEG_COUNT);
    for c in ["rx", "ry", "rz", "phi_x", "phi_y", "phi_z"] {
        q_cols.push(table.column(c)?);
    }
    for n in 1..=LEG_COUNT {
        for j in 1..=3 {
            q_cols.push(table.column(&format!("theta{j}_{n}"))?);
        }
    }
    let stance_cols: Vec<usize> = (1..=LEG_COUNT)
        .map(|n| table.column(&format!("stance{n}")))
        .collect::<Result<_, _>>()?;
    let com_cols: Option<Vec<usize>> = ["com_x", "com_y", "com_z"]
        .iter()
        .map(|c| table.columns.get(*c).copied())
        .collect();
    let margin_col = table.columns.get("margin").copied();
    let mut q = vec![0.0; q_cols.len()];
    for (r, row) in table.rows.iter().enumerate() {
        for (v, &c) in q.iter_mut().zip(&q_cols) {
            *v = table.number(row, r, c)?;
        }
        let mut stance = [false; LEG_COUNT];
        for (leg, &c) in stance_cols.iter().enumerate() {
            let s = cell(row, c).trim();
            stance[leg] = match s {
                "1" | "true" | "ST2" | "ST3" => true,
                "0" | "false" | "ST1" => false,
                _ => {
                    return Err(OutputError::Io(format!(
                        "{}: line {}: stance{} = `{s}`: expected 0 or 1",
                        table.file.display(),
                        r + 2,
                        leg + 1
                    )));
                }
            };
        }
        let mut com = [q[0], q[1], q[2]];
        if let Some(c) = &com_cols {
            for (v, &col) in com.iter_mut().zip(c) {
                *v = table.number(row, r, col)?;
            }
        }
        let margin = match margin_col {
            Some(c) => Some(table.number(row, r, c)?).filter(|m| m.is_finite()),
            None => None,
        };
        view.push_gait(table.number(row, r, t_col)?, &q, &stance, com, margin);
    }
    Ok(())
}

/// Pushes the rows of a dynamic (3D FBD) hexapod run's `trajectory.csv`
/// for the model of `params` to `view`: pose, joint angles, each contact
/// point's state and ground force, each leg's foot normal force, hip and
/// knee forces and torques.
fn spatial_rows(
    table: &Table,
    params: &fbd_sim::spatial::SpatialParams,
    view: &mut HexapodView,
) -> Result<(), OutputError> {
    let legs = view.legs().to_vec();
    let t_col = table.column("t")?;
    let mut q_cols = Vec::with_capacity(6 + 3 * legs.len());
    for c in crate::spatial::csv::POSE_COLUMNS {
        q_cols.push(table.column(c)?);
    }
    for n in &legs {
        for j in 1..=3 {
            q_cols.push(table.column(&format!("theta{j}_{n}"))?);
        }
    }
    let triple = |name: &str| -> Result<[usize; 3], OutputError> {
        Ok([
            table.column(&format!("{name}_fx"))?,
            table.column(&format!("{name}_fy"))?,
            table.column(&format!("{name}_fz"))?,
        ])
    };
    // Per leg: the foot's normal force, the hip and knee forces, the
    // torques.
    type LegColumns = (Option<usize>, [usize; 3], [usize; 3], [usize; 3]);
    let leg_cols: Vec<LegColumns> = legs
        .iter()
        .map(|n| {
            Ok((
                params
                    .contact_points
                    .tips
                    .then(|| table.column(&format!("foot{n}_n")))
                    .transpose()?,
                triple(&format!("hip{n}"))?,
                triple(&format!("knee{n}"))?,
                [
                    table.column(&format!("tau1_{n}"))?,
                    table.column(&format!("tau2_{n}"))?,
                    table.column(&format!("tau3_{n}"))?,
                ],
            ))
        })
        .collect::<Result<_, OutputError>>()?;
    // Per contact point of the scene: its state and force columns (a
    // foot's are `state{n}` and `foot{n}_f*`).
    let contact_cols: Vec<(usize, [usize; 3])> = view
        .contacts()
        .iter()
        .map(|&(n, kind)| {
            let prefix = crate::spatial::csv::point_prefix(kind);
            let state = match kind {
                PointKind::Tip => format!("state{n}"),
                _ => format!("{prefix}{n}_state"),
            };
            Ok((table.column(&state)?, triple(&format!("{prefix}{n}"))?))
        })
        .collect::<Result<_, OutputError>>()?;
    let mut q = vec![0.0; q_cols.len()];
    let mut contacts = vec![(StateCode::St1, [0.0; 3]); contact_cols.len()];
    let mut values = vec![LegValues::default(); legs.len()];
    for (r, row) in table.rows.iter().enumerate() {
        for (v, &c) in q.iter_mut().zip(&q_cols) {
            *v = table.number(row, r, c)?;
        }
        let v3 = |c: [usize; 3]| -> Result<[f64; 3], OutputError> {
            Ok([
                table.number(row, r, c[0])?,
                table.number(row, r, c[1])?,
                table.number(row, r, c[2])?,
            ])
        };
        for (out, &(state_col, force)) in contacts.iter_mut().zip(&contact_cols) {
            let s = cell(row, state_col);
            let code = state(s).ok_or_else(|| {
                OutputError::Io(format!(
                    "{}: line {}: `{s}` is not a contact state (ST1, ST2 or ST3)",
                    table.file.display(),
                    r + 2
                ))
            })?;
            *out = (code, v3(force)?);
        }
        for (out, &(normal, hip, knee, tau)) in values.iter_mut().zip(&leg_cols) {
            *out = LegValues {
                normal: normal.map_or(Ok(0.0), |c| table.number(row, r, c))?,
                hip_force: v3(hip)?,
                knee_force: v3(knee)?,
                torque: v3(tau)?,
            };
        }
        view.push_dynamic(table.number(row, r, t_col)?, &q, &contacts, &values);
    }
    Ok(())
}

/// Writes `dir/viewer.html` from the files of a finished run; returns its
/// path.
pub fn write_from_dir(dir: &Path) -> Result<PathBuf, OutputError> {
    if !dir.is_dir() {
        return Err(OutputError::Usage(format!(
            "{}: not a directory (give the output folder of `fbd run`)",
            dir.display()
        )));
    }
    let config_file = dir.join("config.toml");
    if let Ok(text) = std::fs::read_to_string(&config_file)
        && config::robot::is_robot(&text)
    {
        return robot_view(dir, &config_file, &text);
    }
    let config = config::load(&config_file)?;
    let source = config_file.display().to_string();
    let traj = dir.join("trajectory.csv");
    let title = super::title_of(
        &source,
        match &config {
            Config::Planar(_) => "planar model",
            Config::Hexapod(c) if c.is_dynamic() => "hexapod, 3D dynamics",
            Config::Hexapod(_) => "hexapod, kinematic gait",
        },
    );
    if !traj.exists() && dir.join("trajectory.parquet").exists() {
        return Err(OutputError::Usage(format!(
            "{}: `fbd view` reads trajectory.csv, and this run wrote trajectory.parquet (`[output] format = \"parquet\"`); `fbd run` with `[output] viewer = true` writes the viewer itself",
            dir.display()
        )));
    }
    let mut hexapod = match &config {
        Config::Planar(c) => {
            let model = c.model(&source)?;
            let table = Table::read(&traj)?;
            let records = planar_records(&model, &table)?;
            let events = planar_events(&model, &dir.join("events.csv"))?;
            let mut scene = PlanarScene::new(&model, records.len(), &title);
            for r in &records {
                scene.push(r);
            }
            let mut scene = scene.finish(&events);
            // The header counts the rows of events.csv.
            scene.event_rows = event_rows(dir).unwrap_or(scene.events.len());
            return super::write(dir, &scene);
        }
        Config::Hexapod(c) if c.is_dynamic() => {
            let params = c.spatial_params(&source)?;
            let table = Table::read(&traj)?;
            let mut view = HexapodView::dynamic(&params, table.rows.len(), &title);
            spatial_rows(&table, &params, &mut view)?;
            view
        }
        Config::Hexapod(c) => {
            let model = c.gait_model(&source)?;
            let table = Table::read(&traj)?;
            let mut view = HexapodView::gait(&model.kin, model.surface, table.rows.len(), &title);
            hexapod_rows(&table, &mut view)?;
            view
        }
    };
    if let Some(rows) = event_rows(dir) {
        hexapod.set_event_rows(rows);
    }
    hexapod.write(dir)
}

/// The rows of `dir/events.csv`, when it can be read.
fn event_rows(dir: &Path) -> Option<usize> {
    std::fs::read_to_string(dir.join("events.csv"))
        .ok()
        .map(|t| t.lines().count().saturating_sub(1))
}

/// `viewer.html` of an imported robot's run (`model = "robot"`): the base
/// pose and the joint angles of `trajectory.csv` by name (`t, rx, ry, rz,
/// phi_x, phi_y, phi_z`, one column per joint) and, when the file has them,
/// each contact point's `<c>_state` and `<c>_fx, <c>_fy, <c>_fz`.
fn robot_view(dir: &Path, config_file: &Path, text: &str) -> Result<PathBuf, OutputError> {
    let robot = config::robot::load_str(text, config_file)?;
    let traj = dir.join("trajectory.csv");
    if !traj.exists() {
        return Err(OutputError::Io(format!(
            "{}: missing (give the output folder of `fbd run`)",
            traj.display()
        )));
    }
    let table = Table::read(&traj)?;
    let model = &robot.model;
    let t_col = table.column("t")?;
    let mut q_cols = Vec::with_capacity(6 + model.joints.len());
    for c in ["rx", "ry", "rz", "phi_x", "phi_y", "phi_z"] {
        q_cols.push(table.column(c)?);
    }
    for j in &model.joints {
        q_cols.push(table.column(&j.name)?);
    }
    // Contact columns: all or none (a flight has none).
    let has_contacts = model
        .contacts
        .iter()
        .any(|c| table.columns.contains_key(&format!("{}_state", c.name)));
    let contact_cols: Vec<[usize; 4]> = if has_contacts {
        model
            .contacts
            .iter()
            .map(|c| {
                let n = &c.name;
                Ok([
                    table.column(&format!("{n}_state"))?,
                    table.column(&format!("{n}_fx"))?,
                    table.column(&format!("{n}_fy"))?,
                    table.column(&format!("{n}_fz"))?,
                ])
            })
            .collect::<Result<_, OutputError>>()?
    } else {
        Vec::new()
    };
    let mut frames = super::robot::RobotFrames::new(model, has_contacts);
    if has_contacts && robot.config.terrain.kind != config::TerrainKind::None {
        frames = frames.with_surface(robot.config.terrain.surface());
    }
    let mut q = vec![0.0; q_cols.len()];
    let mut codes = vec![1u8; contact_cols.len()];
    let mut forces = vec![[0.0; 3]; contact_cols.len()];
    for (r, row) in table.rows.iter().enumerate() {
        for (v, &c) in q.iter_mut().zip(&q_cols) {
            *v = table.number(row, r, c)?;
        }
        for (k, cols) in contact_cols.iter().enumerate() {
            let s = cell(row, cols[0]);
            codes[k] = match state(s) {
                Some(StateCode::St1) => 1,
                Some(StateCode::St2) => 2,
                Some(StateCode::St3) => 3,
                None => {
                    return Err(OutputError::Io(format!(
                        "{}: line {}: `{s}` is not a contact state (ST1, ST2 or ST3)",
                        table.file.display(),
                        r + 2
                    )));
                }
            };
            for (a, &c) in cols[1..].iter().enumerate() {
                forces[k][a] = table.number(row, r, c)?;
            }
        }
        let t = table.number(row, r, t_col)?;
        frames.push(t, &q, has_contacts.then_some((&codes[..], &forces[..])));
    }
    if let Some(rows) = event_rows(dir) {
        frames.set_event_rows(rows);
    }
    frames.write(dir)
}

/// `fbd view DIR`: writes `DIR/viewer.html` and prints its path.
pub fn view_command(dir: &Path, out: &mut dyn Write) -> Result<(), OutputError> {
    let path = write_from_dir(dir)?;
    writeln!(out, "{}", path.display()).map_err(OutputError::stdout)
}
