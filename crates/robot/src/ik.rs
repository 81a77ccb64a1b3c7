//! Numeric inverse kinematics of contact points: the joint angles that put
//! chosen contact points at targets, for any robot (no closed form needed).
//!
//! Damped least squares (Levenberg–Marquardt) on the stacked position
//! errors of the points, over the joints of their chains only, the floating
//! base held: `Δq = Jᵀ·(J·Jᵀ + λ²·1)⁻¹·e`, with `J` the points' geometric
//! Jacobian (`∂p/∂θ_j = u_j × (p − o_j)` for each joint `j` above the
//! point), each step clamped to the joint limits; `λ` grows when a step does
//! not reduce the error and shrinks when it does.

use nalgebra::{DMatrix, DVector, Isometry3, Vector3};

use crate::forward::{RobotData, forward};
use crate::model::RobotModel;

/// A contact point (index) and its target (inertial, m).
pub type Target = (usize, Vector3<f64>);

/// Tolerances of [`solve`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IkParams {
    /// Largest remaining distance of any point to its target (m). Default
    /// 1e-10.
    pub tolerance: f64,
    /// Most iterations. Default 200.
    pub max_iterations: usize,
    /// Initial damping `λ` (m). Default 1e-3.
    pub damping: f64,
}

impl Default for IkParams {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            max_iterations: 200,
            damping: 1e-3,
        }
    }
}

/// Why no joint angles put the points on their targets.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "contact point \"{point}\" stays {distance:.6} m from its target (the closest its joints reach within their limits)"
)]
pub struct IkError {
    /// The point farthest from its target at the end.
    pub point: String,
    /// Its distance to the target (m).
    pub distance: f64,
}

/// The joints above body `b`, root side first.
fn chain(model: &RobotModel, mut b: usize) -> Vec<usize> {
    let mut out = Vec::new();
    while let Some(j) = model.bodies[b].joint {
        out.push(j);
        b = model.joints[j].parent;
    }
    out.reverse();
    out
}

/// Joint angles from `q` that put each contact point `targets[i].0` at
/// `targets[i].1` (inertial) with the root at `base`; joints not above any
/// of the points keep their angles. A search that stalls (a limit in the
/// way, the other branch of a knee) starts again: from every combination
/// of 1/6, 1/2 and 5/6 of the joints' ranges for a chain of up to four
/// joints, else from Van der Corput fractions ([`RESTARTS`] in all).
///
/// # Errors
/// [`IkError`] naming the point left farthest, after every start, when
/// the targets are not reached within the limits.
pub fn solve(
    model: &RobotModel,
    base: &Isometry3<f64>,
    q: &[f64],
    targets: &[Target],
    params: &IkParams,
) -> Result<Vec<f64>, IkError> {
    // Points whose chains share no joint are solved apart (a leg each).
    let mut groups: Vec<(Vec<usize>, Vec<Target>)> = Vec::new();
    for t in targets {
        let joints = moved_joints(model, std::slice::from_ref(t));
        match groups
            .iter_mut()
            .find(|(g, _)| g.iter().any(|j| joints.contains(j)))
        {
            Some((g, ts)) => {
                g.extend(joints);
                g.sort_unstable();
                g.dedup();
                ts.push(*t);
            }
            None => groups.push((joints, vec![*t])),
        }
    }
    let mut out = q.to_vec();
    for (joints, group) in &groups {
        let found = solve_group(model, base, &out, group, params)?;
        for &j in joints {
            out[j] = found[j];
        }
    }
    Ok(out)
}

/// [`solve`] for points whose chains share joints, with restarts.
fn solve_group(
    model: &RobotModel,
    base: &Isometry3<f64>,
    q: &[f64],
    targets: &[Target],
    params: &IkParams,
) -> Result<Vec<f64>, IkError> {
    let mut best: Option<IkError> = None;
    let joints = moved_joints(model, targets);
    // The caller's angles first; then, for a chain of up to four joints,
    // every combination of 1/6, 1/2 and 5/6 of each joint's range (a leg
    // whose target needs a joint near a limit is reached from one of
    // them); for longer chains Van der Corput fractions 1/2, 1/4, 3/4, …
    let grid = joints.len() <= 4;
    let starts = if grid {
        1 + 3usize.pow(joints.len() as u32)
    } else {
        RESTARTS
    };
    for k in 0..starts {
        let mut start = q.to_vec();
        if k > 0 {
            for (i, &j) in joints.iter().enumerate() {
                let f = if grid {
                    [1.0 / 6.0, 0.5, 5.0 / 6.0][(k - 1) / 3usize.pow(i as u32) % 3]
                } else {
                    van_der_corput(k + 3 * i)
                };
                start[j] = match model.joints[j].limits {
                    Some(l) => l.lower + f * (l.upper - l.lower),
                    None => q[j] + std::f64::consts::TAU * f - std::f64::consts::PI,
                };
            }
        }
        match attempt(model, base, &start, targets, params) {
            Ok(found) => return Ok(found),
            Err(e) => {
                if best.as_ref().is_none_or(|b| e.distance < b.distance) {
                    best = Some(e);
                }
            }
        }
    }
    Err(best.expect("at least one start"))
}

/// Starts tried by [`solve`] for a chain of more than four joints.
pub const RESTARTS: usize = 16;

/// The `n`-th Van der Corput fraction in base 2 (n ≥ 1): 1/2, 1/4, 3/4, …
fn van_der_corput(mut n: usize) -> f64 {
    let (mut x, mut denom) = (0.0, 1.0);
    n += 1;
    while n > 0 {
        denom *= 2.0;
        x += (n % 2) as f64 / denom;
        n /= 2;
    }
    x
}

/// The joints above any of the targets' points.
fn moved_joints(model: &RobotModel, targets: &[(usize, Vector3<f64>)]) -> Vec<usize> {
    let mut joints: Vec<usize> = targets
        .iter()
        .flat_map(|(c, _)| chain(model, model.contacts[*c].body))
        .collect();
    joints.sort_unstable();
    joints.dedup();
    joints
}

/// One damped least-squares search from `q`.
fn attempt(
    model: &RobotModel,
    base: &Isometry3<f64>,
    q: &[f64],
    targets: &[Target],
    params: &IkParams,
) -> Result<Vec<f64>, IkError> {
    let joints = moved_joints(model, targets);
    let mut q = q.to_vec();
    let clamp = |j: usize, x: f64| match model.joints[j].limits {
        Some(l) => x.clamp(l.lower, l.upper),
        None => x,
    };
    for &j in &joints {
        q[j] = clamp(j, q[j]);
    }
    let mut data = RobotData::new(model);
    let errors = |q: &[f64], data: &mut RobotData| {
        forward(model, base, q, data);
        let e: Vec<Vector3<f64>> = targets.iter().map(|(c, t)| t - data.contacts[*c]).collect();
        e
    };
    let norm = |e: &[Vector3<f64>]| e.iter().map(|v| v.norm_squared()).sum::<f64>();
    let mut e = errors(&q, &mut data);
    let mut lambda = params.damping;
    for _ in 0..params.max_iterations {
        if e.iter().all(|v| v.norm() <= params.tolerance) {
            return Ok(q);
        }
        // J (3·points × joints) at the current angles (`data` holds them).
        let mut jac = DMatrix::<f64>::zeros(3 * targets.len(), joints.len());
        for (i, (c, _)) in targets.iter().enumerate() {
            let p = data.contacts[*c];
            let above = chain(model, model.contacts[*c].body);
            for (k, &j) in joints.iter().enumerate() {
                if above.contains(&j) {
                    let o = data.frames[model.joints[j].child].translation.vector;
                    let col = data.axes[j].cross(&(p - o));
                    jac.fixed_view_mut::<3, 1>(3 * i, k).copy_from(&col);
                }
            }
        }
        let rhs =
            DVector::from_iterator(3 * targets.len(), e.iter().flat_map(|v| v.iter().copied()));
        let mut improved = false;
        for _ in 0..30 {
            let a =
                &jac * jac.transpose() + DMatrix::identity(rhs.len(), rhs.len()) * lambda * lambda;
            let Some(y) = a.lu().solve(&rhs) else {
                lambda *= 10.0;
                continue;
            };
            let mut dq = jac.transpose() * y;
            // Active set: a joint at a limit that the step pushes past it
            // is held, and the step is solved again without it.
            let mut held = jac.clone();
            for _ in 0..joints.len() {
                let mut changed = false;
                for (k, &j) in joints.iter().enumerate() {
                    let Some(l) = model.joints[j].limits else {
                        continue;
                    };
                    let at_lower = q[j] <= l.lower && dq[k] < 0.0;
                    let at_upper = q[j] >= l.upper && dq[k] > 0.0;
                    if (at_lower || at_upper) && held.column(k).norm() > 0.0 {
                        held.column_mut(k).fill(0.0);
                        changed = true;
                    }
                }
                if !changed {
                    break;
                }
                let a = &held * held.transpose()
                    + DMatrix::identity(rhs.len(), rhs.len()) * lambda * lambda;
                let Some(y) = a.lu().solve(&rhs) else { break };
                dq = held.transpose() * y;
            }
            let mut trial = q.clone();
            for (k, &j) in joints.iter().enumerate() {
                trial[j] = clamp(j, q[j] + dq[k]);
            }
            let mut trial_data = RobotData::new(model);
            let te = errors(&trial, &mut trial_data);
            if norm(&te) < norm(&e) {
                q = trial;
                e = te;
                data = trial_data;
                lambda = (lambda / 10.0).max(1e-12);
                improved = true;
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    forward(model, base, &q, &mut data);
    let (worst, distance) = targets
        .iter()
        .map(|(c, t)| (*c, (t - data.contacts[*c]).norm()))
        .fold((0, 0.0), |acc, x| if x.1 > acc.1 { x } else { acc });
    if distance <= params.tolerance {
        return Ok(q);
    }
    Err(IkError {
        point: model.contacts[worst].name.clone(),
        distance,
    })
}
