//! The analytical dynamics derivatives (Carpentier & Mansard) against central finite
//! differences of the algorithms they differentiate, on every robot in `robots/`, a tree
//! (two arms on one torso), the mimic gripper and generated chains (one of 30 joints, two
//! of them reversed, for the column pass of long chains), with gravity,
//! armature and external wrenches: `∂τ/∂q`, `∂τ/∂q̇` against RNEA, `∂τ/∂q̈` against CRBA,
//! `∂q̈/∂q`, `∂q̈/∂q̇` against ABA, `∂q̈/∂τ` and `M⁻¹` against the inverse of CRBA's `M`;
//! and the derivatives with the scene's effects (friction, rotors, a payload, world-fixed
//! wrenches) against central differences of `inverse_dynamics` / `forward_dynamics_with`.

mod common;

use armsim::core::spatial::{Force, Vec3};
use armsim::dynamics;
use armsim::dynamics::Effects;
use armsim::model::data::Data;
use armsim::model::Model;
use nalgebra::DMatrix;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};

/// Every test model with gravity and a random armature on every coordinate.
fn models() -> Vec<(String, Model)> {
    let mut v = common::test_models(12);
    v.push(("dual_arm".into(), common::load("tests/data/dual_arm.urdf")));
    // Long enough for the RNEA derivatives' column pass; two axes reversed (negative
    // multipliers).
    let mut spec = armsim::model::chain::chain_spec(30);
    for k in [3, 11] {
        spec.joints[k].axis = -spec.joints[k].axis;
    }
    let chain = Model::build(spec).unwrap().0;
    assert!(chain.q_mult.iter().any(|m| *m < 0.0), "a reversed axis");
    v.push(("chain_30_reversed".into(), chain));
    let mut rng = SmallRng::seed_from_u64(5);
    for (_, m) in &mut v {
        m.gravity = Vec3::new(0.3, -0.2, -9.81);
        for a in &mut m.armature {
            *a = rng.random_range(0.0..0.2);
        }
    }
    v
}

struct State {
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
}

fn states(m: &Model, count: usize, seed: u64) -> Vec<State> {
    let mut rng = SmallRng::seed_from_u64(seed);
    (0..count)
        .map(|_| State {
            q: m.random_q(&mut rng),
            v: common::rand_vec(&mut rng, m.nv, 2.0),
            a: common::rand_vec(&mut rng, m.nv, 3.0),
        })
        .collect()
}

#[test]
fn rnea_partials_equal_central_differences_of_rnea() {
    for (name, m) in models() {
        let mut d = Data::new(&m);
        let mut fd = Data::new(&m);
        for (s, st) in states(&m, 4, 21).iter().enumerate() {
            let what = format!("{name} state {s}");
            let p = dynamics::rnea_derivatives(&m, &mut d, &st.q, &st.v, &st.a);
            let (dq, dv, mass) = (p.dtau_dq.clone(), p.dtau_dv.clone(), p.mass.clone());
            let tau = d.tau.clone();
            let want = dynamics::rnea(&m, &mut fd, &st.q, &st.v, &st.a).to_vec();
            common::assert_matrix_close(
                &format!("{what}: τ"),
                &DMatrix::from_column_slice(m.nv, 1, &tau),
                &DMatrix::from_column_slice(m.nv, 1, &want),
                1e-12,
            );
            let fq = common::central_differences(&st.q, 1e-6, |q| {
                dynamics::rnea(&m, &mut fd, q, &st.v, &st.a).to_vec()
            });
            common::assert_matrix_close(&format!("{what}: ∂τ/∂q"), &dq, &fq, 1e-6);
            let fv = common::central_differences(&st.v, 1e-6, |v| {
                dynamics::rnea(&m, &mut fd, &st.q, v, &st.a).to_vec()
            });
            common::assert_matrix_close(&format!("{what}: ∂τ/∂q̇"), &dv, &fv, 1e-6);
            let crba = dynamics::crba(&m, &mut fd, &st.q).clone();
            common::assert_matrix_close(&format!("{what}: ∂τ/∂q̈ = M"), &mass, &crba, 1e-12);
        }
    }
}

#[test]
fn rnea_partials_with_body_wrenches_equal_central_differences() {
    for (name, m) in models() {
        let mut rng = SmallRng::seed_from_u64(8);
        let f_ext: Vec<Force> = (0..m.nbodies())
            .map(|_| {
                let w = common::rand_vec(&mut rng, 6, 3.0);
                Force::new(Vec3::new(w[0], w[1], w[2]), Vec3::new(w[3], w[4], w[5]))
            })
            .collect();
        let mut d = Data::new(&m);
        let mut fd = Data::new(&m);
        for st in states(&m, 2, 9) {
            let p = dynamics::rnea_derivatives_with_forces(&m, &mut d, &st.q, &st.v, &st.a, &f_ext);
            let (dq, dv) = (p.dtau_dq.clone(), p.dtau_dv.clone());
            let fq = common::central_differences(&st.q, 1e-6, |q| {
                dynamics::rnea_with_forces(&m, &mut fd, q, &st.v, &st.a, &f_ext).to_vec()
            });
            common::assert_matrix_close(&format!("{name}: ∂τ/∂q with wrenches"), &dq, &fq, 1e-6);
            let fv = common::central_differences(&st.v, 1e-6, |v| {
                dynamics::rnea_with_forces(&m, &mut fd, &st.q, v, &st.a, &f_ext).to_vec()
            });
            common::assert_matrix_close(&format!("{name}: ∂τ/∂q̇ with wrenches"), &dv, &fv, 1e-6);
        }
    }
}

#[test]
fn minverse_times_crba_mass_matrix_is_identity() {
    for (name, m) in models() {
        let mut d = Data::new(&m);
        for st in states(&m, 4, 33) {
            let minv = dynamics::compute_minverse(&m, &mut d, &st.q)
                .unwrap()
                .clone();
            let mass = dynamics::crba(&m, &mut d, &st.q).clone();
            let eye = DMatrix::identity(m.nv, m.nv);
            common::assert_matrix_close(&format!("{name}: M⁻¹ M"), &(&minv * &mass), &eye, 1e-9);
            common::assert_matrix_close(
                &format!("{name}: M⁻¹ symmetric"),
                &minv,
                &minv.transpose(),
                1e-12,
            );
        }
    }
}

/// Column `c` of `M⁻¹` is the acceleration under the unit torque `e_c` from rest without
/// gravity: ABA, an algorithm `compute_minverse` does not call (it inverts CRBA's `M` on
/// the arms and runs its own recursion on the larger models).
#[test]
fn minverse_columns_equal_aba_under_unit_torques_from_rest_without_gravity() {
    for (name, mut m) in models() {
        m.gravity = Vec3::zeros();
        let (mut d, mut fd) = (Data::new(&m), Data::new(&m));
        let z = vec![0.0; m.nv];
        for st in states(&m, 3, 35) {
            let minv = dynamics::compute_minverse(&m, &mut d, &st.q)
                .unwrap()
                .clone();
            let cols: Vec<f64> = (0..m.nv)
                .flat_map(|c| {
                    let mut e = z.clone();
                    e[c] = 1.0;
                    dynamics::forward_dynamics(&m, &mut fd, &st.q, &z, &e)
                        .unwrap()
                        .to_vec()
                })
                .collect();
            let aba = DMatrix::from_column_slice(m.nv, m.nv, &cols);
            common::assert_matrix_close(
                &format!("{name}: M⁻¹ e_c = ABA(q, 0, e_c)"),
                &minv,
                &aba,
                1e-10,
            );
        }
    }
}

/// The Cholesky inverse compiled for each size up to `SPD_FIXED_MAX`, against nalgebra's
/// LU inverse on random symmetric positive-definite matrices (`B Bᵀ + n·1`, `B` uniform
/// in ±1); a matrix that is not positive definite fails at its first bad pivot.
#[test]
fn small_spd_inverse_equals_the_lu_inverse_at_every_compiled_size() {
    use armsim::core::spd_inverse::{spd_inverse_small, SPD_FIXED_MAX};
    let mut rng = SmallRng::seed_from_u64(12);
    for n in 1..=SPD_FIXED_MAX {
        for _ in 0..5 {
            let b = DMatrix::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
            let a = &b * b.transpose() + DMatrix::identity(n, n) * n as f64;
            let mut inv = DMatrix::zeros(n, n);
            spd_inverse_small(n, a.as_slice(), inv.as_mut_slice()).unwrap();
            let lu = a.clone().try_inverse().expect("invertible");
            common::assert_matrix_close(
                &format!("n = {n}: Cholesky vs LU inverse"),
                &inv,
                &lu,
                1e-13,
            );
            assert_eq!(inv, inv.transpose(), "n = {n}: exactly symmetric");
        }
    }
    // Positive definite on the leading 2 × 2, then a zero pivot at coordinate 2.
    let a = DMatrix::from_row_slice(3, 3, &[4.0, 2.0, 2.0, 2.0, 2.0, 1.0, 2.0, 1.0, 1.0]);
    let mut inv = DMatrix::zeros(3, 3);
    let e = spd_inverse_small(3, a.as_slice(), inv.as_mut_slice()).unwrap_err();
    assert_eq!((e.pivot, e.value), (2, 0.0), "{e}");
}

/// Models above the size `M⁻¹` inverts CRBA's `M` at: the recursion, in blocks of
/// columns; on a serial chain (two storage slots in turn) and on a tree (a slot per body:
/// joints 9 and 17 branch off links 3 and 6, joint 22 off the world's link).
#[test]
fn minverse_in_column_blocks_times_crba_mass_matrix_is_identity() {
    let chain = armsim::model::chain::chain_spec(30);
    let mut tree = chain.clone();
    tree.name = "tree_30".into();
    for (j, from) in [(8, "link3"), (16, "link6"), (21, "link0")] {
        tree.joints[j].parent = from.into();
    }
    for spec in [chain, tree] {
        let mut m = Model::build(spec).unwrap().0;
        let serial = (1..m.nbodies()).all(|i| m.parent[i] == i - 1);
        assert_eq!(
            serial,
            m.name == "chain_30",
            "{}: a chain, or branched",
            m.name
        );
        let mut rng = SmallRng::seed_from_u64(7);
        for a in &mut m.armature {
            *a = rng.random_range(0.0..0.2);
        }
        let mut d = Data::new(&m);
        for st in states(&m, 4, 34) {
            let minv = dynamics::compute_minverse(&m, &mut d, &st.q)
                .unwrap()
                .clone();
            let mass = dynamics::crba(&m, &mut d, &st.q).clone();
            let eye = DMatrix::identity(m.nv, m.nv);
            let what = |x: &str| format!("{}: {x}", m.name);
            common::assert_matrix_close(&what("M⁻¹ M"), &(&minv * &mass), &eye, 1e-9);
            common::assert_matrix_close(&what("M⁻¹ symmetric"), &minv, &minv.transpose(), 1e-12);
        }
    }
}

#[test]
fn aba_partials_equal_central_differences_of_forward_dynamics() {
    for (name, m) in models() {
        let mut d = Data::new(&m);
        let mut fd = Data::new(&m);
        for (s, st) in states(&m, 3, 44).iter().enumerate() {
            let what = format!("{name} state {s}");
            let tau = st.a.clone();
            let p = dynamics::aba_derivatives(&m, &mut d, &st.q, &st.v, &tau).unwrap();
            let (dq, dv, minv) = (p.ddq_dq.clone(), p.ddq_dv.clone(), p.minv.clone());
            let col = |x: &[f64]| DMatrix::from_column_slice(x.len(), 1, x);
            let qdd = dynamics::forward_dynamics(&m, &mut fd, &st.q, &st.v, &tau)
                .unwrap()
                .to_vec();
            common::assert_matrix_close(
                &format!("{what}: q̈ = FD"),
                &col(&d.qdd),
                &col(&qdd),
                1e-10,
            );
            common::assert_matrix_close(
                &format!("{what}: ID(q̈) = τ"),
                &col(&d.tau),
                &col(&tau),
                1e-10,
            );
            let mut fwd = |q: &[f64], v: &[f64], t: &[f64]| {
                dynamics::forward_dynamics(&m, &mut fd, q, v, t)
                    .unwrap()
                    .to_vec()
            };
            let fq = common::central_differences(&st.q, 1e-6, |q| fwd(q, &st.v, &tau));
            common::assert_matrix_close(&format!("{what}: ∂q̈/∂q"), &dq, &fq, 1e-5);
            let fv = common::central_differences(&st.v, 1e-6, |v| fwd(&st.q, v, &tau));
            common::assert_matrix_close(&format!("{what}: ∂q̈/∂q̇"), &dv, &fv, 1e-5);
            let ft = common::central_differences(&tau, 1e-6, |t| fwd(&st.q, &st.v, t));
            common::assert_matrix_close(&format!("{what}: ∂q̈/∂τ = M⁻¹"), &minv, &ft, 1e-5);
        }
    }
}

#[test]
fn inverse_dynamics_partials_with_effects_equal_central_differences() {
    for (name, m) in models() {
        let fx = common::scene_effects(&m, 3);
        let mut d = Data::new(&m);
        let mut fd = Data::new(&m);
        for (s, st) in states(&m, 3, 17).iter().enumerate() {
            let what = format!("{name} state {s} with effects");
            let p = dynamics::inverse_dynamics_derivatives(&m, &mut d, &fx, &st.q, &st.v, &st.a);
            let (dq, dv, mass) = (p.dtau_dq.clone(), p.dtau_dv.clone(), p.mass.clone());
            let tau = d.tau.clone();
            let mut id = |q: &[f64], v: &[f64], a: &[f64]| {
                dynamics::inverse_dynamics(&m, &mut fd, &fx, q, v, a).to_vec()
            };
            let want = id(&st.q, &st.v, &st.a);
            let col = |x: &[f64]| DMatrix::from_column_slice(x.len(), 1, x);
            common::assert_matrix_close(&format!("{what}: τ"), &col(&tau), &col(&want), 1e-12);
            let fq = common::central_differences(&st.q, 1e-6, |q| id(q, &st.v, &st.a));
            common::assert_matrix_close(&format!("{what}: ∂τ/∂q"), &dq, &fq, 1e-6);
            let fv = common::central_differences(&st.v, 1e-6, |v| id(&st.q, v, &st.a));
            common::assert_matrix_close(&format!("{what}: ∂τ/∂q̇"), &dv, &fv, 1e-6);
            let fa = common::central_differences(&st.a, 1e-3, |a| id(&st.q, &st.v, a));
            common::assert_matrix_close(&format!("{what}: ∂τ/∂q̈ = M̃"), &mass, &fa, 1e-9);
            let m_tilde = dynamics::mass_matrix(&m, &mut fd, &fx, &st.q).clone();
            common::assert_matrix_close(
                &format!("{what}: M̃ = mass_matrix"),
                &mass,
                &m_tilde,
                1e-12,
            );
        }
    }
}

#[test]
fn forward_dynamics_partials_with_effects_equal_central_differences() {
    for (name, m) in models() {
        let fx = common::scene_effects(&m, 4);
        let mut d = Data::new(&m);
        let mut fd = Data::new(&m);
        for (s, st) in states(&m, 3, 29).iter().enumerate() {
            let what = format!("{name} state {s} with effects");
            let tau = st.a.clone();
            let p = dynamics::forward_dynamics_derivatives(&m, &mut d, &fx, &st.q, &st.v, &tau)
                .unwrap();
            let (dq, dv, minv) = (p.ddq_dq.clone(), p.ddq_dv.clone(), p.minv.clone());
            let mut fwd = |q: &[f64], v: &[f64], t: &[f64]| {
                dynamics::forward_dynamics_with(&m, &mut fd, &fx, q, v, t)
                    .unwrap()
                    .to_vec()
            };
            let col = |x: &[f64]| DMatrix::from_column_slice(x.len(), 1, x);
            let qdd = fwd(&st.q, &st.v, &tau);
            common::assert_matrix_close(&format!("{what}: q̈"), &col(&d.qdd), &col(&qdd), 1e-10);
            let fq = common::central_differences(&st.q, 1e-6, |q| fwd(q, &st.v, &tau));
            common::assert_matrix_close(&format!("{what}: ∂q̈/∂q"), &dq, &fq, 1e-5);
            let fv = common::central_differences(&st.v, 1e-6, |v| fwd(&st.q, v, &tau));
            common::assert_matrix_close(&format!("{what}: ∂q̈/∂q̇"), &dv, &fv, 1e-5);
            let ft = common::central_differences(&tau, 1e-6, |t| fwd(&st.q, &st.v, t));
            common::assert_matrix_close(&format!("{what}: ∂q̈/∂τ = M̃⁻¹"), &minv, &ft, 1e-5);
        }
    }
}

#[test]
fn partials_with_the_models_gravity_alone_equal_the_plain_partials() {
    for (name, m) in models() {
        let fx = Effects::gravity(m.gravity);
        let (mut d, mut e) = (Data::new(&m), Data::new(&m));
        for st in states(&m, 2, 51) {
            let p = dynamics::rnea_derivatives(&m, &mut d, &st.q, &st.v, &st.a);
            let (dq, dv) = (p.dtau_dq.clone(), p.dtau_dv.clone());
            let r = dynamics::inverse_dynamics_derivatives(&m, &mut e, &fx, &st.q, &st.v, &st.a);
            // The model's armature is in both; the effects add none.
            common::assert_matrix_close(&format!("{name}: ∂τ/∂q"), r.dtau_dq, &dq, 1e-13);
            common::assert_matrix_close(&format!("{name}: ∂τ/∂q̇"), r.dtau_dv, &dv, 1e-13);
            let p = dynamics::aba_derivatives(&m, &mut d, &st.q, &st.v, &st.a).unwrap();
            let (dq, minv) = (p.ddq_dq.clone(), p.minv.clone());
            let r = dynamics::forward_dynamics_derivatives(&m, &mut e, &fx, &st.q, &st.v, &st.a)
                .unwrap();
            common::assert_matrix_close(&format!("{name}: ∂q̈/∂q"), r.ddq_dq, &dq, 1e-10);
            common::assert_matrix_close(&format!("{name}: M⁻¹"), r.minv, &minv, 1e-10);
        }
    }
}
