//! Every Jacobian expression, and its time derivative, against central finite
//! differences of forward kinematics, for every robot in `robots/` and every link frame.

mod common;

use armsim::core::spatial::{Motion, Se3};
use armsim::kinematics::{self, Expressed};
use armsim::model::data::Data;
use armsim::model::Model;
use common::{omega, robot_files};
use nalgebra::DMatrix;
use rand::rngs::SmallRng;
use rand::SeedableRng;

const H: f64 = 1e-6;
const TOL: f64 = 1e-7;

fn placement(model: &Model, data: &mut Data, q: &[f64], link: usize) -> Se3 {
    kinematics::forward_kinematics(model, data, q);
    kinematics::frame_placement(model, data, link)
}

/// Finite-difference Jacobian column k of `link` in `expressed`.
fn fd_column(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    link: usize,
    k: usize,
    ex: Expressed,
) -> Motion {
    let mut qp = q.to_vec();
    let mut qm = q.to_vec();
    qp[k] += H;
    qm[k] -= H;
    let tp = placement(model, data, &qp, link);
    let tm = placement(model, data, &qm, link);
    let t = placement(model, data, q, link);
    let p_dot = (tp.trans - tm.trans) / (2.0 * H);
    let r_dot = (tp.rot - tm.rot) / (2.0 * H);
    let w = omega(&r_dot, &t.rot);
    match ex {
        Expressed::WorldAligned => Motion::new(p_dot, w),
        // Velocity of the body point at the world origin: ṗ − ω × p.
        Expressed::World => Motion::new(p_dot - w.cross(&t.trans), w),
        Expressed::Local => Motion::new(t.rot.transpose() * p_dot, t.rot.transpose() * w),
    }
}

fn jacobian(model: &Model, data: &mut Data, q: &[f64], link: usize, ex: Expressed) -> DMatrix<f64> {
    let mut j = DMatrix::zeros(6, model.nv);
    kinematics::compute_joint_jacobians(model, data, q);
    kinematics::frame_jacobian(model, data, link, ex, &mut j);
    j
}

const ALL: [Expressed; 3] = [Expressed::World, Expressed::Local, Expressed::WorldAligned];

fn check_model(model: &Model, name: &str, states: usize) -> usize {
    let mut data = Data::new(model);
    let mut rng = SmallRng::seed_from_u64(7);
    let mut checked = 0;
    for _ in 0..states {
        let q = model.random_q(&mut rng);
        let qd: Vec<f64> = model
            .random_q(&mut rng)
            .iter()
            .map(|x| x.sin() + 0.3)
            .collect();
        for link in 0..model.links.len() {
            for ex in ALL {
                let j = jacobian(model, &mut data, &q, link, ex);
                for k in 0..model.nv {
                    let fd = fd_column(model, &mut data, &q, link, k, ex).to_array();
                    for r in 0..6 {
                        let err = (j[(r, k)] - fd[r]).abs();
                        assert!(
                            err < TOL,
                            "{name}: link '{}' {:?} J[{r},{k}] = {} vs FD {} (err {err:e})",
                            model.links[link].name,
                            ex,
                            j[(r, k)],
                            fd[r]
                        );
                    }
                }
                // dJ/dt against (J(q + h qd) − J(q − h qd)) / 2h.
                let mut dj = DMatrix::zeros(6, model.nv);
                kinematics::compute_joint_jacobians_time_variation(model, &mut data, &q, &qd);
                kinematics::frame_jacobian_time_variation(model, &data, link, ex, &mut dj);
                let qp: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a + H * b).collect();
                let qm: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a - H * b).collect();
                let jp = jacobian(model, &mut data, &qp, link, ex);
                let jm = jacobian(model, &mut data, &qm, link, ex);
                let fd = (jp - jm) / (2.0 * H);
                let err = (&dj - &fd).abs().max();
                assert!(
                    err < TOL,
                    "{name}: link '{}' {:?} dJ/dt differs from FD by {err:e}",
                    model.links[link].name,
                    ex
                );
                checked += 1;
            }
        }
    }
    checked
}

#[test]
fn every_robot_every_frame_every_expression_matches_finite_differences() {
    let files = robot_files();
    assert!(
        files.len() >= 5,
        "robots/ holds {} model files",
        files.len()
    );
    for f in files {
        let (model, _) = Model::load(&f).unwrap_or_else(|e| panic!("{e}"));
        let n = check_model(&model, &f.display().to_string(), 6);
        assert!(n > 0);
    }
}

#[test]
fn generated_chain_and_mimic_tree_match_finite_differences() {
    let (chain, _) = Model::build(armsim::model::chain::chain_spec(30)).unwrap();
    check_model(&chain, "chain_30", 2);
    let (gripper, _) = Model::build(
        armsim::model::parse::urdf::parse(
            include_str!("data/mimic_gripper.urdf"),
            "mimic_gripper.urdf",
        )
        .unwrap(),
    )
    .unwrap();
    assert!(gripper.has_mimic);
    check_model(&gripper, "mimic_gripper", 6);
}

/// `compute_frame_jacobian` (row-major, forward kinematics of the support only) gives
/// the same bits as `compute_joint_jacobians` + `frame_jacobian`, starting from a
/// workspace left at another configuration (a support body it skipped would be stale).
fn check_frame_jacobian_in_one_call(model: &Model, name: &str) -> usize {
    let mut rng = SmallRng::seed_from_u64(11);
    let (mut full, mut one) = (Data::new(model), Data::new(model));
    let mut row_major = vec![f64::NAN; 6 * model.nv];
    let mut compared = 0;
    for _ in 0..3 {
        let (q, stale) = (model.random_q(&mut rng), model.random_q(&mut rng));
        for link in 0..model.links.len() {
            for ex in ALL {
                let j = jacobian(model, &mut full, &q, link, ex);
                kinematics::forward_kinematics(model, &mut one, &stale);
                kinematics::compute_frame_jacobian(model, &mut one, &q, link, ex, &mut row_major);
                for r in 0..6 {
                    for k in 0..model.nv {
                        assert_eq!(
                            row_major[r * model.nv + k].to_bits(),
                            j[(r, k)].to_bits(),
                            "{name}: link '{}' {ex:?} J[{r},{k}]",
                            model.links[link].name
                        );
                        compared += 1;
                    }
                }
                let body = model.links[link].body;
                if body != armsim::model::WORLD {
                    let (a, b) = (
                        kinematics::frame_placement(model, &full, link),
                        kinematics::frame_placement(model, &one, link),
                    );
                    assert_eq!(
                        (a.rot, a.trans),
                        (b.rot, b.trans),
                        "{name}: oMf of '{}'",
                        model.links[link].name
                    );
                }
            }
        }
    }
    compared
}

#[test]
fn compute_frame_jacobian_equals_joint_jacobians_then_frame_jacobian_bit_for_bit() {
    for f in robot_files() {
        let (model, _) = Model::load(&f).unwrap_or_else(|e| panic!("{e}"));
        assert!(check_frame_jacobian_in_one_call(&model, &f.display().to_string()) > 0);
    }
    let (gripper, _) = Model::build(
        armsim::model::parse::urdf::parse(
            include_str!("data/mimic_gripper.urdf"),
            "mimic_gripper.urdf",
        )
        .unwrap(),
    )
    .unwrap();
    assert!(gripper.has_mimic);
    assert!(check_frame_jacobian_in_one_call(&gripper, "mimic_gripper") > 0);
}
