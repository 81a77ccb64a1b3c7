//! Fixtures of the spatial (3D) tests.

use fbd_dynamics::tree::kin::TreeKin;
use fbd_sim::spatial::{SpatialControl, SpatialModel, SpatialParams};

/// The configuration of landing `run` of
/// `examples/sweep_hexapod_landing_1000.toml` (the default hexapod dropped
/// onto its feet, knees and hips; Δt = 2 ms, 1.5 s), as `fbd sweep` runs
/// it.
#[allow(dead_code)]
pub fn landing_config(run: usize) -> fbd_scenario::HexapodConfig {
    let plan = fbd_cli::sweep::plan(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/sweep_hexapod_landing_1000.toml"
    )))
    .expect("the sweep file loads");
    let fbd_cli::sweep::RunConfig::Model(fbd_cli::Config::Hexapod(c)) = &plan.configs[run] else {
        panic!("a hexapod run")
    };
    (**c).clone()
}

/// A PD-held stance with the feet on the ground at t = 0.
pub fn stance() -> SpatialParams {
    let theta = [0.0, (-20f64).to_radians(), 290f64.to_radians()];
    let mut p = SpatialParams {
        duration: 2.0,
        control: SpatialControl::Pd {
            kp: 300.0,
            kd: 10.0,
            torque_limit: None,
            target: vec![theta; 6],
        },
        ..SpatialParams::default()
    };
    for s in 0..6 {
        p.q0[6 + 3 * s..9 + 3 * s].copy_from_slice(&theta);
    }
    p.q0[1] = 0.0;
    let model = SpatialModel::new(&SpatialParams {
        terrain: fbd_contact::Surface::new(fbd_contact::Terrain::None, 0.0),
        ..p.clone()
    })
    .unwrap();
    let mut kin = TreeKin::new(&model.mech.model);
    kin.eval(&model.mech.model, &p.q0);
    // Contact 0 is leg 1's tip.
    let tip_y = kin.contact[model.mech.contacts[0].model_contact].y;
    p.q0[1] = -tip_y;
    p
}

/// What [`check_contact_laws`] found.
#[derive(Debug, Default)]
#[allow(dead_code)]
pub struct LawReport {
    /// Rows × points checked in ST2 and ST3.
    pub sticking: usize,
    pub sliding: usize,
    /// Of the sliding ones, those whose direction was checked against the
    /// slip to the next row.
    pub directions: usize,
    /// The largest violation found (N) and where.
    pub worst: f64,
    pub worst_at: String,
}

/// Coulomb's law on every contact row of a 3D run, from the records alone
/// (forces, points and states): a free point carries no force; otherwise
/// `N ≥ 0`; sticking `|Ft| ≤ μS·N`; sliding `|Ft| = μD·N` and
/// `Ft = −μD·N·ŝ` with `ŝ` the unit slip of the point from this row to the
/// next (stride 1; not checked on a row whose step was solved in substeps,
/// whose forces are its first substep's). `Ft` is the force minus its part
/// along the surface normal at the point. Violations are forces (N).
#[allow(dead_code)]
pub fn check_contact_laws(
    model: &SpatialModel,
    rows: &[fbd_sim::robot::RobotRecord],
    retried: &[usize],
) -> LawReport {
    let p = &model.params;
    let (mu_s, mu_d) = (p.friction.mu_static, p.friction.mu_dynamic);
    let mut rep = LawReport::default();
    let note = |v: f64, at: String, rep: &mut LawReport| {
        if v > rep.worst {
            rep.worst = v;
            rep.worst_at = at;
        }
    };
    for (i, r) in rows.iter().enumerate() {
        let next = rows.get(i + 1).filter(|n| n.step == r.step + 1);
        for (j, (c, spec)) in r.contacts.iter().zip(&model.contacts).enumerate() {
            let f = c.force;
            let at = |law: &str| {
                format!(
                    "t = {:.4} leg {} {} {}: {law}",
                    r.t,
                    spec.leg,
                    spec.kind.as_str(),
                    c.state.as_str()
                )
            };
            let fnorm = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
            if c.state.as_str() == "ST1" {
                note(fnorm, at("free point carries a force"), &mut rep);
                continue;
            }
            let n = c.normal;
            note(-n, at("N < 0"), &mut rep);
            let [_, nv, _] = fbd_contact::spatial::frame(&p.terrain, c.point[0], c.point[2]);
            let ft: [f64; 3] = std::array::from_fn(|a| f[a] - n * nv[a]);
            let ftn = (ft[0] * ft[0] + ft[1] * ft[1] + ft[2] * ft[2]).sqrt();
            if c.state.as_str() == "ST2" {
                rep.sticking += 1;
                note(ftn - mu_s * n, at("|Ft| > μS·N"), &mut rep);
                continue;
            }
            rep.sliding += 1;
            note((ftn - mu_d * n).abs(), at("|Ft| ≠ μD·N"), &mut rep);
            let Some(next) = next else { continue };
            if retried.contains(&r.step) {
                continue;
            }
            let q = next.contacts[j].point;
            let d: [f64; 3] = std::array::from_fn(|a| q[a] - c.point[a]);
            let dn = d[0] * nv[0] + d[1] * nv[1] + d[2] * nv[2];
            let s: [f64; 3] = std::array::from_fn(|a| d[a] - dn * nv[a]);
            let sl = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
            if sl > fbd_contact::spatial::STOP_SPEED * model.params.dt {
                rep.directions += 1;
                let e: [f64; 3] = std::array::from_fn(|a| ft[a] + mu_d * n * s[a] / sl);
                // The slip's direction is resolved to δ/|s| rad
                // (docs/reference.md, "Resolution of a slip's direction").
                let resolution = mu_d * n.abs() * fbd_sim::spatial::step::SLIP_RESOLUTION / sl;
                let off = ((e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt() - resolution).max(0.0);
                note(
                    off,
                    at(&format!("Ft not −μD·N·ŝ (slip {:.3e} m/s)", sl / p.dt)),
                    &mut rep,
                );
            }
        }
    }
    rep
}

/// [`check_contact_laws`] on a finished run (its retried steps taken from
/// `summary`), failing unless every row is within the laws to 1e-6 of the
/// weight; `what` names the run in the message. The law report.
#[allow(dead_code)]
pub fn assert_rows_within_laws(
    model: &SpatialModel,
    rows: &[fbd_sim::robot::RobotRecord],
    summary: &fbd_sim::RunSummary,
    what: &str,
) -> LawReport {
    let retried: Vec<usize> = summary.retries.iter().map(|r| r.step).collect();
    let rep = check_contact_laws(model, rows, &retried);
    let weight = model.mech.total_mass() * model.params.gravity;
    assert!(
        rep.worst <= 1e-6 * weight,
        "{what}: {:.3e} N at {}",
        rep.worst,
        rep.worst_at
    );
    rep
}
