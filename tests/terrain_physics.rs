//! Contact on height maps and friction patches, asserted as physics: a
//! height map sampled from a plane gives the analytic slope's forces; a
//! stance on a tilted height map sticks below atan μS and slides above,
//! with Coulomb's law on every row; a fall onto a bump touches down at the
//! free-fall time on the surface; a friction patch changes the law where
//! it lies, in 3D and in the plane.

mod common;

use common::spatial::stance;
use fbd_contact::spatial::{clearance, frame};
use fbd_contact::{Friction, FrictionPatch, HeightGrid, StateCode, Surface, Terrain, friction_at};
use fbd_dynamics::spatial::SpatialKin;
use fbd_sim::robot::RobotRecord;
use fbd_sim::spatial::{SpatialModel, SpatialParams, closed_form, run_collect};

/// A 4 m × 4 m height map of the plane `y = slope·x` (81 × 61 samples).
fn plane_map(slope: f64) -> Surface {
    Surface::from_grid(
        HeightGrid::sample(81, 61, [4.0, 3.0], [0.0, 0.0], |x, _| slope * x).unwrap(),
    )
}

/// The PD stance on `surface` tilted like a slope of `angle` (rad, rising
/// towards +X), its lowest foot 1 mm above the ground, run for `duration`.
fn on(
    surface: Surface,
    angle: f64,
    friction: Friction,
    duration: f64,
) -> (SpatialModel, Vec<RobotRecord>) {
    let mut p = stance();
    p.duration = duration;
    p.terrain = surface;
    p.friction = friction;
    p.q0[5] = angle;
    let hexapod = closed_form(&p);
    let mut kin = SpatialKin::new(&hexapod);
    kin.eval(&hexapod, &p.q0);
    let lowest = kin
        .fk
        .legs
        .iter()
        .map(|l| clearance(&p.terrain, [l.tip.x, l.tip.y, l.tip.z]))
        .fold(f64::INFINITY, f64::min);
    p.q0[1] += 0.001 - lowest;
    let mut model = SpatialModel::new(&p).unwrap();
    // Tight Newton convergence: what is compared is the ground, not where
    // each step's iteration stopped.
    model.newton.residual_tol = 1e-11;
    let (rows, summary) = run_collect(&model);
    assert!(summary.error.is_none(), "{:?}", summary.error);
    (model, rows)
}

fn weight(p: &SpatialParams) -> f64 {
    (p.body_mass + p.legs.len() as f64 * (p.upper_mass + p.lower_mass)) * p.gravity
}

/// Coulomb's law on every contact row, with the friction of the patch
/// under the point: returns (sticking, sliding) rows.
fn check_law(model: &SpatialModel, rows: &[RobotRecord]) -> (usize, usize) {
    let p = &model.params;
    let (mut stick, mut slide) = (0, 0);
    for r in rows {
        for c in &r.contacts {
            let f = c.force;
            let fnorm = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
            let tol = 1e-6 * (1.0 + fnorm);
            let mu = friction_at(p.terrain.patches(), &p.friction, c.point[0], c.point[2]);
            match c.state {
                StateCode::St1 => assert!(fnorm < 1e-9, "t = {}: free point pushed", r.t),
                state => {
                    let n = c.normal;
                    assert!(n > -tol, "t = {}: pulling contact N = {n}", r.t);
                    let [_, nv, _] = frame(&p.terrain, c.point[0], c.point[2]);
                    let ftn = (0..3)
                        .map(|i| (f[i] - n * nv[i]).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    if state == StateCode::St2 {
                        stick += 1;
                        assert!(
                            ftn <= mu.mu_static * n + tol,
                            "t = {}: outside the cone",
                            r.t
                        );
                    } else {
                        slide += 1;
                        assert!(
                            (ftn - mu.mu_dynamic * n).abs() < tol,
                            "t = {}: |Ft| {ftn} ≠ μD·N {}",
                            r.t,
                            mu.mu_dynamic * n
                        );
                    }
                }
            }
        }
    }
    (stick, slide)
}

#[test]
fn a_height_map_of_a_plane_gives_the_slopes_forces() {
    let angle = 10f64.to_radians();
    let friction = Friction::default();
    let (m, exact) = on(
        Surface::new(
            Terrain::Slope {
                slope: angle.tan(),
                height: 0.0,
            },
            0.0,
        ),
        angle,
        friction,
        0.5,
    );
    let (_, map) = on(plane_map(angle.tan()), angle, friction, 0.5);
    let w = weight(&m.params);
    let (mut worst, mut worst_rest) = (0.0f64, 0.0f64);
    let mut touching = 0;
    for (a, b) in exact.iter().zip(&map) {
        let mut row = 0.0f64;
        for (ca, cb) in a.contacts.iter().zip(&b.contacts) {
            assert_eq!(ca.state, cb.state, "t = {}: states differ", a.t);
            touching += usize::from(ca.state != StateCode::St1);
            for i in 0..3 {
                row = row.max((ca.force[i] - cb.force[i]).abs());
            }
        }
        worst = worst.max(row);
        if a.t >= 0.4 {
            worst_rest = worst_rest.max(row);
        }
    }
    println!(
        "largest force difference {worst:e} N ({:e} of the weight), at rest (t ≥ 0.4 s) {worst_rest:e} N ({:e})",
        worst / w,
        worst_rest / w
    );
    assert!(touching > 1000);
    assert!(
        worst_rest <= 1e-9 * w,
        "at rest the forces differ by {worst_rest:e} N"
    );
    assert!(worst <= 1e-9 * w, "forces differ by {worst:e} N");
}

#[test]
fn a_stance_on_a_tilted_height_map_sticks_below_atan_mu_and_slides_above() {
    let angle = 10f64.to_radians();
    // atan 0.4 = 21.8° > 10°: it sticks.
    let f = Friction {
        mu_static: 0.4,
        mu_dynamic: 0.3,
    };
    let (m, rows) = on(plane_map(angle.tan()), angle, f, 1.0);
    let (stick, _) = check_law(&m, &rows);
    let moved = rows.last().unwrap().q[0] - rows[0].q[0];
    println!("μS 0.4: moved {moved:e} m, {stick} sticking rows");
    assert!(moved.abs() < 0.005, "sticks: moved {moved}");
    assert!(
        rows.last()
            .unwrap()
            .contacts
            .iter()
            .all(|c| c.state != StateCode::St3)
    );
    // atan 0.15 = 8.5° < 10°: it slides down (−X).
    let f = Friction {
        mu_static: 0.15,
        mu_dynamic: 0.1,
    };
    let (m, rows) = on(plane_map(angle.tan()), angle, f, 1.0);
    let (_, slide) = check_law(&m, &rows);
    let moved = rows.last().unwrap().q[0] - rows[0].q[0];
    println!("μS 0.15: moved {moved} m, {slide} sliding rows");
    assert!(moved < -0.05 && slide > 100, "slides: moved {moved}");
}

#[test]
fn a_friction_patch_makes_the_stance_slide_where_it_lies() {
    let angle = 10f64.to_radians();
    let dry = Friction {
        mu_static: 0.4,
        mu_dynamic: 0.3,
    };
    let ice = Friction {
        mu_static: 0.15,
        mu_dynamic: 0.1,
    };
    let patch = |x: [f64; 2]| {
        plane_map(angle.tan()).with_patches(vec![FrictionPatch {
            x,
            z: [-2.0, 2.0],
            friction: ice,
        }])
    };
    // Ice everywhere under the robot: it slides as on an icy slope.
    let (m, rows) = on(patch([-2.0, 2.0]), angle, dry, 1.0);
    let (_, slide) = check_law(&m, &rows);
    let moved = rows.last().unwrap().q[0] - rows[0].q[0];
    assert!(moved < -0.05 && slide > 100, "slides on ice: {moved}");
    // Ice far away: it sticks.
    let (m, rows) = on(patch([1.5, 2.0]), angle, dry, 1.0);
    check_law(&m, &rows);
    let moved = rows.last().unwrap().q[0] - rows[0].q[0];
    assert!(moved.abs() < 0.005, "sticks off the ice: {moved}");
}

/// The stance dropped onto a bump under foot 1: every body falls freely
/// (the PD holds the pose, no torque) until the first touchdown, foot 1 on
/// the bump, at the free-fall time of its gap; the touchdown point is on
/// the surface.
#[test]
fn a_fall_onto_a_bump_touches_down_at_the_free_fall_time() {
    let mut p = stance();
    p.duration = 0.3;
    let hexapod = closed_form(&p);
    let mut kin = SpatialKin::new(&hexapod);
    kin.eval(&hexapod, &p.q0);
    let foot1 = kin.fk.legs[0].tip;
    let (xf, zf) = (foot1.x, foot1.z);
    let bump = move |x: f64, z: f64| {
        0.04 * (-((x - xf).powi(2) + (z - zf).powi(2)) / (2.0 * 0.06f64.powi(2))).exp()
    };
    p.terrain =
        Surface::from_grid(HeightGrid::sample(201, 201, [2.0, 2.0], [0.0, 0.0], bump).unwrap());
    p.q0[1] += 0.1; // every foot 0.1 m above y = 0, foot 1 0.06 m above the bump
    let model = SpatialModel::new(&p).unwrap();
    let (rows, summary) = run_collect(&model);
    assert!(summary.error.is_none(), "{:?}", summary.error);
    let first = summary
        .events
        .iter()
        .find(|e| e.to != StateCode::St1)
        .unwrap();
    assert_eq!(first.leg, 1, "foot 1 lands first, on the bump");
    let gap = foot1.y + 0.1 - p.terrain.height(xf, zf);
    let t_free = (2.0 * gap / p.gravity).sqrt();
    // A touchdown at t puts the point on the ground at t + Δt: the
    // free-fall crossing lies in (t, t + Δt].
    println!("touchdown step starts {} s, free fall {t_free} s", first.t);
    assert!(first.t < t_free && t_free <= first.t + p.dt + 1e-12);
    let row = &rows[first.step + 1];
    let c = model
        .contacts
        .iter()
        .position(|c| c.leg == 1)
        .map(|c| &row.contacts[c])
        .unwrap();
    assert!(
        clearance(&p.terrain, c.point).abs() < 1e-9,
        "on the surface"
    );
    // The other feet land later, on flat ground, at theirs.
    let t_flat = (2.0 * (foot1.y + 0.1) / p.gravity).sqrt();
    let later = summary.events.iter().find(|e| e.leg != 1).unwrap();
    assert!(later.t > first.t);
    println!(
        "next touchdown {} s (free fall to y = 0: {t_flat} s)",
        later.t
    );
}

/// The planar model on a 10° slope (examples/slope_stick.toml, μS = 0.4:
/// it stands), sliding down on a patch of ice under its stance, and
/// exactly as without it when the patch lies off the plane z = 0.
#[test]
fn a_friction_patch_in_the_plane() {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/slope_stick.toml"),
    )
    .unwrap();
    let run = |extra: &str| {
        let t = format!("{text}\n{extra}");
        let fbd_scenario::Config::Planar(c) = fbd_scenario::parse_str(&t, "p.toml", &[]).unwrap()
        else {
            panic!("planar")
        };
        let model = c.model("p.toml").unwrap();
        let (rows, s) = fbd_sim::run_collect(&model);
        assert!(s.error.is_none(), "{:?}", s.error);
        let slid = rows
            .iter()
            .filter(|r| r.contacts.iter().any(|c| c.state == StateCode::St3))
            .count();
        (rows.last().unwrap().q[0] - rows[0].q[0], slid)
    };
    let (dry, dry_slid) = run("");
    assert!(dry.abs() < 5e-3, "dry: {dry} {dry_slid}");
    let ice =
        "[[terrain.patch]]\nx = [-2.0, 2.0]\nz = [-1.0, 1.0]\nmu_static = 0.1\nmu_dynamic = 0.05\n";
    let (moved, slid) = run(ice);
    assert!(moved < -0.05 && slid > 100, "ice: {moved} {slid}");
    let off = ice.replace("z = [-1.0, 1.0]", "z = [0.5, 1.0]");
    assert_eq!(
        run(&off),
        (dry, dry_slid),
        "ice off the plane changes nothing"
    );
}
