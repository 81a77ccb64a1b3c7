//! The hexapod dynamics examples do what their headers say: the stand and
//! the slope come to rest with every foot sticking and the normal forces
//! carrying the weight, the drop lands on its feet and body, the walk
//! walks up its slope without a loaded stance foot slipping, on ice the
//! feet slip down the slope and the robot walks less far, and the slope
//! slides with μS = 0.1.

use std::path::Path;

use fbd_contact::StateCode;
use fbd_dynamics::PointKind;
use fbd_scenario::{Config, Override, load_with_overrides};
use fbd_sim::robot::{RobotContactRow, RobotRecord};
use fbd_sim::spatial::{SpatialModel, run_collect};

fn run(name: &str, overrides: &[&str]) -> (SpatialModel, Vec<RobotRecord>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name);
    let o: Vec<Override> = overrides
        .iter()
        .map(|s| Override::parse(s).unwrap())
        .collect();
    let Config::Hexapod(h) = load_with_overrides(&path, &o).unwrap() else {
        panic!("{name}: not a hexapod")
    };
    assert!(h.is_dynamic(), "{name}");
    let model = h.spatial_model(name).unwrap();
    let (records, summary) = run_collect(&model);
    assert!(summary.error.is_none(), "{name}: {:?}", summary.error);
    assert_eq!(records.len(), model.steps, "{name}");
    (model, records)
}

/// Total mass (kg) and weight (N) of the model.
fn weight(m: &SpatialModel) -> f64 {
    let p = &m.params;
    (p.body_mass + p.legs.len() as f64 * (p.upper_mass + p.lower_mass)) * p.gravity
}

/// The feet's rows of `r` (a record of `m`).
fn tips<'a>(m: &'a SpatialModel, r: &'a RobotRecord) -> impl Iterator<Item = &'a RobotContactRow> {
    r.contacts
        .iter()
        .zip(&m.contacts)
        .filter(|(_, spec)| spec.kind == PointKind::Tip)
        .map(|(c, _)| c)
}

/// At the last step: at rest, every touching point sticking, and the
/// ground's forces (all points) adding up to the weight.
fn at_rest_on_the_ground(name: &str, m: &SpatialModel, last: &RobotRecord) {
    assert!(last.kinetic < 1e-9, "{name}: kinetic {}", last.kinetic);
    let fy: f64 = last.contacts.iter().map(|c| c.force[1]).sum();
    let w = weight(m);
    assert!((fy - w).abs() < 1e-6 * w, "{name}: Σ fy {fy} vs weight {w}");
    for c in &last.contacts {
        assert_ne!(c.state, StateCode::St3, "{name}: {c:?}");
    }
}

#[test]
fn stand_comes_to_rest_on_six_sticking_feet() {
    let (m, rec) = run("hexapod_stand.toml", &[]);
    let last = rec.last().unwrap();
    at_rest_on_the_ground("stand", &m, last);
    for c in tips(&m, last) {
        assert_eq!(c.state, StateCode::St2, "{c:?}");
        // Lower links vertical: little tangential force.
        let ft = c.force[0].hypot(c.force[2]);
        assert!(ft < 0.2 * c.normal, "{c:?}");
    }
    // No foot slips at any step.
    assert!(
        rec.iter()
            .flat_map(|r| tips(&m, r))
            .all(|c| c.state != StateCode::St3)
    );
    // The body settles within 2 mm of the touchdown height 0.3516 m.
    assert!((last.q[1] - 0.3516).abs() < 2e-3, "{}", last.q[1]);
}

#[test]
fn drop_lands_on_its_feet_and_body() {
    let (m, rec) = run("hexapod_drop.toml", &[]);
    let last = rec.last().unwrap();
    at_rest_on_the_ground("drop", &m, last);
    for kind in [PointKind::Tip, PointKind::Hip] {
        let n = last
            .contacts
            .iter()
            .zip(&m.contacts)
            .filter(|(c, spec)| spec.kind == kind && c.state == StateCode::St2)
            .count();
        assert_eq!(n, 6, "{kind:?} sticking at the end");
    }
    // The first touchdown of the feet (all six at once): the free fall of
    // the feet from 0.85 − c·cos 35°, within a step.
    let h = 0.85 - 0.42 * 35f64.to_radians().cos();
    let t_fall = (2.0 * h / m.params.gravity).sqrt();
    let first = rec
        .iter()
        .find(|r| tips(&m, r).any(|c| c.state != StateCode::St1))
        .unwrap();
    assert!((first.t - t_fall).abs() < 2e-3, "{} vs {t_fall}", first.t);
    assert!(tips(&m, first).all(|c| c.state != StateCode::St1));
}

#[test]
fn slope_sticks_with_04_and_slides_with_01() {
    let (m, rec) = run("hexapod_slope.toml", &[]);
    let last = rec.last().unwrap();
    at_rest_on_the_ground("slope", &m, last);
    assert!(
        rec.iter()
            .flat_map(|r| tips(&m, r))
            .all(|c| c.state != StateCode::St3)
    );
    assert!(last.q[0].abs() < 1e-3, "rx {}", last.q[0]);
    let (_, rec) = run(
        "hexapod_slope.toml",
        &["terrain.mu_static=0.1", "terrain.mu_dynamic=0.08"],
    );
    let last = rec.last().unwrap();
    assert!(last.q[0] < -0.3, "rx {}", last.q[0]);
    assert!(tips(&m, last).all(|c| c.state == StateCode::St3));
}

/// Loaded (normal force above 5 N) foot rows, and those sliding.
fn loaded_slips(m: &SpatialModel, rec: &[RobotRecord]) -> (usize, usize) {
    let loaded: Vec<_> = rec
        .iter()
        .flat_map(|r| tips(m, r))
        .filter(|c| c.normal > 5.0)
        .collect();
    let slipping = loaded.iter().filter(|c| c.state == StateCode::St3).count();
    (loaded.len(), slipping)
}

/// The feet's slides along X (m): the mean over the feet on the ground
/// (touching at both ends of a step) of their displacement over the step,
/// summed over the run — how far the stance feet let the body slip back —
/// and the total of every foot's slides down (−X) and up (+X).
fn foot_slides_x(m: &SpatialModel, rec: &[RobotRecord]) -> (f64, f64, f64) {
    let (mut mean, mut down, mut up) = (0.0, 0.0, 0.0);
    for w in rec.windows(2) {
        let (mut sum, mut n) = (0.0, 0usize);
        for (a, b) in tips(m, &w[0]).zip(tips(m, &w[1])) {
            if a.state == StateCode::St1 || b.state == StateCode::St1 {
                continue;
            }
            let dx = b.point[0] - a.point[0];
            sum += dx;
            n += 1;
            if dx < 0.0 {
                down -= dx;
            } else {
                up += dx;
            }
        }
        if n > 0 {
            mean += sum / n as f64;
        }
    }
    (mean, down, up)
}

#[test]
fn walk_keeps_its_stance_feet_and_ice_slips_back_down_the_slope() {
    // Up a 3.5° slope rising towards +X, the robot facing +X.
    let (m, dry) = run("hexapod_walk.toml", &[]);
    let (loaded, slipping) = loaded_slips(&m, &dry);
    assert!(
        loaded > 10_000 && slipping == 0,
        "dry: {slipping} of {loaded}"
    );
    // 0.1 m/s for 2 s less the two half-ramps: 0.15 m forward (+X).
    let x_dry = dry.last().unwrap().q[0];
    assert!((x_dry - 0.15).abs() < 5e-3, "dry: rx {x_dry}");
    let (slide, _, _) = foot_slides_x(&m, &dry);
    assert!(slide.abs() < 1e-4, "dry: feet slid {slide} m");

    let (m_ice, ice) = run("hexapod_walk_ice.toml", &[]);
    let (loaded, slipping) = loaded_slips(&m_ice, &ice);
    assert!(
        slipping > loaded / 5,
        "ice: {slipping} of {loaded} loaded foot rows slipping"
    );
    // The slope's pull (tan 3.5° = 0.06 of the 0.1 ice gives) makes the
    // slides go down it.
    let (slide, down, up) = foot_slides_x(&m_ice, &ice);
    assert!(down > 4.0 * up, "ice: feet slid {down} m down, {up} m up");
    // The joints track angles relative to the body: what the feet slid
    // back is lost, and is what the body lost against the dry walk.
    let x_ice = ice.last().unwrap().q[0];
    let lost = x_dry - x_ice;
    assert!(
        lost > 0.1 * x_dry,
        "ice: rx {x_ice} vs dry {x_dry}: lost {lost} m"
    );
    assert!(
        (lost + slide).abs() < 0.1 * lost,
        "ice: lost {lost} m, mean slide of the feet {slide} m"
    );
    // At the end it stands on the slope (tan 3.5° < 0.1).
    at_rest_on_the_ground("walk on ice", &m, ice.last().unwrap());
}
