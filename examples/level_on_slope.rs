//! A controller closed around the stepping API in Rust: the hexapod of
//! `examples/hexapod_slope.toml` stands on the 10° slope and levels its
//! body from what it reads after every step.
//!
//!     cargo run -p fbd-suite --example level_on_slope
//!
//! The robot is set down rolled with the slope (φz = 10°). Every step it
//! reads the body's orientation and the six feet's contact forces
//! ([`fbd_sim::Readout`]) and sets PD targets: each leg's θ2 and θ3 move
//! so that its foot goes down (uphill legs bend, downhill legs stretch)
//! in proportion to the integral of the body's roll, while the feet stay
//! stuck (the contact states say so, and the tangential forces stay
//! inside the friction cone |Ft| ≤ μS·N that the example checks from the
//! forces). The body ends level (roll below 0.5°, from 10°).

use fbd_sim::simulator::{Action, PdTargets, Simulator};
use fbd_sim::spatial::SpatialModel;
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/hexapod_slope.toml");
    let config = fbd_scenario::load(&path)?;
    let fbd_scenario::Config::Hexapod(h) = config else {
        return Err("a hexapod configuration".into());
    };
    let mut params = h.spatial_params(&path.display().to_string())?;
    // The controller is ours: the configured PD's gains, our targets.
    params.control = fbd_sim::spatial::SpatialControl::None;
    params.duration = 1.5;
    let mu = params.friction.mu_static;
    let model = SpatialModel::new(&params)?;
    let legs = model.legs.clone();
    // γ of each leg (SPEC §1.2): the hip at (d·cos γ, 0, −d·sin γ) in
    // body axes, +x to the right.
    let gamma = [120.0f64, 60.0, 180.0, 0.0, 240.0, 300.0];
    let side: Vec<f64> = legs
        .iter()
        .map(|&l| gamma[l - 1].to_radians().cos())
        .collect();
    let q0 = model.params.q0.clone();
    let stance: Vec<f64> = (6..24).map(|i| q0[i]).collect();
    let mut pd = PdTargets::hold(300.0, 8.0, None, &stance);
    let mut sim = Simulator::new(model);
    let dt = sim.model().dt();
    let (mut integral, gain) = (0.0, 10.0);
    let mut roll_start = None;
    for k in 0..1500 {
        sim.step(&Action::Pd(&pd))?;
        let r = sim.readout();
        // The body's roll about its forward axis: the tilt of its x axis
        // (to the right) out of the horizontal plane.
        let rot = r.bodies[0].rotation;
        let roll = rot[1][0].asin();
        roll_start.get_or_insert(roll);
        // Feet on the ground carry the body: check the friction cone and
        // the load from the forces read.
        let mut load = 0.0;
        for c in r.contacts.iter().filter(|c| c.normal_force > 0.0) {
            let f = c.force;
            let n = c.normal;
            let fn_ = f[0] * n[0] + f[1] * n[1] + f[2] * n[2];
            let ft = [f[0] - fn_ * n[0], f[1] - fn_ * n[1], f[2] - fn_ * n[2]];
            let ft = (ft[0] * ft[0] + ft[1] * ft[1] + ft[2] * ft[2]).sqrt();
            assert!(
                ft <= mu * fn_ * (1.0 + 1e-9) + 1e-9,
                "outside the friction cone"
            );
            load += f[1];
        }
        // Level only once standing (the load on the feet).
        if load > 100.0 {
            integral += roll * dt;
        }
        // Raising θ2 by δ and lowering θ3 by δ lowers a foot, its lower
        // link kept vertical: the uphill (right) legs bend, the downhill
        // legs stretch.
        for (s, side) in side.iter().enumerate() {
            let d = gain * integral * side;
            pd.position[3 * s + 1] = stance[3 * s + 1] - d;
            pd.position[3 * s + 2] = stance[3 * s + 2] + d;
        }
        if k % 250 == 0 || k == 1499 {
            println!(
                "t = {:5.3} s  roll = {:6.2}°  load = {:6.1} N  feet stuck = {}",
                r.t,
                roll.to_degrees(),
                load,
                r.contacts
                    .iter()
                    .filter(|c| c.state == fbd_contact::StateCode::St2)
                    .count()
            );
        }
    }
    let roll = sim.readout().bodies[0].rotation[1][0].asin();
    println!(
        "roll {:.2}° → {:.2}°",
        roll_start.unwrap_or(0.0).to_degrees(),
        roll.to_degrees()
    );
    assert!(roll.abs() < 0.5f64.to_radians(), "the body is level");
    Ok(())
}
