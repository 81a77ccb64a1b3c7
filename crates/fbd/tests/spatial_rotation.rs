//! The rotation scheme of the spatial FBD equations on a single free rigid
//! body: (a) second order, (b) the angular momentum exact to solver
//! tolerance, (c) the paper's central difference of the angle for a turn
//! about a fixed axis, and a body spinning near its intermediate principal
//! axis flipping as Euler's equations say (Dzhanibekov's effect), against
//! a fine Runge–Kutta solution of `I·ω̇ = −ω × I·ω`, `Ṙ = R·[ω]×`.

use fbd_dynamics::spatial::half_momentum;
use fbd_dynamics::spatial::so3::{exp, hat, right_jacobian};
use fbd_kinematics::nalgebra::{Matrix3, Vector3};

#[path = "../../../tests/common/readme.rs"]
mod readme;

fn inertia() -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(0.1, 0.2, 0.3))
}

/// One step of the scheme for a free body: `R[k+1]` from `R[k]` and the
/// conserved `L` (inertial): solves `exp(ψ/2)·I·ψ = Δt·R[k]ᵀ·L` by Newton.
fn step(r_k: &Matrix3<f64>, l: &Vector3<f64>, i: &Matrix3<f64>, dt: f64) -> Matrix3<f64> {
    let b = dt * r_k.transpose() * l;
    let mut psi = i.try_inverse().unwrap() * b;
    for _ in 0..50 {
        let ipsi = i * psi;
        let f = exp(&(0.5 * psi)) * ipsi - b;
        if f.norm() < 1e-15 * b.norm().max(1e-300) {
            break;
        }
        let jac = exp(&(0.5 * psi)) * (i - 0.5 * hat(&ipsi) * right_jacobian(&(0.5 * psi)));
        psi -= jac.try_inverse().unwrap() * f;
    }
    r_k * exp(&psi)
}

/// Runs the scheme from `R(0)`, body angular velocity `w0` for `n` steps
/// of `dt`, starting as the simulator does: `L[−½] = 2·L(0) − L[½]`, i.e.
/// `L[½] = L(0)` for a free body.
fn scheme(w0: &Vector3<f64>, dt: f64, n: usize) -> (Vec<Matrix3<f64>>, Vec<Vector3<f64>>) {
    let i = inertia();
    let mut r = Matrix3::identity();
    let l = r * i * w0;
    let mut rs = vec![r];
    let mut ls = Vec::new();
    for _ in 0..n {
        let next = step(&r, &l, &i, dt);
        ls.push(half_momentum(&r, &next, &i, dt).0);
        r = next;
        rs.push(r);
    }
    (rs, ls)
}

/// Classical RK4 of Euler's equations and the attitude, body frame.
fn rk4(w0: &Vector3<f64>, t_end: f64, n: usize) -> Vec<(Matrix3<f64>, Vector3<f64>)> {
    let i = inertia();
    let ii = i.try_inverse().unwrap();
    let f = |r: &Matrix3<f64>, w: &Vector3<f64>| (r * hat(w), ii * (-w.cross(&(i * w))));
    let h = t_end / n as f64;
    let (mut r, mut w) = (Matrix3::identity(), *w0);
    let mut out = vec![(r, w)];
    for _ in 0..n {
        let (a1, b1) = f(&r, &w);
        let (a2, b2) = f(&(r + 0.5 * h * a1), &(w + 0.5 * h * b1));
        let (a3, b3) = f(&(r + 0.5 * h * a2), &(w + 0.5 * h * b2));
        let (a4, b4) = f(&(r + h * a3), &(w + h * b3));
        r += h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
        w += h / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4);
        // Re-orthonormalise (RK4 drifts off SO(3) by O(h⁴)).
        let svd = r.svd(true, true);
        r = svd.u.unwrap() * svd.v_t.unwrap();
        out.push((r, w));
    }
    out
}

#[test]
fn angular_momentum_is_exact() {
    let w0 = Vector3::new(0.4, 5.0, 0.3);
    let (_, ls) = scheme(&w0, 0.01, 2000);
    let l0 = ls[0];
    let worst = ls.iter().map(|l| (l - l0).norm()).fold(0.0, f64::max);
    assert!(
        worst < 1e-12 * l0.norm(),
        "angular momentum drifts by {worst:e}"
    );
}

#[test]
fn fixed_axis_is_the_central_difference_of_the_angle() {
    // Turns about a fixed (non-principal) axis e, angle φ(t) arbitrary.
    let i = Matrix3::new(0.3, 0.02, -0.01, 0.02, 0.2, 0.03, -0.01, 0.03, 0.1);
    let e = Vector3::new(0.3, -0.5, 0.8).normalize();
    let phi = [0.10, 0.13, 0.171, 0.2];
    let r = phi.map(|p| exp(&(p * e)));
    let dt = 0.01;
    let l1 = half_momentum(&r[0], &r[1], &i, dt).0;
    let l2 = half_momentum(&r[1], &r[2], &i, dt).0;
    let lhs = e.dot(&(l2 - l1)) / dt;
    let iee = e.dot(&(i * e));
    let rhs = iee * (phi[2] - 2.0 * phi[1] + phi[0]) / (dt * dt);
    assert!((lhs - rhs).abs() < 1e-10 * rhs.abs(), "{lhs} vs {rhs}");
}

#[test]
fn second_order_against_euler_equations() {
    let w0 = Vector3::new(1.0, 2.0, -1.5);
    let t = 1.0;
    let reference = rk4(&w0, t, 100_000).last().unwrap().0;
    let err = |n: usize| {
        let (rs, _) = scheme(&w0, t / n as f64, n);
        (rs[n] - reference).norm()
    };
    let (e1, e2, e3) = (err(100), err(200), err(400));
    let (p1, p2) = ((e1 / e2).log2(), (e2 / e3).log2());
    println!("errors {e1:.3e} {e2:.3e} {e3:.3e}, orders {p1:.3} {p2:.3}");
    // The README's figure (the single free body: after the `;`).
    let row = readme::doc("README.md").row("order of convergence (whole robot; single free body)");
    let quoted = row[1]
        .split(';')
        .nth(1)
        .unwrap_or_default()
        .trim()
        .to_owned();
    assert!(
        quoted == format!("{p1:.3}") || quoted == format!("{p2:.3}"),
        "README.md is stale: quotes {quoted}, the orders are {p1:.3} {p2:.3}"
    );
    assert!(
        (1.9..2.1).contains(&p1) && (1.9..2.1).contains(&p2),
        "orders {p1} {p2}"
    );
}

#[test]
fn spinning_near_the_intermediate_axis_flips() {
    // Mostly about the intermediate axis (y), a small perturbation.
    let w0 = Vector3::new(0.01, 4.0, 0.0);
    let (t_end, n) = (12.0, 12_000);
    let (rs, _) = scheme(&w0, t_end / n as f64, n);
    let ref_run = rk4(&w0, t_end, 240_000);
    let i = inertia();
    // Body-frame y component of the angular velocity from the momentum:
    // ω_b = I⁻¹·Rᵀ·L, L conserved.
    let l = i * w0;
    let wy: Vec<f64> = rs
        .iter()
        .map(|r| (i.try_inverse().unwrap() * r.transpose() * l).y)
        .collect();
    let first_flip = |w: &[f64], dt: f64| w.iter().position(|v| *v < 0.0).map(|k| k as f64 * dt);
    let t_scheme = first_flip(&wy, t_end / n as f64).expect("the scheme flips");
    let wy_ref: Vec<f64> = ref_run.iter().map(|(_, w)| w.y).collect();
    let t_ref = first_flip(&wy_ref, t_end / 240_000.0).expect("Euler's equations flip");
    println!("first flip: scheme {t_scheme:.4} s, Runge–Kutta {t_ref:.4} s");
    let readme = readme::doc("README.md");
    readme.figure(
        "first flip | ",
        " s (Runge–Kutta",
        t_scheme,
        "first flip, scheme",
    );
    readme.figure("(Runge–Kutta: ", " s) |", t_ref, "first flip, Runge–Kutta");
    assert!(
        (t_scheme - t_ref).abs() < 0.01 * t_ref,
        "{t_scheme} vs {t_ref}"
    );
    // And it flips back: ω_y returns positive.
    let back = wy.iter().skip_while(|v| **v > 0.0).position(|v| *v > 0.0);
    assert!(back.is_some(), "the spin flips back");
}
