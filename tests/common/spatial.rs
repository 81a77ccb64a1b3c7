//! Fixtures of the spatial (3D) tests.

use fbd_dynamics::spatial::SpatialKin;
use fbd_sim::spatial::{SpatialControl, SpatialModel, SpatialParams};

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
    let mut kin = SpatialKin::new(&model.mech);
    kin.eval(&model.mech, &p.q0);
    let tip_y = kin.fk.legs[0].tip.y;
    p.q0[1] = -tip_y;
    p
}
