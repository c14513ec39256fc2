//! The linearised integration step (`dynamics::StepLinearisation`): `A = ∂x⁺/∂x` and
//! `B = ∂x⁺/∂τ` against central differences of the step written out here from
//! `forward_dynamics_with`, on every test robot with every effect that has a derivative;
//! RK4 at an equilibrium against the fourth-order Taylor polynomial of `e^{hF}`; semi-implicit
//! Euler on a damped rotor against its closed form; and the refusals.

mod common;

use armsim::core::spatial::Vec3;
use armsim::dynamics::{
    self, Effects, Friction, LinearisationError, StepLinearisation, StepScheme,
};
use armsim::model::data::Data;
use armsim::model::Model;
use nalgebra::DMatrix;
use rand::rngs::SmallRng;
use rand::SeedableRng;

/// One step of `scheme` from `x = (q, q̇)` under `τ`, written out independently of the
/// linearisation.
fn step(
    m: &Model,
    d: &mut Data,
    fx: &Effects,
    scheme: StepScheme,
    h: f64,
    x: &[f64],
    tau: &[f64],
) -> Vec<f64> {
    let n = m.nv;
    let mut f = |x: &[f64]| -> Vec<f64> {
        let qdd = dynamics::forward_dynamics_with(m, d, fx, &x[..n], &x[n..], tau).unwrap();
        x[n..].iter().chain(qdd).copied().collect()
    };
    match scheme {
        StepScheme::SemiImplicitEuler => {
            let k = f(x);
            let v: Vec<f64> = (0..n).map(|i| x[n + i] + h * k[n + i]).collect();
            (0..n)
                .map(|i| x[i] + h * v[i])
                .chain(v.iter().copied())
                .collect()
        }
        StepScheme::Rk4 => {
            let shift = |k: &[f64], c: f64| -> Vec<f64> {
                x.iter().zip(k).map(|(x, k)| x + c * k).collect()
            };
            let k1 = f(x);
            let k2 = f(&shift(&k1, h / 2.0));
            let k3 = f(&shift(&k2, h / 2.0));
            let k4 = f(&shift(&k3, h));
            (0..2 * n)
                .map(|i| x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
                .collect()
        }
    }
}

const SCHEMES: [StepScheme; 2] = [StepScheme::SemiImplicitEuler, StepScheme::Rk4];

#[test]
fn a_and_b_equal_central_differences_of_the_step() {
    let h = 0.01;
    // chain_30 takes the blocked-product path (above 24 coordinates).
    for (name, m) in common::test_models(30) {
        let fx = common::scene_effects(&m, 7);
        let (mut d, mut fd) = (Data::new(&m), Data::new(&m));
        let mut rng = SmallRng::seed_from_u64(13);
        let q = m.random_q(&mut rng);
        let v = common::rand_vec(&mut rng, m.nv, 1.5);
        let tau = common::rand_vec(&mut rng, m.nv, 5.0);
        let x: Vec<f64> = q.iter().chain(&v).copied().collect();
        for scheme in SCHEMES {
            let what = format!("{name} {scheme:?}");
            let mut lin = StepLinearisation::new(&m, scheme, h).unwrap();
            lin.linearise(&m, &mut d, &fx, &q, &v, &tau).unwrap();
            let want = step(&m, &mut fd, &fx, scheme, h, &x, &tau);
            let col = |x: &[f64]| DMatrix::from_column_slice(x.len(), 1, x);
            common::assert_matrix_close(
                &format!("{what}: x⁺"),
                &col(lin.next_state()),
                &col(&want),
                1e-12,
            );
            let fa = common::central_differences(&x, 1e-6, |x| {
                step(&m, &mut fd, &fx, scheme, h, x, &tau)
            });
            common::assert_matrix_close(&format!("{what}: A"), lin.a(), &fa, 1e-7);
            let fb = common::central_differences(&tau, 1e-4, |t| {
                step(&m, &mut fd, &fx, scheme, h, &x, t)
            });
            common::assert_matrix_close(&format!("{what}: B"), lin.b(), &fb, 1e-7);
        }
    }
}

#[test]
fn rk4_at_an_equilibrium_is_the_fourth_order_taylor_polynomial_of_exp_hf() {
    let h = 0.02;
    for (name, m) in common::test_models(8) {
        let fx = common::scene_effects(&m, 9);
        let mut d = Data::new(&m);
        let q = m.random_q(&mut SmallRng::seed_from_u64(3));
        let (n, zero) = (m.nv, vec![0.0; m.nv]);
        // At rest under the torque that holds it, every RK4 stage sits at x.
        let tau = dynamics::inverse_dynamics(&m, &mut d, &fx, &q, &zero, &zero).to_vec();
        let p = dynamics::forward_dynamics_derivatives(&m, &mut d, &fx, &q, &zero, &tau).unwrap();
        let mut f = DMatrix::zeros(2 * n, 2 * n);
        let mut g = DMatrix::zeros(2 * n, n);
        f.view_mut((0, n), (n, n)).fill_with_identity();
        f.view_mut((n, 0), (n, n)).copy_from(p.ddq_dq);
        f.view_mut((n, n), (n, n)).copy_from(p.ddq_dv);
        g.view_mut((n, 0), (n, n)).copy_from(p.minv);
        let hf = &f * h;
        let eye = DMatrix::identity(2 * n, 2 * n);
        let hf2 = &hf * &hf;
        let hf3 = &hf2 * &hf;
        let a = &eye + &hf + &hf2 / 2.0 + &hf3 / 6.0 + &hf3 * &hf / 24.0;
        let b = (&eye + &hf / 2.0 + &hf2 / 6.0 + &hf3 / 24.0) * &g * h;
        let mut lin = StepLinearisation::new(&m, StepScheme::Rk4, h).unwrap();
        lin.linearise(&m, &mut d, &fx, &q, &zero, &tau).unwrap();
        common::assert_matrix_close(&format!("{name}: A"), lin.a(), &a, 1e-12);
        common::assert_matrix_close(&format!("{name}: B"), lin.b(), &b, 1e-12);
    }
}

#[test]
fn euler_on_a_damped_rotor_is_the_closed_form() {
    // M = J, q̈ = (τ − b q̇)/J: q̇⁺ = q̇ + h q̈, q⁺ = q + h q̇⁺.
    let (j, b, h) = (0.3, 0.4, 0.05);
    let m = common::single_joint(j);
    let fx = Effects {
        friction: Some(Friction {
            viscous: vec![b],
            coulomb: vec![0.0],
            stiction: vec![0.0],
            stribeck_velocity: vec![1.0],
            smoothing: 1e-3,
        }),
        ..Effects::default()
    };
    let mut lin = StepLinearisation::new(&m, StepScheme::SemiImplicitEuler, h).unwrap();
    lin.linearise(&m, &mut Data::new(&m), &fx, &[0.7], &[1.2], &[2.0])
        .unwrap();
    let decay = 1.0 - h * b / j;
    let a = DMatrix::from_row_slice(2, 2, &[1.0, h * decay, 0.0, decay]);
    let bb = DMatrix::from_row_slice(2, 1, &[h * h / j, h / j]);
    common::assert_matrix_close("A", lin.a(), &a, 1e-15);
    common::assert_matrix_close("B", lin.b(), &bb, 1e-15);
    let v1 = 1.2 + h * (2.0 - b * 1.2) / j;
    assert_eq!(lin.next_state(), &[0.7 + h * v1, v1]);
}

#[test]
fn elasticity_bad_steps_and_overflowing_steps_are_refused() {
    let m = common::load("robots/ur5.urdf");
    for h in [0.0, -0.01, f64::NAN, f64::INFINITY] {
        let e = StepLinearisation::new(&m, StepScheme::Rk4, h).unwrap_err();
        assert!(matches!(e, LinearisationError::Step { .. }), "{h}: {e}");
    }
    let n = m.nv;
    let mut fx = Effects::gravity(Vec3::new(0.0, 0.0, -9.81));
    let mut d = Data::new(&m);
    let (q, z) = (vec![0.3; n], vec![0.0; n]);
    let mut lin = StepLinearisation::new(&m, StepScheme::Rk4, 1e150).unwrap();
    let e = lin
        .linearise(&m, &mut d, &fx, &q, &vec![1.0; n], &z)
        .unwrap_err();
    assert!(
        matches!(
            e,
            LinearisationError::NonFinite { .. } | LinearisationError::Dynamics { .. }
        ),
        "{e}"
    );
    fx.elasticity = Some(dynamics::Elasticity {
        stiffness: vec![1e3; n],
        damping: vec![1.0; n],
        motor_inertia: vec![0.1; n],
    });
    let e = lin.linearise(&m, &mut d, &fx, &q, &z, &z).unwrap_err();
    assert_eq!(e, LinearisationError::Elasticity);
    assert!(e.to_string().contains("elasticity"));
}
