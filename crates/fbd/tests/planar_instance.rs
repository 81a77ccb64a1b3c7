//! The paper's planar model as an instance of the generic robot model in
//! the plane (`fbd_robot::dh::planar` stepped through
//! `Mechanism::in_plane`) is the two-leg mechanism (`Mechanism::two_leg`)
//! to the bit: the same bodies (masses, inertias, rotation versors),
//! joints, contact points in the same order, and at random configurations
//! the same positions of every joint, contact point and centre of mass and
//! the same body angles, bit for bit; and a robot that leaves the plane is
//! refused.

use fbd_dynamics::mechanism::ContactPoints;
use fbd_dynamics::{Mechanism, TwoLegInertia};
use fbd_kinematics::planar::PlanarGeometry;
use fbd_robot::dh::{PlanarMasses, planar};
use fbd_robot::nalgebra::Vector3;

fn pair(points: ContactPoints) -> (Mechanism, Mechanism) {
    let g = PlanarGeometry {
        d: 0.27 * (std::f64::consts::PI / 6.0).cos(),
        a: 0.21,
        c: 0.43,
        upper_com: 0.45,
        lower_com: 0.7,
    };
    let inertia = TwoLegInertia {
        body_mass: 9.5,
        body_inertia: 0.17,
        upper_mass: 0.35,
        upper_inertia: 0.0021,
        lower_mass: 1.2,
        lower_inertia: 0.019,
    };
    let (two_leg, _) = Mechanism::two_leg(&g, &inertia, 9.81, points);
    let robot = planar(
        &g,
        &PlanarMasses {
            body_mass: inertia.body_mass,
            body_inertia: inertia.body_inertia,
            upper_mass: inertia.upper_mass,
            upper_inertia: inertia.upper_inertia,
            lower_mass: inertia.lower_mass,
            lower_inertia: inertia.lower_inertia,
        },
    );
    let contacts: Vec<usize> = fbd_dynamics::tree::contacts_by_kind(&robot)
        .into_iter()
        .filter(|&c| {
            let name = &robot.contacts[c].name;
            (points.tips && name.starts_with("tip"))
                || (points.knees && name.starts_with("knee"))
                || (points.hips && name.starts_with("hip"))
        })
        .collect();
    let generic = Mechanism::in_plane(&robot, &contacts, 9.81).expect("in the plane");
    (two_leg, generic)
}

#[test]
fn the_planar_instance_is_the_two_leg_mechanism_to_the_bit() {
    for points in [
        ContactPoints::default(),
        ContactPoints {
            tips: true,
            knees: false,
            hips: false,
        },
    ] {
        let (a, b) = pair(points);
        assert_eq!(a.layout(), b.layout());
        assert_eq!(a.total_mass().to_bits(), b.total_mass().to_bits());
        assert_eq!(a.length_scale().to_bits(), b.length_scale().to_bits());
        for (x, y) in a.bodies.iter().zip(&b.bodies) {
            assert_eq!(
                (&x.name, x.mass, x.inertia, x.versor_z),
                (&y.name, y.mass, y.inertia, y.versor_z)
            );
        }
        for (x, y) in a.joints.iter().zip(&b.joints) {
            assert_eq!(
                (
                    &x.name, x.parent, x.child, x.axis_z, x.q_index, x.leg, x.joint
                ),
                (
                    &y.name, y.parent, y.child, y.axis_z, y.q_index, y.leg, y.joint
                )
            );
        }
        for (x, y) in a.contacts.iter().zip(&b.contacts) {
            assert_eq!(
                (&x.name, x.leg, x.kind, x.body),
                (&y.name, y.leg, y.kind, y.body)
            );
        }
        let (mut ka, mut kb) = (a.chains.new_data(), b.chains.new_data());
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..200 {
            let q: Vec<f64> = (0..7)
                .map(|_| {
                    seed ^= seed << 13;
                    seed ^= seed >> 7;
                    seed ^= seed << 17;
                    8.0 * ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5)
                })
                .collect();
            a.chains.eval_positions(&q, &mut ka);
            b.chains.eval_positions(&q, &mut kb);
            let same = |p: usize, r: usize, what: &str| {
                assert_eq!(
                    ka.pos[p].map(f64::to_bits),
                    kb.pos[r].map(f64::to_bits),
                    "{what} at {q:?}"
                );
            };
            for (x, y) in a.bodies.iter().zip(&b.bodies) {
                same(x.com, y.com, &format!("{}'s centre of mass", x.name));
                assert_eq!(
                    ka.angle[x.angle].to_bits(),
                    kb.angle[y.angle].to_bits(),
                    "{}'s angle",
                    x.name
                );
            }
            for (x, y) in a.joints.iter().zip(&b.joints) {
                same(x.point, y.point, &x.name);
            }
            for (x, y) in a.contacts.iter().zip(&b.contacts) {
                same(x.point, y.point, &x.name);
            }
        }
    }
}

#[test]
fn a_robot_off_the_plane_is_refused() {
    let g = PlanarGeometry::default();
    let masses = PlanarMasses {
        body_mass: 10.0,
        body_inertia: 0.2,
        upper_mass: 0.3,
        upper_inertia: 0.001,
        lower_mass: 1.1,
        lower_inertia: 0.016,
    };
    let mut robot = planar(&g, &masses);
    robot.contacts[0].position.z = 0.01;
    let e = Mechanism::in_plane(&robot, &[0], 9.81).unwrap_err();
    assert!(e.contains("tip3") && e.contains("off the plane"), "{e}");
    let mut robot = planar(&g, &masses);
    robot.joints[1].axis = fbd_robot::nalgebra::Unit::new_normalize(Vector3::new(0.0, 1.0, 0.0));
    let e = Mechanism::in_plane(&robot, &[0], 9.81).unwrap_err();
    assert!(e.contains("knee3") && e.contains("not along Z"), "{e}");
}
