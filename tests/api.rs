//! The `Robot` facade against independent references: finite differences of its own
//! forward kinematics, the equation of motion assembled from the mass matrix, the
//! low-level Model/Data calls, and its refusals of bad input (errors, never panics).

use armsim::dynamics;
use armsim::kinematics::{self, Expressed};
use armsim::model::Model;
use armsim::{Data, IkOptions, IkStatus, Robot, RobotError, Vec3};

const UR5: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/robots/ur5.urdf");
const Q: [f64; 6] = [0.3, -1.1, 1.3, -0.5, 1.2, 0.4];
const V: [f64; 6] = [0.2, -0.3, 0.5, 0.1, -0.4, 0.6];
const A: [f64; 6] = [1.0, -0.5, 0.3, 0.8, -1.2, 0.7];

fn ur5() -> Robot {
    Robot::from_file(UR5).unwrap()
}

#[test]
fn jacobian_matches_finite_differences_of_fk() {
    let mut robot = ur5();
    let tool = robot.frame("tool0").unwrap();
    let j = robot
        .jacobian(&Q, tool, Expressed::WorldAligned)
        .unwrap()
        .clone();
    let h = 1e-6;
    for k in 0..6 {
        let (mut qp, mut qm) = (Q, Q);
        qp[k] += h;
        qm[k] -= h;
        let pp = robot.pose(&qp, tool).unwrap();
        let pm = robot.pose(&qm, tool).unwrap();
        let dp = (pp.trans - pm.trans) / (2.0 * h);
        // Angular column: vee((R+ − R−)/2h · Rᵀ).
        let r0 = robot.pose(&Q, tool).unwrap().rot;
        let w = (pp.rot - pm.rot) / (2.0 * h) * r0.transpose();
        let dw = Vec3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
        for r in 0..3 {
            assert!((j[(r, k)] - dp[r]).abs() < 1e-7, "J[{r},{k}]");
            assert!((j[(r + 3, k)] - dw[r]).abs() < 1e-7, "J[{},{k}]", r + 3);
        }
    }
}

#[test]
fn rnea_equals_mass_matrix_times_a_plus_bias_with_model_gravity() {
    let mut robot = ur5();
    assert_eq!(robot.gravity(), Vec3::new(0.0, 0.0, -9.81));
    let tau = robot.rnea(&Q, &V, &A).unwrap().to_vec();
    let h = robot.rnea(&Q, &V, &[0.0; 6]).unwrap().to_vec();
    let m = robot.crba(&Q).unwrap().clone();
    for i in 0..6 {
        let ma: f64 = (0..6).map(|k| m[(i, k)] * A[k]).sum();
        assert!((tau[i] - (ma + h[i])).abs() < 1e-10, "row {i}");
    }
    // With v = a = 0, RNEA is the gravity torque, and zero without gravity.
    let g = robot.gravity_torque(&Q).unwrap().to_vec();
    let r = robot.rnea(&Q, &[0.0; 6], &[0.0; 6]).unwrap().to_vec();
    assert_eq!(g, r);
    assert!(g[1].abs() > 10.0, "the shoulder holds the arm: {g:?}");
    robot.set_gravity(Vec3::zeros());
    assert!(robot.gravity_torque(&Q).unwrap().iter().all(|t| *t == 0.0));
}

#[test]
fn aba_inverts_rnea() {
    let mut robot = ur5();
    let tau = robot.rnea(&Q, &V, &A).unwrap().to_vec();
    let qdd = robot.aba(&Q, &V, &tau).unwrap();
    for (x, a) in qdd.iter().zip(A) {
        assert!((x - a).abs() < 1e-9, "{x} vs {a}");
    }
}

#[test]
fn facade_agrees_with_the_low_level_calls_bit_for_bit() {
    let (model, _) = Model::load(UR5).unwrap();
    let mut data = Data::new(&model);
    let mut robot = ur5();
    let tool = model.link_id("tool0").unwrap();
    kinematics::forward_kinematics(&model, &mut data, &Q);
    let low = kinematics::frame_placement(&model, &data, tool);
    let high = robot.pose(&Q, robot.frame("tool0").unwrap()).unwrap();
    assert_eq!(low.trans, high.trans);
    assert_eq!(low.rot, high.rot);
    let low = dynamics::rnea(&model, &mut data, &Q, &V, &A).to_vec();
    assert_eq!(low, robot.rnea(&Q, &V, &A).unwrap());
    let ke_low = dynamics::kinetic_energy(&model, &mut data, &Q, &V);
    let m = robot.crba(&Q).unwrap().clone();
    let vm = nalgebra::DVector::from_row_slice(&V);
    let ke_m = 0.5 * (vm.transpose() * &m * &vm)[(0, 0)];
    assert!((ke_low - ke_m).abs() < 1e-10);
    assert_eq!(robot.kinetic_energy(&Q, &V).unwrap(), ke_low);
}

#[test]
fn ik_reaches_a_reachable_pose_and_explains_an_unreachable_one() {
    let mut robot = ur5();
    let tool = robot.frame("tool0").unwrap();
    let target = robot.pose(&Q, tool).unwrap();
    let sol = robot.ik(tool, &target, &IkOptions::default()).unwrap();
    assert_eq!(sol.status, IkStatus::Converged, "{}", sol.reason);
    let reached = robot.pose(&sol.q, tool).unwrap();
    assert!((reached.trans - target.trans).norm() < 1e-6);
    assert!(sol.position_error < 1e-6 && sol.reason.contains("within"));

    let mut far = target;
    far.trans = Vec3::new(5.0, 0.0, 0.0);
    let opts = IkOptions {
        max_restarts: 3,
        ..IkOptions::default()
    };
    let sol = robot.ik(tool, &far, &opts).unwrap();
    assert_ne!(sol.status, IkStatus::Converged);
    // Every UR5 link length and offset together is under 1.2 m (0.089 + 0.425 + 0.392 +
    // 0.109 + 0.095 + 0.082): the residual is at least the missing distance.
    assert!(sol.position_error > 5.0 - 1.2, "{}", sol.position_error);
    assert!(!sol.reason.is_empty());
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let mut robot = ur5();
    match robot.frame("tool9") {
        Err(RobotError::UnknownFrame { name, known }) => {
            assert_eq!(name, "tool9");
            assert!(known.contains("tool0"));
        }
        other => panic!("{:?}", other.map(|f| f.index())),
    }
    let e = robot.rnea(&Q[..5], &V, &A).unwrap_err();
    assert_eq!(e.to_string(), "q: 5 values for 6 coordinates");
    let mut q = Q;
    q[2] = f64::NAN;
    let e = robot.jacobian(&q, armsim::FrameId(0), Expressed::Local);
    assert_eq!(e.unwrap_err().to_string(), "q[2] is not finite");
    let e = robot.pose(&Q, armsim::FrameId(999)).unwrap_err();
    assert!(matches!(e, RobotError::BadFrame(999)));
    let e = Robot::from_file("no/such/robot.urdf").err().unwrap();
    assert!(
        e.to_string()
            .starts_with("no/such/robot.urdf: file: cannot read"),
        "{e}"
    );
}

#[test]
fn planar_2r_dh_table_matches_its_closed_forms() {
    // robots/planar_2r.toml: rods l = 0.5 m, m1 = 2 kg, m2 = 1 kg, moving in the world x-z
    // plane, angles from +x towards +z.
    let mut robot = Robot::from_file(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/robots/planar_2r.toml"
    ))
    .unwrap();
    assert_eq!(robot.nv(), 2);
    let names = robot.frame_names();
    let tip = robot.frame(names.last().unwrap()).unwrap();
    let (l, m1, m2, g) = (0.5, 2.0, 1.0, 9.81);
    let q = [0.4f64, 0.9];
    let (c1, s1, c12, s12) = (
        q[0].cos(),
        q[0].sin(),
        (q[0] + q[1]).cos(),
        (q[0] + q[1]).sin(),
    );
    let p = robot.pose(&q, tip).unwrap().trans;
    assert!((p.x - l * (c1 + c12)).abs() < 1e-12, "{p}");
    assert!((p.z - l * (s1 + s12)).abs() < 1e-12, "{p}");
    let tau = robot.gravity_torque(&q).unwrap().to_vec();
    let g1 = (m1 / 2.0 + m2) * g * l * c1 + m2 / 2.0 * g * l * c12;
    let g2 = m2 / 2.0 * g * l * c12;
    assert!(
        (tau[0] - g1).abs() < 1e-10 && (tau[1] - g2).abs() < 1e-10,
        "{tau:?}"
    );
    let m = robot.crba(&q).unwrap();
    let c2 = q[1].cos();
    let m11 = m1 * l * l / 3.0 + m2 * l * l * (4.0 / 3.0 + c2);
    let m12 = m2 * l * l * (1.0 / 3.0 + c2 / 2.0);
    assert!((m[(0, 0)] - m11).abs() < 1e-12 && (m[(0, 1)] - m12).abs() < 1e-12);
    assert!((m[(1, 1)] - m2 * l * l / 3.0).abs() < 1e-12);
}

#[path = "../examples/kinematics_dynamics.rs"]
mod example;

#[test]
fn the_kinematics_dynamics_example_runs() {
    example::main().unwrap();
}
