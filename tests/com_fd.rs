//! The centre of mass against the potential energy and the 2R arm's closed form, and its
//! Jacobian against central finite differences of the centre of mass, on every model of
//! `common::test_models` (the robots in `robots/`, the mimic gripper, a long chain).

mod common;

use armsim::core::spatial::Vec3;
use armsim::dynamics;
use armsim::model::data::Data;
use common::{load, test_models};
use nalgebra::DMatrix;
use rand::rngs::SmallRng;
use rand::SeedableRng;

const H: f64 = 1e-6;

#[test]
fn com_weights_the_potential_energy() {
    // V(g) = −M gᵀ c for every g: the unit vectors read c off V, which potential_energy
    // computes body by body without the centre of mass.
    let mut checked = 0;
    for (name, m) in test_models(12) {
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(3);
        let total = dynamics::total_mass(&m);
        if total == 0.0 {
            // A kinematic-only model (no inertials): no centre of mass.
            assert_eq!(
                dynamics::center_of_mass(&m, &mut d, &m.neutral()),
                None,
                "{name}"
            );
            continue;
        }
        checked += 1;
        for _ in 0..4 {
            let q = m.random_q(&mut rng);
            let c = dynamics::center_of_mass(&m, &mut d, &q).expect("a massive model");
            for (k, e) in [Vec3::x(), Vec3::y(), Vec3::z()].iter().enumerate() {
                let v = dynamics::potential_energy(&m, &mut d, &q, e);
                let want = -v / total;
                assert!(
                    (c[k] - want).abs() <= 1e-12 * (1.0 + want.abs()),
                    "{name}: c[{k}] = {} vs -V/M = {want}",
                    c[k]
                );
            }
        }
    }
    assert!(checked >= 5, "{checked} models with mass");
}

#[test]
fn com_of_the_2r_arm_is_the_closed_form() {
    // robots/planar_2r.toml: uniform 0.5 m links of 2 kg and 1 kg in the x-z plane.
    let m = load("robots/planar_2r.toml");
    let mut d = Data::new(&m);
    let (l, m1, m2) = (0.5, 2.0, 1.0);
    for q in [[0.0, 0.0], [0.3, -1.1], [2.0, 0.7]] {
        let c = dynamics::center_of_mass(&m, &mut d, &q).unwrap();
        let (a, b) = (q[0], q[0] + q[1]);
        let x = (m1 * l / 2.0 * a.cos() + m2 * (l * a.cos() + l / 2.0 * b.cos())) / (m1 + m2);
        let z = (m1 * l / 2.0 * a.sin() + m2 * (l * a.sin() + l / 2.0 * b.sin())) / (m1 + m2);
        assert!((c - Vec3::new(x, 0.0, z)).abs().max() < 1e-12, "{q:?}: {c}");
        // dc/dq1 for the second column: only the 1 kg link turns.
        let mut j = DMatrix::zeros(3, 2);
        dynamics::jacobian_center_of_mass(&m, &mut d, &q, &mut j).unwrap();
        let dx2 = -m2 * l / 2.0 * b.sin() / (m1 + m2);
        assert!((j[(0, 1)] - dx2).abs() < 1e-12, "{q:?}: J = {j}");
    }
}

#[test]
fn com_jacobian_matches_finite_differences() {
    for (name, m) in test_models(12) {
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(11);
        let mut j = DMatrix::zeros(3, m.nv);
        if dynamics::total_mass(&m) == 0.0 {
            continue;
        }
        for _ in 0..4 {
            let q = m.random_q(&mut rng);
            let c = dynamics::jacobian_center_of_mass(&m, &mut d, &q, &mut j).unwrap();
            let c0 = dynamics::center_of_mass(&m, &mut d, &q).unwrap();
            assert_eq!(c, c0, "{name}: the Jacobian's centre of mass");
            for k in 0..m.nv {
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[k] += H;
                qm[k] -= H;
                let cp = dynamics::center_of_mass(&m, &mut d, &qp).unwrap();
                let cm = dynamics::center_of_mass(&m, &mut d, &qm).unwrap();
                let fd = (cp - cm) / (2.0 * H);
                for r in 0..3 {
                    let err = (j[(r, k)] - fd[r]).abs();
                    assert!(
                        err < 1e-7,
                        "{name}: J[{r},{k}] = {} vs FD {}",
                        j[(r, k)],
                        fd[r]
                    );
                }
            }
        }
    }
}

#[test]
fn a_massless_model_has_no_centre_of_mass() {
    let mut m = load("robots/planar_2r.toml");
    for b in m.inertia.iter_mut() {
        b.mass = 0.0;
    }
    let mut d = Data::new(&m);
    let mut j = DMatrix::from_element(3, 2, 7.0);
    assert_eq!(dynamics::center_of_mass(&m, &mut d, &[0.1, 0.2]), None);
    assert_eq!(
        dynamics::jacobian_center_of_mass(&m, &mut d, &[0.1, 0.2], &mut j),
        None
    );
    assert!(j.iter().all(|x| *x == 0.0));
}
