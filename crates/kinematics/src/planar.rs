//! Planar 7-DOF kinematics of the two-leg model (docs/reference.md, paper §3.2).
//!
//! Every auxiliary point of the planar model (hips, knees, tips, link centres
//! of mass) is the body position plus a sum of rotated segments,
//!
//! ```text
//! p(q) = (Rx, Ry) + Σ_m ℓ_m · (cos α_m(q), sin α_m(q)),
//! ```
//!
//! where every angle `α_m` is *linear* in the generalised coordinates. This
//! holds for any planar tree of revolute joints on a floating base, so the
//! description ([`PlanarChains`]) is generic; [`PlanarChains::two_leg`] builds
//! the paper's model. The analytic Jacobian and the velocity-product
//! ("second-derivative") terms follow in closed form:
//!
//! ```text
//! ∂p/∂q_i = δ_{i,Rx} ex + δ_{i,Ry} ey + Σ_m ℓ_m c_{m,i} (−sin α_m, cos α_m)
//! p̈ = J q̈ + Σ_m −ℓ_m α̇_m² (cos α_m, sin α_m)
//! ```
//!
//! The model is immutable ([`PlanarChains`]); evaluations go into a reusable
//! workspace ([`PlanarData`]) so that stepping never allocates.

/// Number of generalised coordinates of the two-leg planar model.
pub const NQ: usize = 7;
/// Index of `Rx` in `q`.
pub const RX: usize = 0;
/// Index of `Ry` in `q`.
pub const RY: usize = 1;
/// Index of `φz` in `q`.
pub const PHI_Z: usize = 2;

/// Index in `q` of θ2 (hip) of the planar leg `leg` (0 = leg 3, 1 = leg 4).
pub const fn theta2_index(leg: usize) -> usize {
    3 + 2 * leg
}
/// Index in `q` of θ3 (knee) of the planar leg `leg` (0 = leg 3, 1 = leg 4).
pub const fn theta3_index(leg: usize) -> usize {
    4 + 2 * leg
}

/// Side sign `s` of docs/reference.md: −1 for leg 3 (left), +1 for leg 4 (right).
pub const fn side_sign(leg: usize) -> f64 {
    if leg == 0 { -1.0 } else { 1.0 }
}

/// The hexapod leg number (3 or 4) of planar leg `leg` (0 or 1).
pub const fn hexapod_leg_number(leg: usize) -> usize {
    3 + leg
}

/// An angle linear in the generalised coordinates:
/// `α(q) = offset + Σ coef · q[index]`.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearAngle {
    /// Constant part (rad).
    pub offset: f64,
    /// `(index into q, coefficient)` pairs.
    pub terms: Vec<(usize, f64)>,
}

impl LinearAngle {
    /// Evaluates the angle at `q`.
    pub fn value(&self, q: &[f64]) -> f64 {
        self.offset + self.terms.iter().map(|&(i, c)| c * q[i]).sum::<f64>()
    }

    /// `∂α/∂q_i`.
    pub fn coefficient(&self, i: usize) -> f64 {
        self.terms
            .iter()
            .filter(|&&(j, _)| j == i)
            .map(|&(_, c)| c)
            .sum()
    }

    /// `α̇ = Σ coef · q̇[index]`.
    pub fn rate(&self, qdot: &[f64]) -> f64 {
        self.terms.iter().map(|&(i, c)| c * qdot[i]).sum()
    }
}

/// A point of the mechanism: the base position plus rotated segments
/// `(angle index, length)`.
#[derive(Clone, Debug, PartialEq)]
pub struct PointDef {
    /// Human-readable name, e.g. `"tip3"`.
    pub name: String,
    /// `(index into PlanarChains::angles, length in m)`.
    pub segments: Vec<(usize, f64)>,
}

/// Generic planar floating-base tree: the angles and points, immutable
/// (built by [`PlanarChains::new`]).
#[derive(Clone, Debug, PartialEq)]
pub struct PlanarChains {
    /// Number of generalised coordinates; `q[0], q[1]` are the base position.
    pub nq: usize,
    /// Every angle that orients a segment or a body.
    pub angles: Vec<LinearAngle>,
    /// Every auxiliary point.
    pub points: Vec<PointDef>,
    /// The flat evaluation order of [`Self::eval_positions`].
    plan: Plan,
}

/// How [`PlanarChains::eval_positions`] evaluates the angles and points:
/// flat lists, each distinct angle's sine and cosine once, and every point
/// from the point whose segments begin its own (the same sums in the same
/// order, so the same values to the bit as summing every point's segments
/// from the base).
#[derive(Clone, Debug, PartialEq)]
struct Plan {
    /// Every distinct angle: its index, offset and terms `terms[start..end]`
    /// (an angle equal to an earlier one, offset and terms alike, is in
    /// `copies` instead).
    angles: Vec<PlanAngle>,
    /// `(index into q, coefficient)` of every distinct angle, angle after
    /// angle.
    terms: Vec<(usize, f64)>,
    /// `(angle, earlier angle it equals)`: the values copied.
    copies: Vec<(usize, usize)>,
    /// The points' updates in order, one per segment: point `dst` is point
    /// `src` (or the base) plus the segment; a point's first update starts
    /// from the earlier point its segments extend, its further ones from
    /// itself. A point without segments of its own is one copy.
    points: Vec<PlanStep>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct PlanAngle {
    index: usize,
    offset: f64,
    start: usize,
    end: usize,
}

/// One update of [`Plan::points`]: `pos[dst] = pos[src] + length·(cos, sin)
/// of angle`, with `src ==` [`BASE`] for the base position and `angle ==`
/// [`NO_SEGMENT`] for a copy.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PlanStep {
    dst: usize,
    src: usize,
    angle: usize,
    length: f64,
}

/// [`PlanStep::src`] of a point that starts from the base position.
const BASE: usize = usize::MAX;
/// [`PlanStep::angle`] of a copy.
const NO_SEGMENT: usize = usize::MAX;

impl Plan {
    fn new(angles: &[LinearAngle], points: &[PointDef]) -> Self {
        let mut plan = Plan {
            angles: Vec::with_capacity(angles.len()),
            terms: Vec::new(),
            copies: Vec::new(),
            points: Vec::with_capacity(points.len()),
        };
        for (k, a) in angles.iter().enumerate() {
            if let Some(e) = angles[..k].iter().position(|b| b == a) {
                plan.copies.push((k, e));
                continue;
            }
            let start = plan.terms.len();
            plan.terms.extend_from_slice(&a.terms);
            plan.angles.push(PlanAngle {
                index: k,
                offset: a.offset,
                start,
                end: plan.terms.len(),
            });
        }
        for (p, def) in points.iter().enumerate() {
            // The earlier point with the longest segment list that begins
            // this one's.
            let parent = (0..p)
                .filter(|&e| def.segments.starts_with(&points[e].segments))
                .max_by_key(|&e| points[e].segments.len())
                .filter(|&e| !points[e].segments.is_empty());
            let skip = parent.map_or(0, |e| points[e].segments.len());
            let mut src = parent.unwrap_or(BASE);
            let own = &def.segments[skip..];
            if own.is_empty() {
                plan.points.push(PlanStep {
                    dst: p,
                    src,
                    angle: NO_SEGMENT,
                    length: 0.0,
                });
            }
            for &(angle, length) in own {
                plan.points.push(PlanStep {
                    dst: p,
                    src,
                    angle,
                    length,
                });
                src = p;
            }
        }
        plan
    }
}

/// Largest change of an angle (rad) from the last angle whose sine and
/// cosine were evaluated in a [`PlanarData`] for which they follow from
/// that one by `sin(b + δ) = sin b + (sin b·(cos δ − 1) + cos b·sin δ)`
/// (and the cosine's), with `sin δ` and `cos δ − 1` from their Taylor
/// series up to `δ⁷` and `δ⁶`: the first terms left out, `δ⁸/8!` and
/// `δ⁹/9!`, are below 7e-19 at δ = 0.02, under the rounding of the values
/// themselves. Newton's iterates of one step, and the steps of a run at
/// the usual Δt, differ by far less (an angle turning at 10 rad/s moves
/// 0.01 rad a millisecond); any larger change is evaluated.
const SERIES_MAX: f64 = 0.02;

/// Geometry of the two-leg planar model (both legs alike, as in the paper).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanarGeometry {
    /// `d = L·cos(π/6)`: distance from the body centre to each hip (m).
    pub d: f64,
    /// Upper link length `a` (m).
    pub a: f64,
    /// Lower link length `c` (m).
    pub c: f64,
    /// Upper link centre of mass, as a fraction of `a` from the hip.
    pub upper_com: f64,
    /// Lower link centre of mass, as a fraction of `c` from the knee.
    pub lower_com: f64,
}

impl Default for PlanarGeometry {
    /// The docs/reference.md test-vector geometry: `L = 0.25` (so `d = 0.25·cos 30°`),
    /// `a = 0.2`, `c = 0.42`, centres of mass at mid-link.
    fn default() -> Self {
        Self {
            d: 0.25 * (std::f64::consts::PI / 6.0).cos(),
            a: 0.2,
            c: 0.42,
            upper_com: 0.5,
            lower_com: 0.5,
        }
    }
}

/// Indices of the named angles and points of the two-leg model in its
/// [`PlanarChains`]. Per-leg arrays are `[leg 3, leg 4]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TwoLegIndex {
    /// The central body's angle `φz`.
    pub body_angle: usize,
    /// Absolute angle of each upper link (direction hip → knee).
    pub upper_angle: [usize; 2],
    /// Absolute angle of each lower link (direction knee → tip).
    pub lower_angle: [usize; 2],
    /// Hip points.
    pub hip: [usize; 2],
    /// Knee points.
    pub knee: [usize; 2],
    /// Tip (foot) points.
    pub tip: [usize; 2],
    /// Upper link centres of mass.
    pub upper_com: [usize; 2],
    /// Lower link centres of mass.
    pub lower_com: [usize; 2],
    /// The central body's centre of mass (= R).
    pub body_com: usize,
}

impl PlanarChains {
    /// The paper's planar model: central body and legs 3 and 4 (docs/reference.md).
    pub fn two_leg(g: &PlanarGeometry) -> (Self, TwoLegIndex) {
        use std::f64::consts::PI;
        let mut angles = vec![LinearAngle {
            offset: 0.0,
            terms: vec![(PHI_Z, 1.0)],
        }];
        let mut points = vec![PointDef {
            name: "body".into(),
            segments: vec![],
        }];
        let mut idx = TwoLegIndex {
            body_angle: 0,
            upper_angle: [0; 2],
            lower_angle: [0; 2],
            hip: [0; 2],
            knee: [0; 2],
            tip: [0; 2],
            upper_com: [0; 2],
            lower_com: [0; 2],
            body_com: 0,
        };
        for leg in 0..2 {
            let s = side_sign(leg);
            let n = hexapod_leg_number(leg);
            let (t2, t3) = (theta2_index(leg), theta3_index(leg));
            // hip = R + Rot(φz)(s·d, 0)
            let hip_dir = angles.len();
            angles.push(LinearAngle {
                offset: if s < 0.0 { PI } else { 0.0 },
                terms: vec![(PHI_Z, 1.0)],
            });
            // knee − hip = Rot(φz)(s·a·cos θ2, −a·sin θ2) = a·u(φz − s·θ2 [+π if s<0])
            let up = angles.len();
            angles.push(LinearAngle {
                offset: if s < 0.0 { PI } else { 0.0 },
                terms: vec![(PHI_Z, 1.0), (t2, -s)],
            });
            // tip − knee = Rot(φz)(−s·c·cos β, c·sin β) = c·u(φz − s·β [+π if s>0])
            let low = angles.len();
            angles.push(LinearAngle {
                offset: if s > 0.0 { PI } else { 0.0 },
                terms: vec![(PHI_Z, 1.0), (t2, -s), (t3, -s)],
            });
            let hip = vec![(hip_dir, g.d)];
            let knee = [hip.clone(), vec![(up, g.a)]].concat();
            let tip = [knee.clone(), vec![(low, g.c)]].concat();
            let ucom = [hip.clone(), vec![(up, g.a * g.upper_com)]].concat();
            let lcom = [knee.clone(), vec![(low, g.c * g.lower_com)]].concat();
            let mut push = |name: String, segments: Vec<(usize, f64)>| {
                points.push(PointDef { name, segments });
                points.len() - 1
            };
            idx.hip[leg] = push(format!("hip{n}"), hip);
            idx.knee[leg] = push(format!("knee{n}"), knee);
            idx.tip[leg] = push(format!("tip{n}"), tip);
            idx.upper_com[leg] = push(format!("upper_com{n}"), ucom);
            idx.lower_com[leg] = push(format!("lower_com{n}"), lcom);
            idx.upper_angle[leg] = up;
            idx.lower_angle[leg] = low;
        }
        (Self::new(NQ, angles, points), idx)
    }

    /// A tree of `nq` coordinates with these angles and points.
    ///
    /// # Panics
    /// If a term or a segment refers to a coordinate or angle that does
    /// not exist.
    pub fn new(nq: usize, angles: Vec<LinearAngle>, points: Vec<PointDef>) -> Self {
        for a in &angles {
            assert!(a.terms.iter().all(|&(i, _)| i < nq), "angle term beyond q");
        }
        for p in &points {
            assert!(
                p.segments.iter().all(|&(a, _)| a < angles.len()),
                "segment of point {} on no angle",
                p.name
            );
        }
        let plan = Plan::new(&angles, &points);
        Self {
            nq,
            angles,
            points,
            plan,
        }
    }

    /// A fresh workspace sized for this model.
    pub fn new_data(&self) -> PlanarData {
        let na = self.angles.len();
        PlanarData {
            angle: vec![0.0; na],
            cos: vec![0.0; na],
            sin: vec![0.0; na],
            pos: vec![[0.0; 2]; self.points.len()],
            jac: vec![0.0; self.points.len() * 2 * self.nq],
            nq: self.nq,
            base: vec![[f64::NAN; 3]; na],
        }
    }

    /// Evaluates every angle, its sine and cosine, and every point at `q`.
    ///
    /// An angle within [`SERIES_MAX`] of the last one whose sine and
    /// cosine were evaluated in `data` takes them from that one by their
    /// Taylor series, exact to rounding (the iterates of a Newton solve,
    /// the next steps); any other is evaluated (and kept as the next
    /// reference).
    pub fn eval_positions(&self, q: &[f64], data: &mut PlanarData) {
        assert_eq!(q.len(), self.nq, "q has the wrong length");
        let plan = &self.plan;
        for a in &plan.angles {
            let k = a.index;
            let terms = &plan.terms[a.start..a.end];
            let v = a.offset + terms.iter().map(|&(i, c)| c * q[i]).sum::<f64>();
            let [b, bs, bc] = data.base[k];
            let d = v - b;
            let (sin, cos) = if d.abs() <= SERIES_MAX {
                let d2 = d * d;
                // sin δ and cos δ − 1, Horner in δ².
                let sd = d
                    * (1.0
                        - d2 * (1.0 / 6.0) * (1.0 - d2 * (1.0 / 20.0) * (1.0 - d2 * (1.0 / 42.0))));
                let cd = -d2 * 0.5 * (1.0 - d2 * (1.0 / 12.0) * (1.0 - d2 * (1.0 / 30.0)));
                (bs + (bs * cd + bc * sd), bc + (bc * cd - bs * sd))
            } else {
                let (s, c) = v.sin_cos();
                data.base[k] = [v, s, c];
                (s, c)
            };
            data.angle[k] = v;
            data.sin[k] = sin;
            data.cos[k] = cos;
        }
        for &(k, e) in &plan.copies {
            data.angle[k] = data.angle[e];
            data.sin[k] = data.sin[e];
            data.cos[k] = data.cos[e];
        }
        let (sin, cos, pos) = (&data.sin, &data.cos, &mut data.pos);
        let base = [q[RX], q[RY]];
        for step in &plan.points {
            let [x, y] = if step.src == BASE {
                base
            } else {
                pos[step.src]
            };
            pos[step.dst] = if step.angle == NO_SEGMENT {
                [x, y]
            } else {
                let (a, l) = (step.angle, step.length);
                [x + l * cos[a], y + l * sin[a]]
            };
        }
    }

    /// Fills the analytic point Jacobians; call after [`Self::eval_positions`].
    pub fn eval_jacobians(&self, data: &mut PlanarData) {
        let nq = self.nq;
        data.jac.fill(0.0);
        for (p, def) in self.points.iter().enumerate() {
            let base = p * 2 * nq;
            data.jac[base + RX] = 1.0;
            data.jac[base + nq + RY] = 1.0;
            for &(a, l) in &def.segments {
                let (s, c) = (data.sin[a], data.cos[a]);
                for &(i, coef) in &self.angles[a].terms {
                    data.jac[base + i] -= l * coef * s;
                    data.jac[base + nq + i] += l * coef * c;
                }
            }
        }
    }

    /// Velocity of point `p`: `J(q)·q̇` (after [`Self::eval_jacobians`]).
    pub fn point_velocity(&self, data: &PlanarData, p: usize, qdot: &[f64]) -> [f64; 2] {
        let mut v = [0.0; 2];
        for (axis, vk) in v.iter_mut().enumerate() {
            *vk = (0..self.nq)
                .map(|i| data.jac_at(p, axis, i) * qdot[i])
                .sum();
        }
        v
    }

    /// The velocity-product term of the acceleration of point `p`,
    /// `J̇(q, q̇)·q̇ = Σ_m −ℓ_m α̇_m² (cos α_m, sin α_m)`, so that
    /// `p̈ = J·q̈ + J̇·q̇` (after [`Self::eval_positions`]).
    pub fn point_bias_acceleration(&self, data: &PlanarData, p: usize, qdot: &[f64]) -> [f64; 2] {
        let mut b = [0.0; 2];
        for &(a, l) in &self.points[p].segments {
            let w = self.angles[a].rate(qdot);
            b[0] -= l * w * w * data.cos[a];
            b[1] -= l * w * w * data.sin[a];
        }
        b
    }
}

/// Workspace of [`PlanarChains`] evaluations (allocated once).
#[derive(Clone, Debug)]
pub struct PlanarData {
    /// Angle values (rad).
    pub angle: Vec<f64>,
    /// `cos` of each angle.
    pub cos: Vec<f64>,
    /// `sin` of each angle.
    pub sin: Vec<f64>,
    /// Inertial position of each point (m).
    pub pos: Vec<[f64; 2]>,
    /// Point Jacobians, `[point][axis][q index]` flattened.
    pub jac: Vec<f64>,
    nq: usize,
    /// Per angle, the last angle whose sine and cosine were evaluated, and
    /// those (the reference of the series in
    /// [`PlanarChains::eval_positions`]).
    base: Vec<[f64; 3]>,
}

impl PlanarData {
    /// `∂p_axis/∂q_i` of point `p`.
    #[inline]
    pub fn jac_at(&self, p: usize, axis: usize, i: usize) -> f64 {
        self.jac[(p * 2 + axis) * self.nq + i]
    }

    /// The row `∂p_axis/∂q` of point `p`.
    #[inline]
    pub fn jac_row(&self, p: usize, axis: usize) -> &[f64] {
        let s = (p * 2 + axis) * self.nq;
        &self.jac[s..s + self.nq]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fd::{FdTolerance, check_jacobian};

    fn paper_q() -> [f64; NQ] {
        [
            0.0,
            0.6,
            0.0,
            0.0,
            245f64.to_radians(),
            0.0,
            255f64.to_radians(),
        ]
    }

    #[test]
    fn spec_test_vector() {
        let (ch, ix) = PlanarChains::two_leg(&PlanarGeometry::default());
        let mut d = ch.new_data();
        ch.eval_positions(&paper_q(), &mut d);
        let t3 = d.pos[ix.tip[0]];
        let t4 = d.pos[ix.tip[1]];
        assert!(
            (t3[0] + 0.594006).abs() < 1e-6 && (t3[1] - 0.219351).abs() < 1e-6,
            "{t3:?}"
        );
        assert!(
            (t4[0] - 0.525210).abs() < 1e-6 && (t4[1] - 0.194311).abs() < 1e-6,
            "{t4:?}"
        );
    }

    #[test]
    fn spec_formulas_in_body_frame() {
        // docs/reference.md written out literally, at an arbitrary configuration.
        let g = PlanarGeometry::default();
        let (ch, ix) = PlanarChains::two_leg(&g);
        let mut d = ch.new_data();
        let q = [0.1, 0.5, 0.3, 0.2, 4.0, -0.3, 4.3];
        ch.eval_positions(&q, &mut d);
        for leg in 0..2 {
            let s = side_sign(leg);
            let (t2, t3) = (q[theta2_index(leg)], q[theta3_index(leg)]);
            let hip = [s * g.d, 0.0];
            let knee = [hip[0] + s * g.a * t2.cos(), hip[1] - g.a * t2.sin()];
            let tip = [
                knee[0] - s * g.c * (t2 + t3).cos(),
                knee[1] + g.c * (t2 + t3).sin(),
            ];
            let (sp, cp) = q[PHI_Z].sin_cos();
            let to_world =
                |p: [f64; 2]| [q[0] + cp * p[0] - sp * p[1], q[1] + sp * p[0] + cp * p[1]];
            for (want, got) in [(hip, ix.hip[leg]), (knee, ix.knee[leg]), (tip, ix.tip[leg])] {
                let w = to_world(want);
                let p = d.pos[got];
                assert!((w[0] - p[0]).abs() < 1e-12 && (w[1] - p[1]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn point_jacobians_match_finite_differences() {
        let (ch, _) = PlanarChains::two_leg(&PlanarGeometry::default());
        let mut d = ch.new_data();
        let q = [0.1, 0.5, 0.3, 0.2, 4.0, -0.3, 4.3];
        ch.eval_positions(&q, &mut d);
        ch.eval_jacobians(&mut d);
        let np = ch.points.len();
        let mut work = ch.new_data();
        check_jacobian(
            &q,
            2 * np,
            |x, out| {
                ch.eval_positions(x, &mut work);
                for p in 0..np {
                    out[2 * p] = work.pos[p][0];
                    out[2 * p + 1] = work.pos[p][1];
                }
            },
            |i, j| d.jac_at(i / 2, i % 2, j),
            FdTolerance::default(),
        )
        .unwrap_or_else(|e| panic!("{e}"));
    }

    #[test]
    fn iterates_near_the_last_evaluation_match_fresh_evaluations() {
        // A workspace that evaluated q takes the sines and cosines of the
        // angles within SERIES_MAX of it from their series: the points
        // agree with a fresh workspace's (every sine and cosine evaluated)
        // to rounding, at changes from 1e-12 to just inside the limit,
        // and every sine and cosine is a unit pair.
        let (ch, _) = PlanarChains::two_leg(&PlanarGeometry::default());
        let q = [0.1, 0.5, 0.3, 0.2, 4.0, -0.3, 4.3];
        let dir = [0.3, -0.7, 1.0, -0.4, 0.9, 0.5, -1.0];
        for &h in &[1e-12, 1e-9, 1e-6, 0.9 * SERIES_MAX / 3.0] {
            let mut kept = ch.new_data();
            ch.eval_positions(&q, &mut kept);
            let x: Vec<f64> = q.iter().zip(dir).map(|(a, d)| a + h * d).collect();
            ch.eval_positions(&x, &mut kept);
            let mut fresh = ch.new_data();
            ch.eval_positions(&x, &mut fresh);
            for (k, (a, b)) in kept.pos.iter().zip(&fresh.pos).enumerate() {
                for axis in 0..2 {
                    assert!(
                        (a[axis] - b[axis]).abs() <= 4e-16,
                        "h = {h:e}, point {k} axis {axis}: {} vs {}",
                        a[axis],
                        b[axis]
                    );
                }
            }
            for (a, (s, c)) in kept.sin.iter().zip(&kept.cos).enumerate() {
                assert!(
                    (s * s + c * c - 1.0).abs() <= 4e-16,
                    "h = {h:e}, angle {a}: sin² + cos² − 1 = {:e}",
                    s * s + c * c - 1.0
                );
            }
        }
    }

    #[test]
    fn points_follow_from_their_parents_bit_for_bit() {
        // The plan evaluates each point from the point its segments extend;
        // the sums are the same, in the same order, as from the base.
        let (ch, _) = PlanarChains::two_leg(&PlanarGeometry::default());
        let q = [0.1, 0.5, 0.3, 0.2, 4.0, -0.3, 4.3];
        let mut d = ch.new_data();
        ch.eval_positions(&q, &mut d);
        for (p, def) in ch.points.iter().enumerate() {
            let mut x = q[RX];
            let mut y = q[RY];
            for &(a, l) in &def.segments {
                let (s, c) = ch.angles[a].value(&q).sin_cos();
                x += l * c;
                y += l * s;
            }
            assert_eq!(d.pos[p], [x, y], "point {}", def.name);
        }
    }

    #[test]
    fn bias_acceleration_matches_second_difference() {
        // p(q + t·q̇) has second derivative J̇q̇ at t = 0 (q̈ = 0).
        let (ch, _) = PlanarChains::two_leg(&PlanarGeometry::default());
        let mut d = ch.new_data();
        let q = [0.1, 0.5, 0.3, 0.2, 4.0, -0.3, 4.3];
        let qd = [0.4, -0.2, 1.1, -2.0, 3.0, 0.7, -1.5];
        ch.eval_positions(&q, &mut d);
        let h = 1e-4;
        let at = |t: f64| {
            let mut w = ch.new_data();
            let x: Vec<f64> = q.iter().zip(qd).map(|(a, b)| a + t * b).collect();
            ch.eval_positions(&x, &mut w);
            w.pos
        };
        let (pp, p0, pm) = (at(h), at(0.0), at(-h));
        for p in 0..ch.points.len() {
            let b = ch.point_bias_acceleration(&d, p, &qd);
            for k in 0..2 {
                let fd = (pp[p][k] - 2.0 * p0[p][k] + pm[p][k]) / (h * h);
                assert!(
                    (fd - b[k]).abs() < 1e-5 * (1.0 + b[k].abs()),
                    "point {p} axis {k}: {fd} vs {}",
                    b[k]
                );
            }
        }
    }
}
