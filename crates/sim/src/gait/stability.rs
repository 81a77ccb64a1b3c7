//! Static stability: the support polygon of the stance feet, the whole
//! robot's centre of mass projected along gravity, and the stability
//! margin.
//!
//! Gravity is `−Y`, so the projection along gravity is the horizontal
//! `(x, z)` of each point. The support polygon is the convex hull of the
//! stance feet (Andrew's monotone chain on at most six points, on the
//! stack). The margin is the smallest distance from the projected centre
//! of mass to the polygon's edges, positive inside and negative outside
//! (minus the distance to the polygon). With two stance feet the polygon
//! is a segment and the margin is minus the distance to it; with one,
//! minus the distance to the foot; with none, `−∞`.

use fbd_kinematics::hexapod::HexapodData;
use fbd_kinematics::nalgebra::Vector3;

use super::params::LEGS;

/// Masses of the bodies (kg).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Masses {
    /// Central body, centre of mass at `R`.
    pub body: f64,
    /// Each upper link.
    pub upper: f64,
    /// Each lower link.
    pub lower: f64,
}

impl Default for Masses {
    /// 10 kg body, 0.3 kg upper and 1.1 kg lower links (the planar default
    /// experiment's robot).
    fn default() -> Self {
        Self {
            body: 10.0,
            upper: 0.3,
            lower: 1.1,
        }
    }
}

/// The whole robot's centre of mass (body + 18 links) from a filled
/// forward-kinematics workspace.
#[inline]
pub fn centre_of_mass(m: &Masses, fk: &HexapodData) -> Vector3<f64> {
    let mut s = m.body * fk.body_com;
    for l in &fk.legs {
        s += m.upper * l.upper_com + m.lower * l.lower_com;
    }
    s / (m.body + LEGS as f64 * (m.upper + m.lower))
}

#[inline]
fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// The convex hull of `points` (counter-clockwise in `(x, z)` coordinates
/// as drawn with `z` up the page): the hull's vertices in `out`, their
/// number returned. Collinear and repeated points are dropped.
pub fn convex_hull(points: &[[f64; 2]], out: &mut [[f64; 2]; 2 * LEGS]) -> usize {
    let n = points.len();
    assert!(n <= LEGS, "at most {LEGS} points");
    let mut p = [[0.0; 2]; LEGS];
    p[..n].copy_from_slice(points);
    let p = &mut p[..n];
    p.sort_unstable_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    if n < 3 {
        out[..n].copy_from_slice(p);
        if n == 2 && p[0] == p[1] {
            return 1;
        }
        return n;
    }
    let mut k = 0;
    for &q in p.iter() {
        while k >= 2 && cross(out[k - 2], out[k - 1], q) <= 0.0 {
            k -= 1;
        }
        out[k] = q;
        k += 1;
    }
    let lower = k + 1;
    for &q in p.iter().rev().skip(1) {
        while k >= lower && cross(out[k - 2], out[k - 1], q) <= 0.0 {
            k -= 1;
        }
        out[k] = q;
        k += 1;
    }
    k - 1
}

fn segment_distance(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> f64 {
    let (dx, dz) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dz * dz;
    let u = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dz) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p[0] - a[0] - u * dx).hypot(p[1] - a[1] - u * dz)
}

/// The stability margin of `com` (horizontal `(x, z)`) over the support
/// polygon of `feet` (horizontal positions of the stance feet), m.
pub fn margin(feet: &[[f64; 2]], com: [f64; 2]) -> f64 {
    let mut hull = [[0.0; 2]; 2 * LEGS];
    let n = convex_hull(feet, &mut hull);
    match n {
        0 => f64::NEG_INFINITY,
        1 => -(com[0] - hull[0][0]).hypot(com[1] - hull[0][1]),
        2 => -segment_distance(hull[0], hull[1], com),
        _ => {
            let mut inside = f64::INFINITY;
            let mut outside = f64::INFINITY;
            let mut all_in = true;
            for i in 0..n {
                let (a, b) = (hull[i], hull[(i + 1) % n]);
                let len = (b[0] - a[0]).hypot(b[1] - a[1]);
                let d = cross(a, b, com) / len;
                if d < 0.0 {
                    all_in = false;
                }
                inside = inside.min(d);
                outside = outside.min(segment_distance(a, b, com));
            }
            if all_in { inside } else { -outside }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_margin() {
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5]];
        assert!((margin(&sq, [0.5, 0.5]) - 0.5).abs() < 1e-15);
        assert!((margin(&sq, [0.2, 0.6]) - 0.2).abs() < 1e-15);
        assert!((margin(&sq, [1.5, 0.5]) + 0.5).abs() < 1e-15);
        assert!((margin(&sq, [2.0, 2.0]) + 2f64.sqrt()).abs() < 1e-15);
        assert!((margin(&sq[..2], [0.5, 0.5]) + 0.5).abs() < 1e-15);
        assert!((margin(&sq[..1], [0.0, 2.0]) + 2.0).abs() < 1e-15);
        assert_eq!(margin(&[], [0.0, 0.0]), f64::NEG_INFINITY);
        let mut h = [[0.0; 2]; 12];
        assert_eq!(convex_hull(&sq, &mut h), 4);
    }
}
