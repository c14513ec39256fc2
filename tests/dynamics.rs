//! Dynamics cross-checks on every robot in `robots/`: RNEA = M q̈ + h, CRBA columns from
//! RNEA, ABA(RNEA(q̈)) = q̈, CRBA+Cholesky = ABA, and the planar 2R arm's closed form.

mod common;

use armsim::data::Data;
use armsim::dynamics;
use armsim::model::Model;
use armsim::spatial::Vec3;
use rand::rngs::SmallRng;
use rand::SeedableRng;

fn models() -> Vec<(String, Model)> {
    common::test_models(50)
}

/// `‖a − b‖∞ ≤ tol · max(1, ‖b‖∞)`.
fn close(a: &[f64], b: &[f64], tol: f64) -> Result<(), String> {
    let scale = b.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    let err = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    if err <= tol * scale {
        Ok(())
    } else {
        Err(format!("error {err:e} > {tol:e} × {scale:e}\n{a:?}\n{b:?}"))
    }
}

#[test]
fn rnea_equals_mass_matrix_times_acceleration_plus_bias() {
    let g = Vec3::new(0.0, 0.0, -9.81);
    for (name, m) in models() {
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(11);
        for _ in 0..20 {
            let q = m.random_q(&mut rng);
            let qd = common::rand_vec(&mut rng, m.nv, 2.0);
            let qdd = common::rand_vec(&mut rng, m.nv, 5.0);
            let tau = dynamics::rnea(&m, &mut d, &q, &qd, &qdd, &g, None).to_vec();
            let h = dynamics::bias(&m, &mut d, &q, &qd, &g).to_vec();
            let mass = dynamics::crba(&m, &mut d, &q).clone();
            let mq: Vec<f64> = (0..m.nv)
                .map(|i| (0..m.nv).map(|j| mass[(i, j)] * qdd[j]).sum::<f64>() + h[i])
                .collect();
            close(&tau, &mq, 1e-9).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(
                (&mass - mass.transpose()).abs().max() == 0.0,
                "{name}: M symmetric"
            );
        }
    }
}

#[test]
fn crba_columns_equal_rnea_differences_without_gravity() {
    let zero_g = Vec3::zeros();
    for (name, m) in models() {
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(12);
        for _ in 0..5 {
            let q = m.random_q(&mut rng);
            let z = vec![0.0; m.nv];
            let mass = dynamics::crba(&m, &mut d, &q).clone();
            let base = dynamics::rnea(&m, &mut d, &q, &z, &z, &zero_g, None).to_vec();
            for i in 0..m.nv {
                let mut e = z.clone();
                e[i] = 1.0;
                let col = dynamics::rnea(&m, &mut d, &q, &z, &e, &zero_g, None).to_vec();
                for r in 0..m.nv {
                    let diff = col[r] - base[r];
                    assert!(
                        (mass[(r, i)] - diff).abs() <= 1e-12 * mass.abs().max().max(1.0),
                        "{name}: M[{r},{i}] {} vs {diff}",
                        mass[(r, i)]
                    );
                }
            }
        }
    }
}

#[test]
fn aba_inverts_rnea_and_agrees_with_crba_cholesky() {
    let g = Vec3::new(0.0, 0.0, -9.81);
    for (name, m) in models() {
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(13);
        for _ in 0..20 {
            let q = m.random_q(&mut rng);
            let qd = common::rand_vec(&mut rng, m.nv, 2.0);
            let qdd = common::rand_vec(&mut rng, m.nv, 5.0);
            let tau = dynamics::rnea(&m, &mut d, &q, &qd, &qdd, &g, None).to_vec();
            let Ok(chol) =
                dynamics::forward_dynamics_crba(&m, &mut d, &q, &qd, &tau, &g).map(|x| x.to_vec())
            else {
                // Massless coordinates (kinematics-only models) have no forward dynamics.
                assert!(
                    m.inertia.iter().any(|i| i.mass == 0.0),
                    "{name}: singular M with all bodies massive"
                );
                break;
            };
            close(&chol, &qdd, 1e-8).unwrap_or_else(|e| panic!("{name} CRBA+Cholesky: {e}"));
            if !m.has_mimic {
                let a = dynamics::aba(&m, &mut d, &q, &qd, &tau, &g, None).to_vec();
                close(&a, &qdd, 1e-10).unwrap_or_else(|e| panic!("{name} ABA: {e}"));
            }
        }
    }
}

#[test]
fn planar_2r_matches_the_textbook_closed_form() {
    let m = common::load("robots/planar_2r.toml");
    let (l, m1, m2, g) = (0.5f64, 2.0f64, 1.0f64, 9.81f64);
    let mut d = Data::new(&m);
    let mut rng = SmallRng::seed_from_u64(14);
    let grav = Vec3::new(0.0, 0.0, -g);
    for _ in 0..100 {
        let q = common::rand_vec(&mut rng, 2, 3.1);
        let qd = common::rand_vec(&mut rng, 2, 3.0);
        let qdd = common::rand_vec(&mut rng, 2, 5.0);
        let (c2, s2) = (q[1].cos(), q[1].sin());
        let m11 = m1 * l * l / 3.0 + m2 * l * l * (4.0 / 3.0 + c2);
        let m12 = m2 * l * l * (1.0 / 3.0 + c2 / 2.0);
        let m22 = m2 * l * l / 3.0;
        let h1 = -m2 * l * l * s2 * (qd[0] * qd[1] + qd[1] * qd[1] / 2.0);
        let h2 = m2 * l * l * s2 * qd[0] * qd[0] / 2.0;
        let g1 = (m1 / 2.0 + m2) * g * l * q[0].cos() + m2 / 2.0 * g * l * (q[0] + q[1]).cos();
        let g2 = m2 / 2.0 * g * l * (q[0] + q[1]).cos();
        let expect = [
            m11 * qdd[0] + m12 * qdd[1] + h1 + g1,
            m12 * qdd[0] + m22 * qdd[1] + h2 + g2,
        ];
        let tau = dynamics::rnea(&m, &mut d, &q, &qd, &qdd, &grav, None).to_vec();
        for k in 0..2 {
            assert!(
                (tau[k] - expect[k]).abs() < 1e-12,
                "tau {tau:?} vs {expect:?}"
            );
        }
        let mass = dynamics::crba(&m, &mut d, &q);
        assert!(
            (mass[(0, 0)] - m11).abs() < 1e-14
                && (mass[(0, 1)] - m12).abs() < 1e-14
                && (mass[(1, 1)] - m22).abs() < 1e-14
        );
    }
}

#[test]
fn energy_rate_equals_power_and_potential_matches_gravity_torque() {
    // dT/dt along (q, q̇, q̈) equals q̇ᵀ(τ − g(q)) with τ = RNEA; and g = ∂V/∂q.
    let grav = Vec3::new(0.0, 0.0, -9.81);
    for (name, m) in models() {
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(15);
        let q = m.random_q(&mut rng);
        let qd = common::rand_vec(&mut rng, m.nv, 1.0);
        let qdd = common::rand_vec(&mut rng, m.nv, 1.0);
        let h = 1e-6;
        let at = |s: f64, d: &mut Data| {
            let qs: Vec<f64> = (0..m.nv)
                .map(|k| q[k] + s * qd[k] + 0.5 * s * s * qdd[k])
                .collect();
            let qds: Vec<f64> = (0..m.nv).map(|k| qd[k] + s * qdd[k]).collect();
            dynamics::kinetic_energy(&m, d, &qs, &qds)
                + dynamics::potential_energy(&m, d, &qs, &grav)
        };
        let de = (at(h, &mut d) - at(-h, &mut d)) / (2.0 * h);
        let tau = dynamics::rnea(&m, &mut d, &q, &qd, &qdd, &grav, None).to_vec();
        let power: f64 = tau.iter().zip(&qd).map(|(t, v)| t * v).sum();
        assert!(
            (de - power).abs() <= 1e-6 * power.abs().max(1.0),
            "{name}: dE/dt {de} vs power {power}"
        );
    }
}

#[test]
fn kinetic_energy_gradient_matches_central_differences() {
    // ∂T/∂q at fixed q̇ against (T(q + ε e_k) − T(q − ε e_k)) / 2ε: truncation O(ε²),
    // rounding O(eps T / ε); with ε = 1e-5 both are ~1e-10 of the scale.
    for (name, m) in models() {
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(15);
        for _ in 0..5 {
            let q = m.random_q(&mut rng);
            let qd = common::rand_vec(&mut rng, m.nv, 2.0);
            let grad = dynamics::kinetic_energy_gradient(&m, &mut d, &q, &qd).to_vec();
            let eps = 1e-5;
            let fd: Vec<f64> = (0..m.nv)
                .map(|k| {
                    let (mut a, mut b) = (q.clone(), q.clone());
                    a[k] += eps;
                    b[k] -= eps;
                    (dynamics::kinetic_energy(&m, &mut d, &a, &qd)
                        - dynamics::kinetic_energy(&m, &mut d, &b, &qd))
                        / (2.0 * eps)
                })
                .collect();
            let t = dynamics::kinetic_energy(&m, &mut d, &q, &qd);
            let err = grad
                .iter()
                .zip(&fd)
                .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
            assert!(
                err <= 1e-8 * t.max(1.0),
                "{name}: ∂T/∂q off by {err:e} (T = {t:e})\n{grad:?}\n{fd:?}"
            );
        }
    }
}
