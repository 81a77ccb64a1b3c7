//! One step's FBD equations seen as a [`NewtonSystem`].

use crate::rules::Sink;
use fbd_contact::{ContactState, Terrain};
use fbd_dynamics::{FbdData, Mechanism, NoJacobian};
use fbd_solver::NewtonSystem;

/// One step's FBD equations as a [`NewtonSystem`] (borrowing the model and
/// the workspace); built by [`crate::step::system`].
pub struct StepSystem<'a> {
    pub(crate) mech: &'a Mechanism,
    pub(crate) terrain: &'a Terrain,
    pub(crate) fbd: &'a mut FbdData,
    pub(crate) scales: &'a [f64],
    /// `1 / scales`.
    pub(crate) weights: &'a [f64],
}

impl NewtonSystem for StepSystem<'_> {
    fn dim(&self) -> usize {
        self.mech.layout().dim()
    }
    fn pattern_key(&self) -> u64 {
        fbd_dynamics::pattern_key(self.fbd)
    }
    fn pattern(&self, entries: &mut Vec<(usize, usize)>) {
        fbd_dynamics::pattern(self.mech, self.terrain, self.fbd, entries);
    }
    fn eval(&mut self, x: &[f64], r: &mut [f64], jac: Option<&mut fbd_solver::JacobianSink<'_>>) {
        match jac {
            Some(j) => fbd_dynamics::eval(self.mech, self.terrain, self.fbd, x, r, &mut Sink(j)),
            None => fbd_dynamics::eval(self.mech, self.terrain, self.fbd, x, r, &mut NoJacobian),
        }
    }
    fn residual_scale(&self, row: usize) -> f64 {
        self.scales[row]
    }
    fn residual_weight(&self, row: usize) -> f64 {
        self.weights[row]
    }
}

/// Convergence scales of every row for the current contact states, and
/// their reciprocals (the weights of the scaled norm): forces
/// to `1e-9 ×` the weight, with a round-off floor `1e-6·(M/Δt²)·(1 m + |R|)`
/// (a body row is `m·x/Δt²` minus forces, so its round-off grows with the
/// coordinates' magnitude `|R|` and with `1/Δt²`); moments to that times the
/// length scale; contact positions to `1e-12·(1 m + |R|)`.
pub(crate) fn row_scales(
    mech: &Mechanism,
    fbd: &FbdData,
    extent: f64,
    scales: &mut [f64],
    weights: &mut [f64],
) {
    let lay = mech.layout();
    let k = fbd.position_gain;
    let force = fbd.total_mass * mech.gravity.abs().max(1.0) + 1e-6 * k * (1.0 + extent);
    let moment = force * fbd.length_scale;
    let position = 1e-3 * k * (1.0 + extent);
    // Each row takes one of three scales: `(scale, weight)` pairs, three
    // divisions per system.
    let [force, moment, position] = [force, moment, position].map(|s| (s, 1.0 / s));
    let mut set = |row: usize, (s, w): (f64, f64)| {
        scales[row] = s;
        weights[row] = w;
    };
    for b in 0..lay.bodies {
        let row = lay.body_row(b);
        set(row, force);
        set(row + 1, force);
        set(row + 2, moment);
    }
    for (c, eq) in fbd.contact.iter().enumerate() {
        let row = lay.contact_row(c);
        let (s0, s1) = match eq.state {
            ContactState::Free => (force, force),
            ContactState::Stick { .. } => (position, position),
            ContactState::Slide { .. } => (force, position),
        };
        set(row, s0);
        set(row + 1, s1);
    }
    // A joint-limit row is a moment, free (λ) or at an end (Kθ·δθ).
    for l in 0..lay.limits {
        set(lay.limit_row(l), moment);
    }
}
