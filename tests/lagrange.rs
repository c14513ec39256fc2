//! The two Lagrange formulations against the recursive algorithms, on every robot in
//! `robots/`, the mimic gripper and a 12-link chain: trace form = energy form = RNEA,
//! their mass matrices = CRBA, `Ṁ − 2C` skew-symmetric, analytic `∂M/∂q` = finite
//! differences of CRBA, and `C q̇ + g` = the RNEA bias.

mod common;

use armsim::core::spatial::Vec3;
use armsim::dynamics;
use armsim::model::data::Data;
use armsim::model::Model;
use nalgebra::DMatrix;
use rand::rngs::SmallRng;
use rand::SeedableRng;

fn models() -> Vec<(String, Model)> {
    common::test_models(12)
}

/// `‖a − b‖∞ ≤ tol · max(1, ‖b‖∞)`.
fn close(a: &[f64], b: &[f64], tol: f64) -> Result<(), String> {
    assert_eq!(a.len(), b.len());
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

fn close_mat(a: &DMatrix<f64>, b: &DMatrix<f64>, tol: f64) -> Result<(), String> {
    assert_eq!(a.shape(), b.shape());
    close(a.as_slice(), b.as_slice(), tol)
}

const GRAVITY: Vec3 = Vec3::new(0.0, 0.0, -9.81);

#[test]
fn trace_form_and_energy_form_equal_rnea() {
    // A gravity with all three components, so no term hides behind a zero.
    let g = Vec3::new(0.7, -1.3, -9.81);
    for (name, mut m) in models() {
        m.gravity = g;
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(21);
        for _ in 0..5 {
            let q = m.random_q(&mut rng);
            let qd = common::rand_vec(&mut rng, m.nv, 2.0);
            let qdd = common::rand_vec(&mut rng, m.nv, 5.0);
            let tau = dynamics::rnea(&m, &mut d, &q, &qd, &qdd).to_vec();
            let trace = dynamics::lagrange_trace(&m, &mut d, &q, &qd, &qdd, &g);
            close(&trace, &tau, 1e-9).unwrap_or_else(|e| panic!("{name} trace vs RNEA: {e}"));
            let energy = dynamics::lagrange_energy(&m, &mut d, &q, &qd, &qdd, &g);
            close(&energy, &tau, 1e-9).unwrap_or_else(|e| panic!("{name} energy vs RNEA: {e}"));
            close(&energy, &trace, 1e-9).unwrap_or_else(|e| panic!("{name} energy vs trace: {e}"));
        }
    }
}

#[test]
fn trace_and_energy_mass_matrices_equal_crba() {
    for (name, m) in models() {
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(22);
        for _ in 0..5 {
            let q = m.random_q(&mut rng);
            let crba = dynamics::crba(&m, &mut d, &q).clone();
            let trace = dynamics::mass_matrix_trace(&m, &mut d, &q);
            close_mat(&trace, &crba, 1e-12).unwrap_or_else(|e| panic!("{name} trace M: {e}"));
            let energy = dynamics::mass_matrix_energy(&m, &mut d, &q);
            close_mat(&energy, &crba, 1e-12).unwrap_or_else(|e| panic!("{name} energy M: {e}"));
        }
    }
}

#[test]
fn mass_matrix_derivative_minus_twice_coriolis_is_skew_symmetric() {
    for (name, m) in models() {
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(23);
        for _ in 0..5 {
            let q = m.random_q(&mut rng);
            let qd = common::rand_vec(&mut rng, m.nv, 2.0);
            let dm = dynamics::mass_matrix_derivatives(&m, &mut d, &q);
            let mut m_dot = DMatrix::zeros(m.nv, m.nv);
            for (k, dmk) in dm.iter().enumerate() {
                m_dot += dmk * qd[k];
            }
            let c = dynamics::coriolis_matrix(&m, &mut d, &q, &qd);
            let n = &m_dot - &c * 2.0;
            let scale = m_dot.abs().max().max(c.abs().max()).max(1.0);
            let asym = (&n + n.transpose()).abs().max();
            assert!(
                asym <= 1e-10 * scale,
                "{name}: |N + Nᵀ| = {asym:e} (scale {scale:e})"
            );
        }
    }
}

#[test]
fn mass_matrix_derivatives_match_finite_differences_of_crba() {
    let h = 1e-6;
    for (name, m) in models() {
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(24);
        for _ in 0..3 {
            let q = m.random_q(&mut rng);
            let dm = dynamics::mass_matrix_derivatives(&m, &mut d, &q);
            assert_eq!(dm.len(), m.nv);
            for (k, dmk) in dm.iter().enumerate() {
                let mut qp = q.clone();
                qp[k] += h;
                let mp = dynamics::crba(&m, &mut d, &qp).clone();
                let mut qm = q.clone();
                qm[k] -= h;
                let mm = dynamics::crba(&m, &mut d, &qm).clone();
                let fd = (mp - mm) / (2.0 * h);
                close_mat(dmk, &fd, 1e-7).unwrap_or_else(|e| panic!("{name} ∂M/∂q_{k}: {e}"));
            }
        }
    }
}

#[test]
fn coriolis_times_velocity_plus_gravity_equals_rnea_bias() {
    for (name, mut m) in models() {
        m.gravity = GRAVITY;
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(25);
        for _ in 0..5 {
            let q = m.random_q(&mut rng);
            let qd = common::rand_vec(&mut rng, m.nv, 2.0);
            let bias = dynamics::bias(&m, &mut d, &q, &qd).to_vec();
            let c = dynamics::coriolis_matrix(&m, &mut d, &q, &qd);
            let g = dynamics::gravity_torque_energy(&m, &mut d, &q, &GRAVITY);
            let h: Vec<f64> = (0..m.nv)
                .map(|i| (0..m.nv).map(|j| c[(i, j)] * qd[j]).sum::<f64>() + g[i])
                .collect();
            close(&h, &bias, 1e-9).unwrap_or_else(|e| panic!("{name} C q̇ + g: {e}"));
            let grav = dynamics::gravity_torque(&m, &mut d, &q).to_vec();
            close(&g, &grav, 1e-9).unwrap_or_else(|e| panic!("{name} g(q): {e}"));
        }
    }
}

#[test]
fn planar_2r_trace_form_matches_the_textbook_closed_form() {
    // docs/reference_data.md §S1 checkpoint, in the z-up frame of robots/planar_2r.toml.
    let m = common::load("robots/planar_2r.toml");
    let g = 9.81f64;
    let mut d = Data::new(&m);
    let mut rng = SmallRng::seed_from_u64(26);
    for _ in 0..20 {
        let q = common::rand_vec(&mut rng, 2, 3.1);
        let qd = common::rand_vec(&mut rng, 2, 3.0);
        let qdd = common::rand_vec(&mut rng, 2, 5.0);
        let (_, expect) = common::planar_2r_closed_form(&q, &qd, &qdd);
        let tau = dynamics::lagrange_trace(&m, &mut d, &q, &qd, &qdd, &Vec3::new(0.0, 0.0, -g));
        close(&tau, &expect, 1e-12).unwrap_or_else(|e| panic!("trace form: {e}"));
    }
}
