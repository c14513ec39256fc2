//! Dynamics cross-checks on every robot in `robots/`: RNEA = M q̈ + h, CRBA columns from
//! RNEA, ABA(RNEA(q̈)) = q̈, CRBA+Cholesky = ABA, and the planar 2R arm's closed form.

mod common;

use armsim::core::spatial::Vec3;
use armsim::dynamics;
use armsim::model::data::Data;
use armsim::model::Model;
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
    for (name, mut m) in models() {
        m.gravity = Vec3::new(0.0, 0.0, -9.81);
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(11);
        for _ in 0..20 {
            let q = m.random_q(&mut rng);
            let qd = common::rand_vec(&mut rng, m.nv, 2.0);
            let qdd = common::rand_vec(&mut rng, m.nv, 5.0);
            let tau = dynamics::rnea(&m, &mut d, &q, &qd, &qdd).to_vec();
            let h = dynamics::bias(&m, &mut d, &q, &qd).to_vec();
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
    for (name, mut m) in models() {
        m.gravity = Vec3::zeros();
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(12);
        for _ in 0..5 {
            let q = m.random_q(&mut rng);
            let z = vec![0.0; m.nv];
            let mass = dynamics::crba(&m, &mut d, &q).clone();
            let base = dynamics::rnea(&m, &mut d, &q, &z, &z).to_vec();
            for i in 0..m.nv {
                let mut e = z.clone();
                e[i] = 1.0;
                let col = dynamics::rnea(&m, &mut d, &q, &z, &e).to_vec();
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
    for (name, mut m) in models() {
        m.gravity = Vec3::new(0.0, 0.0, -9.81);
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(13);
        for _ in 0..20 {
            let q = m.random_q(&mut rng);
            let qd = common::rand_vec(&mut rng, m.nv, 2.0);
            let qdd = common::rand_vec(&mut rng, m.nv, 5.0);
            let tau = dynamics::rnea(&m, &mut d, &q, &qd, &qdd).to_vec();
            let Ok(chol) =
                dynamics::forward_dynamics_crba(&m, &mut d, &q, &qd, &tau).map(|x| x.to_vec())
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
                let a = dynamics::aba(&m, &mut d, &q, &qd, &tau).to_vec();
                close(&a, &qdd, 1e-10).unwrap_or_else(|e| panic!("{name} ABA: {e}"));
            }
        }
    }
}

#[test]
fn planar_2r_matches_the_textbook_closed_form() {
    let mut m = common::load("robots/planar_2r.toml");
    let g = 9.81f64;
    m.gravity = Vec3::new(0.0, 0.0, -g);
    let mut d = Data::new(&m);
    let mut rng = SmallRng::seed_from_u64(14);
    for _ in 0..100 {
        let q = common::rand_vec(&mut rng, 2, 3.1);
        let qd = common::rand_vec(&mut rng, 2, 3.0);
        let qdd = common::rand_vec(&mut rng, 2, 5.0);
        let ([m11, m12, m22], expect) = common::planar_2r_closed_form(&q, &qd, &qdd);
        let tau = dynamics::rnea(&m, &mut d, &q, &qd, &qdd).to_vec();
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
    for (name, mut m) in models() {
        m.gravity = grav;
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
        let tau = dynamics::rnea(&m, &mut d, &q, &qd, &qdd).to_vec();
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

#[test]
fn gravity_comes_from_the_model_and_enters_linearly() {
    // g(q) = RNEA(q, 0, 0); τ(q, q̇, q̈) with gravity = τ without + g(q); g(q) is linear
    // in the gravity vector (sum of two gravities, a scaled one, none).
    let (ga, gb) = (Vec3::new(0.0, 0.0, -9.81), Vec3::new(1.3, -0.4, 0.2));
    for (name, mut m) in models() {
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(16);
        let q = m.random_q(&mut rng);
        let qd = common::rand_vec(&mut rng, m.nv, 2.0);
        let qdd = common::rand_vec(&mut rng, m.nv, 5.0);
        let z = vec![0.0; m.nv];
        m.gravity = ga;
        let g_a = dynamics::gravity_torque(&m, &mut d, &q).to_vec();
        assert_eq!(g_a, dynamics::rnea(&m, &mut d, &q, &z, &z), "{name}");
        let full = dynamics::rnea(&m, &mut d, &q, &qd, &qdd).to_vec();
        m.gravity = gb;
        let g_b = dynamics::gravity_torque(&m, &mut d, &q).to_vec();
        m.gravity = ga + gb;
        let g_ab = dynamics::gravity_torque(&m, &mut d, &q).to_vec();
        let sum: Vec<f64> = g_a.iter().zip(&g_b).map(|(a, b)| a + b).collect();
        close(&g_ab, &sum, 1e-12).unwrap_or_else(|e| panic!("{name} g(a + b): {e}"));
        m.gravity = ga * 2.5;
        let scaled: Vec<f64> = g_a.iter().map(|x| 2.5 * x).collect();
        close(dynamics::gravity_torque(&m, &mut d, &q), &scaled, 1e-12)
            .unwrap_or_else(|e| panic!("{name} g(2.5 a): {e}"));
        m.gravity = Vec3::zeros();
        assert!(dynamics::gravity_torque(&m, &mut d, &q)
            .iter()
            .all(|t| *t == 0.0));
        let without = dynamics::rnea(&m, &mut d, &q, &qd, &qdd).to_vec();
        let with: Vec<f64> = without.iter().zip(&g_a).map(|(a, b)| a + b).collect();
        close(&full, &with, 1e-9).unwrap_or_else(|e| panic!("{name} τ = τ₀ + g: {e}"));
    }
}

#[test]
fn planar_2r_gravity_torque_follows_the_closed_form_for_any_model_gravity() {
    // g₁ = (m₁/2 + m₂) g l cos q₁ + m₂/2 g l cos(q₁ + q₂), g₂ = m₂/2 g l cos(q₁ + q₂)
    // for gravity (0, 0, −g) in the arm's plane.
    let mut m = common::load("robots/planar_2r.toml");
    let (l, m1, m2) = (0.5f64, 2.0f64, 1.0f64);
    let mut d = Data::new(&m);
    let q = [0.4f64, -1.1];
    for g in [9.81, 1.62, 0.0, -3.0] {
        m.gravity = Vec3::new(0.0, 0.0, -g);
        let c1 = q[0].cos();
        let c12 = (q[0] + q[1]).cos();
        let expect = [
            (m1 / 2.0 + m2) * g * l * c1 + m2 / 2.0 * g * l * c12,
            m2 / 2.0 * g * l * c12,
        ];
        let tau = dynamics::gravity_torque(&m, &mut d, &q);
        for k in 0..2 {
            assert!(
                (tau[k] - expect[k]).abs() < 1e-12,
                "g = {g}: {tau:?} vs {expect:?}"
            );
        }
    }
}

#[test]
fn armature_adds_to_rnea_the_mass_diagonal_and_aba_agrees_with_crba_cholesky() {
    for (name, mut m) in models() {
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(17);
        let q = m.random_q(&mut rng);
        let qd = common::rand_vec(&mut rng, m.nv, 2.0);
        let qdd = common::rand_vec(&mut rng, m.nv, 5.0);
        assert!(
            m.armature.iter().all(|a| *a == 0.0),
            "{name}: loads with none"
        );
        let tau0 = dynamics::rnea(&m, &mut d, &q, &qd, &qdd).to_vec();
        let mass0 = dynamics::crba(&m, &mut d, &q).clone();
        let ke0 = dynamics::kinetic_energy(&m, &mut d, &q, &qd);
        m.armature = (0..m.nv).map(|k| 0.05 + 0.1 * k as f64).collect();
        let tau = dynamics::rnea(&m, &mut d, &q, &qd, &qdd).to_vec();
        let mass = dynamics::crba(&m, &mut d, &q).clone();
        for k in 0..m.nv {
            let ia = m.armature[k];
            let dt = tau[k] - tau0[k];
            assert!(
                (dt - ia * qdd[k]).abs() <= 1e-12 * tau0[k].abs().max(1.0),
                "{name}: τ[{k}] grew by {dt}, expected {}",
                ia * qdd[k]
            );
            for j in 0..m.nv {
                let expect = if j == k { ia } else { 0.0 };
                let dm = mass[(k, j)] - mass0[(k, j)];
                assert!(
                    (dm - expect).abs() <= 1e-14 * mass0[(k, j)].abs().max(1.0),
                    "{name}: M[{k},{j}] grew by {dm}, expected {expect}"
                );
            }
        }
        // T = ½ q̇ᵀ M q̇ with the armature on the diagonal.
        let extra: f64 = (0..m.nv).map(|k| 0.5 * m.armature[k] * qd[k] * qd[k]).sum();
        let ke = dynamics::kinetic_energy(&m, &mut d, &q, &qd);
        assert!((ke - ke0 - extra).abs() <= 1e-12 * ke.max(1.0), "{name}: T");
        // CRBA + Cholesky inverts RNEA with armature, and ABA agrees with it.
        let Ok(chol) =
            dynamics::forward_dynamics_crba(&m, &mut d, &q, &qd, &tau).map(|x| x.to_vec())
        else {
            assert!(
                m.inertia.iter().any(|i| i.mass == 0.0),
                "{name}: singular M"
            );
            continue;
        };
        close(&chol, &qdd, 1e-8).unwrap_or_else(|e| panic!("{name} CRBA+Cholesky: {e}"));
        let fd = dynamics::forward_dynamics(&m, &mut d, &q, &qd, &tau)
            .unwrap()
            .to_vec();
        if !m.has_mimic {
            let a = dynamics::aba(&m, &mut d, &q, &qd, &tau).to_vec();
            close(&a, &chol, 1e-10).unwrap_or_else(|e| panic!("{name} ABA vs CRBA: {e}"));
            assert_eq!(fd, a, "{name}: the dispatcher runs ABA");
        } else {
            assert_eq!(
                fd, chol,
                "{name}: the dispatcher runs CRBA with mimic joints"
            );
        }
    }
}

#[test]
fn rotor_effect_adds_on_top_of_the_model_armature_and_is_counted_once() {
    // PUMA 560's file gives motor inertias and gear ratios: they feed the Rotor effect,
    // not model.armature, so M with the effect is the rigid M plus I_m N² once; with
    // model.armature set as well, both add.
    use dynamics::{Effects, Rotor};
    let mut m = common::load("robots/puma560.toml");
    assert!(m.armature.iter().all(|a| *a == 0.0));
    let rotor = Rotor::from_model(&m, 1.0);
    assert!(
        (0..m.nv).any(|k| rotor.armature(k) > 0.0),
        "the file has rotors"
    );
    let effects = Effects {
        rotor: Some(rotor.clone()),
        ..Effects::default()
    };
    let mut d = Data::new(&m);
    let q = [0.3, -0.7, 0.9, 0.1, -0.5, 0.4];
    let qd = [0.2, -0.1, 0.3, 0.5, -0.4, 0.6];
    let tau = [5.0, -20.0, 8.0, 0.5, -0.3, 0.2];
    for extra in [0.0, 0.02] {
        m.armature = vec![extra; m.nv];
        let rigid = dynamics::crba(&m, &mut d, &q).clone();
        let with = dynamics::mass_matrix(&m, &mut d, &effects, &q).clone();
        for k in 0..m.nv {
            let dm = with[(k, k)] - rigid[(k, k)];
            assert!(
                (dm - rotor.armature(k)).abs() <= 1e-14 * rigid[(k, k)].max(1.0),
                "M[{k},{k}] grew by {dm}, expected I_m N² = {}",
                rotor.armature(k)
            );
        }
        // Forward dynamics with the effect solves (M + diag(I_m N²)) q̈ = τ − h.
        m.gravity = Vec3::zeros();
        let qdd = dynamics::forward_dynamics_with(&m, &mut d, &effects, &q, &qd, &tau)
            .unwrap()
            .to_vec();
        let h = dynamics::bias(&m, &mut d, &q, &qd).to_vec();
        for i in 0..m.nv {
            let lhs: f64 = (0..m.nv).map(|j| with[(i, j)] * qdd[j]).sum::<f64>() + h[i];
            assert!((lhs - tau[i]).abs() < 1e-9, "row {i}: {lhs} vs {}", tau[i]);
        }
        m.gravity = Vec3::new(0.0, 0.0, -9.81);
    }
}
