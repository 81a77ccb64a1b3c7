//! The plane and space: what differs between the planar and the spatial
//! Newton–Euler equations of a free body, and nothing else.
//!
//! A body in [`Plane`] has 2 linear coordinates and 1 rotation (about Z);
//! in [`Space3`] 3 and 3. Forces are `LIN`-vectors, moments `ANG`-vectors
//! (a planar moment is the Z component of `r × F`). The assembly
//! ([`crate::assembly`]) is written once over this trait; each instance
//! performs exactly the floating-point operations of the equations written
//! out by hand for its dimension (the planar runs are bit-for-bit those of
//! the planar assembly before it became generic).

use crate::assemble::JacobianSink;
use std::fmt::Debug;

/// Linear and angular vectors of one dimension (see the module docs).
pub trait Space: Copy + Debug + PartialEq + 'static {
    /// Linear components: 2 in the plane, 3 in space.
    const LIN: usize;
    /// Rotational components: 1 in the plane (about Z), 3 in space.
    const ANG: usize;
    /// A point, force or linear Jacobian column (`[f64; LIN]`).
    type Lin: Copy + Default + Debug + PartialEq + AsRef<[f64]> + AsMut<[f64]>;
    /// A moment or angular Jacobian column (`[f64; ANG]`).
    type Ang: Copy + Default + Debug + PartialEq + AsRef<[f64]> + AsMut<[f64]>;
    /// A contact frame: `LIN` unit vectors, the normal second
    /// ([`crate::rows::NORMAL`]).
    type Frame: Copy + Debug + PartialEq + AsRef<[Self::Lin]>;

    /// `r × f`.
    fn cross(r: &Self::Lin, f: &Self::Lin) -> Self::Ang;

    /// The structurally non-zero entries of `scale·∂(r × f)/∂f`, scaled by
    /// `−1`, into the rotation rows `row..row + ANG` and the force columns
    /// `col..col + LIN`: the moment rows' derivative with respect to a force
    /// applied at arm `r` (`scale` = the rows' sign and projection).
    fn moment_arm_entries<J: JacobianSink>(
        jac: &mut J,
        row: usize,
        col: usize,
        r: &Self::Lin,
        scale: f64,
    );

    /// `∂(clearance)/∂q_i` of a point on the terrain `y = ϱ(x[, z])` with
    /// slope `(∂ϱ/∂x, ∂ϱ/∂z)`, given the point's Jacobian column `v`:
    /// `v_y − ϱ_x·v_x [− ϱ_z·v_z]`.
    fn clearance_rate(v: &Self::Lin, slope: [f64; 2]) -> f64;
}

/// The plane: `(x, y)` and a rotation about Z.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Plane;

/// Space: `(x, y, z)` and a rotation about any axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Space3;

impl Space for Plane {
    const LIN: usize = 2;
    const ANG: usize = 1;
    type Lin = [f64; 2];
    type Ang = [f64; 1];
    type Frame = [[f64; 2]; 2];

    #[inline]
    fn cross(r: &[f64; 2], f: &[f64; 2]) -> [f64; 1] {
        [r[0] * f[1] - r[1] * f[0]]
    }

    #[inline]
    fn moment_arm_entries<J: JacobianSink>(
        jac: &mut J,
        row: usize,
        col: usize,
        r: &[f64; 2],
        scale: f64,
    ) {
        // −scale·∂(rx·fy − ry·fx)/∂(fx, fy) = scale·(ry, −rx)
        jac.add(row, col, scale * r[1]);
        jac.add(row, col + 1, -scale * r[0]);
    }

    #[inline]
    fn clearance_rate(v: &[f64; 2], slope: [f64; 2]) -> f64 {
        v[1] - slope[0] * v[0]
    }
}

impl Space for Space3 {
    const LIN: usize = 3;
    const ANG: usize = 3;
    type Lin = [f64; 3];
    type Ang = [f64; 3];
    type Frame = [[f64; 3]; 3];

    #[inline]
    fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    }

    #[inline]
    fn moment_arm_entries<J: JacobianSink>(
        jac: &mut J,
        row: usize,
        col: usize,
        r: &[f64; 3],
        scale: f64,
    ) {
        // ∂(r × f)/∂f = [r]×, whose diagonal is structurally zero.
        let h = [[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]];
        for (i, hi) in h.iter().enumerate() {
            for (j, hij) in hi.iter().enumerate() {
                if i != j {
                    jac.add(row + i, col + j, -scale * hij);
                }
            }
        }
    }

    #[inline]
    fn clearance_rate(v: &[f64; 3], slope: [f64; 2]) -> f64 {
        v[1] - slope[0] * v[0] - slope[1] * v[2]
    }
}
