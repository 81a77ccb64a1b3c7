//! Robots as data: one [`RobotModel`] type for every legged robot — a
//! tree of rigid bodies (mass, centre of mass, inertia tensor) joined by
//! revolute joints (axis, origin, limits, effort limits), contact points on
//! the bodies, actuators on the joints.
//!
//! * [`urdf`] and [`mjcf`] import a description (fixed joints merged into
//!   their parents, the root turned to fbd's `+y`-up body frame, contact
//!   points chosen by [`ContactChoice`]), with one error naming the file,
//!   line and element for anything fbd does not model;
//! * [`dh`] builds a model from Denavit–Hartenberg rows, and the paper's
//!   hexapod ([`dh::hexapod`]) from its D-H parameters;
//! * [`ik::solve`] finds joint angles that put contact points at targets
//!   (damped least squares, joint limits respected);
//! * [`mjcf_export::to_mjcf`] writes any model as a MuJoCo model in fbd's
//!   frames;
//! * [`forward()`] places every body, joint axis and contact point for a
//!   floating-base pose and joint angles.
//!
//! The model carries no dynamics: the FBD equations are built from it
//! elsewhere.

pub mod dh;
pub mod error;
pub mod forward;
pub mod gait;
pub mod ik;
pub mod mjcf;
pub mod mjcf_export;
pub mod model;
pub mod tree;
pub mod urdf;
mod xml;

pub use error::{Place, Result, RobotError};
pub use forward::{RobotData, forward};
pub use model::{Actuator, Body, ContactPoint, Joint, JointLimits, RobotModel};
pub use tree::{ContactChoice, Up};

pub use nalgebra;

/// ` (did you mean "x"?)` for the closest of `known` to `name`, or a short
/// list of what there is.
pub(crate) fn suggest(name: &str, known: &[&str]) -> String {
    let best = known
        .iter()
        .map(|k| (edit_distance(name, k), *k))
        .min_by_key(|(d, _)| *d);
    match best {
        Some((d, k)) if d <= 3.max(name.len() / 3) => format!(" (did you mean \"{k}\"?)"),
        _ if known.is_empty() => String::new(),
        _ => {
            let mut list: Vec<&str> = known.iter().take(8).copied().collect();
            if known.len() > 8 {
                list.push("…");
            }
            format!(" (there are: {})", list.join(", "))
        }
    }
}

/// Levenshtein distance (characters).
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}
