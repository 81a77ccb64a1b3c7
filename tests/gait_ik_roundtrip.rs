//! FK(IK(target)) equals the target for every foot at every step, over
//! random gaits (proptest); stance feet do not move.

mod common;

use common::gait::{model, run_ok};
use common::strategies::{fixed_config, gait_params};
use proptest::prelude::*;

proptest! {
    #![proptest_config(fixed_config(24, 0x6a17))]

    #[test]
    fn every_foot_reaches_its_target(mut params in gait_params()) {
        params.walk_time = 4.0;
        let m = model(params, 0.01, 5.0);
        let (rows, _) = run_ok(&m);
        for d in &rows {
            for leg in 0..6 {
                let e = (d.fk.legs[leg].tip - d.feet[leg]).norm();
                prop_assert!(e < 1e-9, "t {} leg {}: |FK − target| = {e:e}", d.t, leg + 1);
            }
        }
        for w in rows.windows(2) {
            for leg in 0..6 {
                if w[0].stance()[leg] && w[1].stance()[leg] {
                    let moved = (w[1].fk.legs[leg].tip - w[0].fk.legs[leg].tip).norm();
                    prop_assert!(moved < 1e-12, "t {} leg {}: stance foot moved {moved:e} m", w[1].t, leg + 1);
                }
            }
        }
    }
}
