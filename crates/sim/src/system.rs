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
        fbd_dynamics::pattern(self.mech, self.fbd, entries);
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
    // divisions per system. Rows: bodies (3 each), contacts (2 each), then
    // limits (a moment each: free, λ, or at an end, Kθ·δθ).
    let [force, moment, position] = [force, moment, position].map(|s| (s, 1.0 / s));
    let contacts_from = lay.contact_row(0);
    let limits_from = lay.limit_row(0);
    for (out, weight) in [(scales, false), (weights, true)] {
        let pick = |(s, w): (f64, f64)| if weight { w } else { s };
        let (body_rows, rest) = out.split_at_mut(contacts_from);
        let (contact_rows, rest) = rest.split_at_mut(limits_from - contacts_from);
        let body = [pick(force), pick(force), pick(moment)];
        for rows in body_rows.chunks_exact_mut(3) {
            rows.copy_from_slice(&body);
        }
        for (rows, eq) in contact_rows.chunks_exact_mut(2).zip(&fbd.contact) {
            let (s0, s1) = match eq.state {
                ContactState::Free => (force, force),
                ContactState::Stick { .. } => (position, position),
                ContactState::Slide { .. } => (force, position),
            };
            rows.copy_from_slice(&[pick(s0), pick(s1)]);
        }
        rest[..lay.limits].fill(pick(moment));
    }
}
