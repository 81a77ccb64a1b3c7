//! The body's commanded motion: the planar twist integrated, start-up and
//! stop, body offsets, sway and terrain following, with analytic velocity
//! and acceleration.
//!
//! # The planar path
//!
//! The heading ψ (yaw about +Y, starting at the initial `φy`) and the
//! horizontal position `(x, z)` obey
//!
//! ```text
//! ψ̇ = s(t)·ω(t)
//! (ẋ, ż) = s(t)·(v_f(t)·f(ψ) + v_l(t)·l(ψ)),  f = (−sin ψ, −cos ψ), l = (cos ψ, −sin ψ)
//! ```
//!
//! (`f` is the body's forward −z, `l` its right +x, at zero tilt), where
//! `v_f, v_l, ω` are the commands and `s(t)` the start-up/stop blend
//! ([`GaitParams::ramp`]). It is integrated once, when the plan is built,
//! with the classical Runge–Kutta method on the run's time grid (error
//! O(Δt⁴)), and evaluated between grid points by cubic Hermite
//! interpolation with the exact velocities. Velocities and accelerations
//! are the analytic ones of the ODE.
//!
//! # The full pose
//!
//! ```text
//! R   = (x, y0 + h·s_on + ϱ̄(x, z) − ϱ̄(x0, z0), z) + σ(t)·l(ψ),  σ = sway·s(t)·sin(2πt/T)
//! Rot = Ry(ψ − ψ0)·Rot0·Rx(p·s_on)·Rz(−r·s_on)
//! ```
//!
//! with `Rot0` the initial rotation, `h, r, p` the height, roll and pitch
//! offsets, `s_on` the start-up blend alone (the offsets are kept at the
//! end), and `ϱ̄` the surface the body follows
//! ([`fbd_contact::Surface::mean_height`], only with
//! [`GaitParams::follow_terrain`]).

use std::sync::Arc;

use fbd_contact::Surface;
use fbd_kinematics::nalgebra::{Matrix3, Vector3};
use fbd_kinematics::pose::{rot_x, rot_y, rot_z};

use super::params::GaitParams;

/// Quintic smoothstep `S(u) = 10u³ − 15u⁴ + 6u⁵` on `[0, 1]` (0 before,
/// 1 after) and its first two derivatives in `u`.
#[inline]
pub fn smoothstep(u: f64) -> (f64, f64, f64) {
    if u <= 0.0 {
        (0.0, 0.0, 0.0)
    } else if u >= 1.0 {
        (1.0, 0.0, 0.0)
    } else {
        let u2 = u * u;
        (
            u2 * u * (10.0 - 15.0 * u + 6.0 * u2),
            30.0 * u2 * (1.0 - u) * (1.0 - u),
            60.0 * u * (1.0 - u) * (1.0 - 2.0 * u),
        )
    }
}

/// The body's pose and its first two time derivatives at one time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyState {
    /// Centre of the body `R` (m).
    pub position: Vector3<f64>,
    /// `Ṙ` (m/s).
    pub velocity: Vector3<f64>,
    /// `R̈` (m/s²).
    pub acceleration: Vector3<f64>,
    /// `Rot`, body → inertial.
    pub rotation: Matrix3<f64>,
    /// Angular velocity ω, inertial frame (rad/s).
    pub omega: Vector3<f64>,
    /// Angular acceleration ω̇, inertial frame (rad/s²).
    pub omega_dot: Vector3<f64>,
    /// `(φx, φy, φz)` of `Rot = Rx(φx)·Rz(φz)·Ry(φy)` (rad), φy continuous
    /// with the heading.
    pub phi: Vector3<f64>,
}

impl Default for BodyState {
    /// At rest at the origin, no rotation.
    fn default() -> Self {
        Self {
            position: Vector3::zeros(),
            velocity: Vector3::zeros(),
            acceleration: Vector3::zeros(),
            rotation: Matrix3::identity(),
            omega: Vector3::zeros(),
            omega_dot: Vector3::zeros(),
            phi: Vector3::zeros(),
        }
    }
}

/// The planar path: `(x, z, ψ)` and derivatives.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Planar {
    /// `(x, z, ψ)` (m, m, rad; ψ the absolute heading).
    pub q: [f64; 3],
    /// Time derivative.
    pub v: [f64; 3],
    /// Second time derivative.
    pub a: [f64; 3],
}

/// The body plan: parameters, the initial pose and the integrated planar
/// path on the time grid.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyPlan {
    params: GaitParams,
    surface: Surface,
    dt: f64,
    /// `(x, z, ψ)` at `k·Δt`, k = 0..table.len(): 24 bytes a step of the
    /// walk, shared by the plan's clones (a run's parameters are cloned
    /// into its model; three copies were 72 bytes a step, 7 GB for a
    /// walk of 10⁸ steps).
    table: Arc<[[f64; 3]]>,
    /// Initial `R`.
    r0: Vector3<f64>,
    /// Initial rotation.
    rot0: Matrix3<f64>,
    /// Initial heading `φy`.
    psi0: f64,
    /// `ϱ̄` under the initial body centre.
    ground0: f64,
    /// The initial rotation is a pure yaw (`φx = φz = 0`).
    level: bool,
}

impl BodyPlan {
    /// Integrates the planar path on the grid `k·dt` up to `until` (s;
    /// beyond it the path is held at its last point, so `until` must reach
    /// past the time the body stops).
    ///
    /// # Panics
    /// If `dt ≤ 0`.
    pub fn new(
        params: &GaitParams,
        surface: &Surface,
        r0: Vector3<f64>,
        phi0: Vector3<f64>,
        dt: f64,
        until: f64,
    ) -> Self {
        assert!(dt > 0.0, "dt must be positive");
        let rot0 = rot_x(phi0.x) * rot_z(phi0.z) * rot_y(phi0.y);
        let ground0 = if params.follow_terrain && surface.exists() {
            surface.mean_height(r0.x, r0.z).0
        } else {
            0.0
        };
        let mut plan = Self {
            params: params.clone(),
            surface: surface.clone(),
            dt,
            table: Arc::new([]),
            r0,
            rot0,
            psi0: phi0.y,
            ground0,
            level: phi0.x == 0.0 && phi0.z == 0.0,
        };
        let n = if params.walking {
            (until.max(0.0) / dt).ceil() as usize + 2
        } else {
            1
        };
        let mut table = Vec::with_capacity(n);
        let mut y = [r0.x, r0.z, phi0.y];
        table.push(y);
        for k in 1..n {
            let t = (k - 1) as f64 * dt;
            let f = |t: f64, y: &[f64; 3]| plan.rates(t, y);
            let k1 = f(t, &y);
            let y2 = [0, 1, 2].map(|i| y[i] + 0.5 * dt * k1[i]);
            let k2 = f(t + 0.5 * dt, &y2);
            let y3 = [0, 1, 2].map(|i| y[i] + 0.5 * dt * k2[i]);
            let k3 = f(t + 0.5 * dt, &y3);
            let y4 = [0, 1, 2].map(|i| y[i] + dt * k3[i]);
            let k4 = f(t + dt, &y4);
            y = [0, 1, 2].map(|i| y[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
            table.push(y);
        }
        plan.table = table.into();
        plan
    }

    /// The parameters.
    pub fn params(&self) -> &GaitParams {
        &self.params
    }

    /// Start-up blend `s_on` and the full blend `s = s_on·s_off`, each with
    /// its two derivatives.
    #[inline]
    pub fn blends(&self, t: f64) -> ((f64, f64, f64), (f64, f64, f64)) {
        let p = &self.params;
        if !p.walking {
            return ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0));
        }
        let r = p.ramp;
        let on = if r > 0.0 {
            let (s, d, dd) = smoothstep(t / r);
            (s, d / r, dd / (r * r))
        } else {
            (1.0, 0.0, 0.0)
        };
        let off = if t >= p.walk_time {
            (0.0, 0.0, 0.0)
        } else if r > 0.0 {
            let (s, d, dd) = smoothstep((p.walk_time - t) / r);
            (s, -d / r, dd / (r * r))
        } else {
            (1.0, 0.0, 0.0)
        };
        let s = (
            on.0 * off.0,
            on.1 * off.0 + on.0 * off.1,
            on.2 * off.0 + 2.0 * on.1 * off.1 + on.0 * off.2,
        );
        (on, s)
    }

    /// The twist in the heading frame `(v_f, v_l, ω)` at `t` and its time
    /// derivative, blended.
    #[inline]
    fn twist(&self, t: f64) -> ([f64; 3], [f64; 3]) {
        let (_, s) = self.blends(t);
        let p = &self.params;
        let c = [p.forward.eval(t), p.lateral.eval(t), p.yaw_rate.eval(t)];
        (c.map(|(v, _)| s.0 * v), c.map(|(v, d)| s.1 * v + s.0 * d))
    }

    fn rates(&self, t: f64, y: &[f64; 3]) -> [f64; 3] {
        let (w, _) = self.twist(t);
        let (sn, cs) = y[2].sin_cos();
        [-w[0] * sn + w[1] * cs, -w[0] * cs - w[1] * sn, w[2]]
    }

    fn planar_derivatives(&self, t: f64, q: [f64; 3]) -> Planar {
        let (w, wd) = self.twist(t);
        let (sn, cs) = q[2].sin_cos();
        let psid = w[2];
        // d/dt of (−v_f·sinψ + v_l·cosψ, −v_f·cosψ − v_l·sinψ).
        let v = [-w[0] * sn + w[1] * cs, -w[0] * cs - w[1] * sn, psid];
        let a = [
            -wd[0] * sn + wd[1] * cs + psid * (-w[0] * cs - w[1] * sn),
            -wd[0] * cs - wd[1] * sn + psid * (w[0] * sn - w[1] * cs),
            wd[2],
        ];
        Planar { q, v, a }
    }

    /// The planar path at grid step `k` (exact table value).
    #[inline]
    pub fn planar_at_step(&self, k: usize) -> Planar {
        let q = self.table[k.min(self.table.len() - 1)];
        self.planar_derivatives(k as f64 * self.dt, q)
    }

    /// The planar path at any time `t ≥ 0` (Hermite interpolation between
    /// grid points; held after the end of the table).
    pub fn planar_at(&self, t: f64) -> Planar {
        let last = self.table.len() - 1;
        let x = (t / self.dt).max(0.0);
        let k = x.floor() as usize;
        if k >= last {
            return self.planar_derivatives(t, self.table[last]);
        }
        let u = x - k as f64;
        let (q0, q1) = (self.table[k], self.table[k + 1]);
        let v0 = self.rates(k as f64 * self.dt, &q0);
        let v1 = self.rates((k + 1) as f64 * self.dt, &q1);
        let (h00, h10, h01, h11) = (
            (1.0 + 2.0 * u) * (1.0 - u) * (1.0 - u),
            u * (1.0 - u) * (1.0 - u),
            u * u * (3.0 - 2.0 * u),
            u * u * (u - 1.0),
        );
        let q = [0, 1, 2]
            .map(|i| h00 * q0[i] + h10 * self.dt * v0[i] + h01 * q1[i] + h11 * self.dt * v1[i]);
        self.planar_derivatives(t, q)
    }

    /// The full body state at time `t` given its planar path `pl`.
    pub fn state(&self, t: f64, pl: &Planar) -> BodyState {
        let p = &self.params;
        let (on, s) = self.blends(t);
        let [x, z, psi] = pl.q;
        let [vx, vz, psid] = pl.v;
        let [ax, az, psidd] = pl.a;
        let (sn, cs) = psi.sin_cos();
        let fwd = Vector3::new(-sn, 0.0, -cs);
        let lat = Vector3::new(cs, 0.0, -sn);
        // Terrain following.
        let (mut gy, mut gyd, mut gydd) = (0.0, 0.0, 0.0);
        if p.follow_terrain && self.surface.exists() && p.walking {
            let (h, [gx, gz], _) = self.surface.mean_height(x, z);
            gy = h - self.ground0;
            gyd = gx * vx + gz * vz;
            gydd = gx * ax + gz * az + self.surface.mean_curvature(x, z, [vx, vz]);
        }
        // Sway σ = sway·s·sin(2πt/T) along l(ψ).
        let w = std::f64::consts::TAU / p.period;
        let (ss, sc) = if p.sway == 0.0 {
            (0.0, 1.0)
        } else {
            (w * t).sin_cos()
        };
        let sig = p.sway * s.0 * ss;
        let sigd = p.sway * (s.1 * ss + s.0 * w * sc);
        let sigdd = p.sway * (s.2 * ss + 2.0 * s.1 * w * sc - s.0 * w * w * ss);
        // l̇ = ψ̇·f, ḟ = −ψ̇·l.
        let sway = sig * lat;
        let swayd = sigd * lat + sig * psid * fwd;
        let swaydd =
            sigdd * lat + (2.0 * sigd * psid + sig * psidd) * fwd - sig * psid * psid * lat;
        let position = Vector3::new(x, self.r0.y + p.height * on.0 + gy, z) + sway;
        let velocity = Vector3::new(vx, p.height * on.1 + gyd, vz) + swayd;
        let acceleration = Vector3::new(ax, p.height * on.2 + gydd, az) + swaydd;
        // Rotation. A level start (φx = φz = 0) without roll or pitch is a
        // pure yaw: Rot = Ry(ψ), φ = (0, ψ, 0), no trigonometry left to do.
        let tilted = p.pitch != 0.0 || p.roll != 0.0;
        let level = !tilted && self.level;
        let m = if level {
            Matrix3::new(cs, 0.0, sn, 0.0, 1.0, 0.0, -sn, 0.0, cs)
        } else {
            rot_y(psi - self.psi0) * self.rot0
        };
        let (pt, ptd, ptdd) = (p.pitch * on.0, p.pitch * on.1, p.pitch * on.2);
        let (rt, rtd, rtdd) = (-p.roll * on.0, -p.roll * on.1, -p.roll * on.2);
        let rx = if tilted {
            rot_x(pt)
        } else {
            Matrix3::identity()
        };
        let rotation = if tilted { m * rx * rot_z(rt) } else { m };
        let y = Vector3::y();
        let xz = rx * Vector3::z();
        let inner = ptd * Vector3::x() + rtd * xz;
        let m_inner = m * inner;
        let omega = psid * y + m_inner;
        let inner_dot = ptdd * Vector3::x() + rtdd * xz + rtd * ptd * Vector3::x().cross(&xz);
        let omega_dot = psidd * y + psid * y.cross(&m_inner) + m * inner_dot;
        BodyState {
            position,
            velocity,
            acceleration,
            rotation,
            omega,
            omega_dot,
            phi: if level {
                Vector3::new(0.0, psi, 0.0)
            } else {
                phi_of(&rotation, psi)
            },
        }
    }

    /// Initial body centre.
    pub fn r0(&self) -> Vector3<f64> {
        self.r0
    }
}

/// `(φx, φy, φz)` with `Rot = Rx(φx)·Rz(φz)·Ry(φy)`, φy the branch nearest
/// `heading`.
pub fn phi_of(r: &Matrix3<f64>, heading: f64) -> Vector3<f64> {
    let pz = (-r[(0, 1)]).clamp(-1.0, 1.0).asin();
    let px = r[(2, 1)].atan2(r[(1, 1)]);
    let py = r[(0, 2)].atan2(r[(0, 0)]);
    let tau = std::f64::consts::TAU;
    let py = py + tau * ((heading - py) / tau).round();
    Vector3::new(px, py, pz)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gait::params::Command;

    fn plan(p: &GaitParams) -> BodyPlan {
        BodyPlan::new(
            p,
            &Surface::default(),
            Vector3::new(0.1, 0.4, -0.2),
            Vector3::new(0.05, 0.3, -0.02),
            1e-3,
            6.0,
        )
    }

    #[test]
    fn clones_share_the_integrated_path() {
        // A run clones its parameters into its model: the path, 24 bytes
        // a step, is stored once.
        let b = plan(&GaitParams::default());
        assert_eq!(b.table.len(), 6002);
        let c = b.clone();
        assert!(Arc::ptr_eq(&b.table, &c.table));
        assert_eq!(b, c);
    }

    #[test]
    fn constant_twist_is_an_arc() {
        let mut p = GaitParams {
            forward: Command::Constant(0.2),
            lateral: Command::Constant(0.05),
            yaw_rate: Command::Constant(0.4),
            ramp: 0.0,
            ..GaitParams::default()
        };
        p.walk_time = 10.0;
        let b = plan(&p);
        let t = 2.5;
        let pl = b.planar_at_step(2500);
        // Closed form: ψ = ψ0 + ωt; heading-frame velocity rotates.
        let (w, vf, vl) = (0.4f64, 0.2f64, 0.05f64);
        let psi0 = 0.3f64;
        let psi = psi0 + w * t;
        let x = 0.1 + (vf * (psi.cos() - psi0.cos()) + vl * (psi.sin() - psi0.sin())) / w;
        let z = -0.2 + (-vf * (psi.sin() - psi0.sin()) + vl * (psi.cos() - psi0.cos())) / w;
        assert!(
            (pl.q[0] - x).abs() < 1e-12 && (pl.q[1] - z).abs() < 1e-12,
            "{pl:?}"
        );
        assert!((pl.q[2] - psi).abs() < 1e-12);
    }

    #[test]
    fn level_yaw_fast_path_is_the_general_rotation() {
        let p = GaitParams {
            yaw_rate: Command::Constant(0.9),
            walk_time: 5.0,
            ..GaitParams::default()
        };
        let b = BodyPlan::new(
            &p,
            &Surface::default(),
            Vector3::new(0.0, 0.4, 0.0),
            Vector3::new(0.0, 2.9, 0.0),
            1e-3,
            6.0,
        );
        for k in [0, 1234, 4000] {
            let pl = b.planar_at_step(k);
            let st = b.state(k as f64 * 1e-3, &pl);
            let general = rot_y(pl.q[2] - 2.9) * rot_y(2.9);
            assert!((st.rotation - general).norm() < 1e-14);
            let phi = phi_of(&general, pl.q[2]);
            assert!((st.phi - phi).norm() < 1e-12, "{} vs {phi}", st.phi);
        }
    }

    #[test]
    fn derivatives_match_differences() {
        let p = GaitParams {
            forward: Command::Profile(vec![[0.0, 0.1], [2.0, 0.3]]),
            lateral: Command::Constant(-0.05),
            yaw_rate: Command::Constant(0.3),
            height: 0.03,
            roll: 0.1,
            pitch: -0.08,
            sway: 0.02,
            ramp: 1.0,
            walk_time: 4.0,
            ..GaitParams::default()
        };
        let b = plan(&p);
        let h = 1e-5;
        for t in [0.37, 0.81, 1.5, 3.3] {
            let s = |t: f64| b.state(t, &b.planar_at(t));
            let (m, c, pl) = (s(t - h), s(t), s(t + h));
            let v = (pl.position - m.position) / (2.0 * h);
            let a = (pl.velocity - m.velocity) / (2.0 * h);
            assert!(
                (v - c.velocity).norm() < 1e-6,
                "t {t}: {v} vs {}",
                c.velocity
            );
            assert!(
                (a - c.acceleration).norm() < 1e-5,
                "t {t}: {a} vs {}",
                c.acceleration
            );
            let rd = (pl.rotation - m.rotation) / (2.0 * h);
            let wx = rd * c.rotation.transpose();
            let w = Vector3::new(wx[(2, 1)], wx[(0, 2)], wx[(1, 0)]);
            assert!((w - c.omega).norm() < 1e-6, "t {t}: {w} vs {}", c.omega);
            let wd = (pl.omega - m.omega) / (2.0 * h);
            assert!(
                (wd - c.omega_dot).norm() < 1e-5,
                "t {t}: {wd} vs {}",
                c.omega_dot
            );
            let back = rot_x(c.phi.x) * rot_z(c.phi.z) * rot_y(c.phi.y);
            assert!((back - c.rotation).norm() < 1e-12);
        }
    }
}
