//! Numeric IK: reachable targets converge inside the limits on every arm, unreachable
//! ones are reported with the closest pose, singular and boundary targets stay finite,
//! redundant arms and joints that do not move the link are handled, and batches are
//! deterministic.

mod common;

use armsim::core::spatial::{Se3, Vec3};
use armsim::kinematics::ik::benchmark::random_targets;
use armsim::kinematics::ik::{solve_batch, IkOptions, IkSolver, IkStatus};
use armsim::kinematics::{forward_kinematics, frame_placement};
use armsim::model::data::Data;
use armsim::model::Model;

fn check_solution(m: &Model, link: usize, target: &Se3, q: &[f64], tol: f64) {
    assert!(m.within_limits(q, 0.0), "q outside limits: {q:?}");
    let mut d = Data::new(m);
    forward_kinematics(m, &mut d, q);
    let p = frame_placement(m, &d, link);
    let ep = (p.trans - target.trans).norm();
    let er = armsim::kinematics::ik::rotation_log(&(target.rot * p.rot.transpose())).norm();
    assert!(
        ep <= tol && er <= tol,
        "FK(q) misses the target: {ep:e} m, {er:e} rad"
    );
}

#[test]
fn reachable_targets_converge_inside_the_limits_on_every_arm() {
    for (file, link, n) in [
        ("robots/ur5.urdf", "tool0", 300),
        ("robots/panda.urdf", "panda_link8", 300),
        ("robots/iiwa14.urdf", "iiwa_link_ee", 300),
        ("robots/puma560.toml", "tool", 200),
        ("robots/stanford.toml", "tool", 200),
        ("robots/ur5_dh.toml", "tool", 100),
    ] {
        let m = common::load(file);
        let link = m.link_id(link).unwrap();
        let targets = random_targets(&m, link, n, 99);
        let results = solve_batch(&m, link, &targets, None, &IkOptions::default());
        for (t, r) in targets.iter().zip(&results) {
            assert_eq!(r.status, IkStatus::Converged, "{file}: {r:?}");
            assert!(r.position_error <= 1e-6 && r.rotation_error <= 1e-6);
            check_solution(&m, link, t, &r.q, 1e-6);
        }
    }
}

#[test]
fn tight_tolerance_and_position_only() {
    let m = common::load("robots/ur5.urdf");
    let link = m.link_id("tool0").unwrap();
    let targets = random_targets(&m, link, 50, 5);
    let tight = IkOptions {
        tol_position: 1e-12,
        tol_rotation: 1e-12,
        ..Default::default()
    };
    for r in solve_batch(&m, link, &targets, None, &tight) {
        assert_eq!(r.status, IkStatus::Converged, "{r:?}");
        assert!(r.position_error <= 1e-12 && r.rotation_error <= 1e-12);
    }
    let pos = IkOptions {
        position_only: true,
        ..Default::default()
    };
    let only_p: Vec<Se3> = targets
        .iter()
        .map(|t| Se3::from_translation(t.trans))
        .collect();
    for r in solve_batch(&m, link, &only_p, None, &pos) {
        assert_eq!(r.status, IkStatus::Converged);
        assert!(r.position_error <= 1e-6 && r.rotation_error == 0.0);
    }
}

#[test]
fn unreachable_targets_return_the_closest_pose_and_its_residual() {
    let m = common::load("robots/ur5.urdf");
    let link = m.link_id("tool0").unwrap();
    let mut solver = IkSolver::new(&m);
    let far = Se3::from_translation(Vec3::new(3.0, 0.0, 0.0));
    for position_only in [false, true] {
        let o = IkOptions {
            position_only,
            ..Default::default()
        };
        let r = solver.solve(&m, link, &far, None, &o);
        assert_eq!(r.status, IkStatus::Unreachable, "{r:?}");
        assert!(r.q.iter().all(|x| x.is_finite()) && m.within_limits(&r.q, 0.0));
        // The UR5 reaches about 0.95 m from its shoulder: the residual says how far off.
        assert!(
            r.position_error > 1.9 && r.position_error < 2.2,
            "{}",
            r.position_error
        );
        assert!(r.time_us < 60_000.0, "bounded time: {} µs", r.time_us);
    }
    // A non-finite target: no NaN in the answer.
    let r = solver.solve(
        &m,
        link,
        &Se3::from_translation(Vec3::new(f64::NAN, 0.0, 0.0)),
        None,
        &IkOptions::default(),
    );
    assert_eq!(r.status, IkStatus::Unreachable);
    assert!(r.q.iter().all(|x| x.is_finite()));
}

#[test]
fn boundary_singular_and_just_outside_targets() {
    let m = common::load("robots/ur5.urdf");
    let link = m.link_id("tool0").unwrap();
    let mut d = Data::new(&m);
    let mut solver = IkSolver::new(&m);
    let pose = |q: &[f64], d: &mut Data| {
        forward_kinematics(&m, d, q);
        frame_placement(&m, d, link)
    };
    // Elbow straight (workspace boundary, elbow singular), wrist singular (q5 = 0),
    // shoulder singular (wrist centre on the base axis is not reachable for the UR5's
    // offsets, so use q2 = -π/2, q3 = 0: the arm straight up), and a generic pose.
    for q in [
        [0.4, -0.7, 0.0, -1.0, 1.2, 0.3],
        [0.4, -0.7, 1.1, -1.0, 0.0, 0.3],
        [
            0.0,
            -std::f64::consts::FRAC_PI_2,
            0.0,
            -std::f64::consts::FRAC_PI_2,
            0.0,
            0.0,
        ],
    ] {
        let t = pose(&q, &mut d);
        let r = solver.solve(&m, link, &t, None, &IkOptions::default());
        assert_eq!(r.status, IkStatus::Converged, "{q:?}: {r:?}");
        check_solution(&m, link, &t, &r.q, 1e-6);
    }
    // 1 cm beyond the stretched arm, along the arm: unreachable, residual about 1 cm.
    let q = [0.4, -0.7, 0.0, -0.7, 1.2, 0.3];
    let t = pose(&q, &mut d);
    forward_kinematics(&m, &mut d, &q);
    let shoulder = frame_placement(&m, &d, m.link_id("upper_arm_link").unwrap()).trans;
    let out = (t.trans - shoulder).normalize();
    let beyond = Se3::from_translation(t.trans + out * 0.01);
    let o = IkOptions {
        position_only: true,
        ..Default::default()
    };
    let r = solver.solve(&m, link, &beyond, None, &o);
    assert_eq!(r.status, IkStatus::Unreachable, "{r:?}");
    assert!(
        r.position_error > 0.005 && r.position_error < 0.0101,
        "{}",
        r.position_error
    );
}

#[test]
fn redundant_arms_and_joints_that_do_not_move_the_link() {
    // Panda with its finger coordinate: the finger does not move panda_link8; it stays
    // where it started, and the 7 arm joints solve the pose.
    let m = common::load("robots/panda.urdf");
    let link = m.link_id("panda_link8").unwrap();
    let targets = random_targets(&m, link, 100, 3);
    let seed = m.neutral();
    for r in solve_batch(
        &m,
        link,
        &targets,
        Some(&seed),
        &IkOptions {
            max_restarts: 0,
            ..Default::default()
        },
    ) {
        if r.status == IkStatus::Converged && r.restarts == 0 {
            assert_eq!(r.q[7], seed[7], "the finger moved");
        }
        assert!(r.q.iter().all(|x| x.is_finite()));
    }
}

#[test]
fn batches_are_deterministic_and_independent_of_threads() {
    let m = common::load("robots/iiwa14.urdf");
    let link = m.link_id("iiwa_link_ee").unwrap();
    let targets = random_targets(&m, link, 40, 11);
    let o = IkOptions::default();
    let a = solve_batch(&m, link, &targets, None, &o);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let b = pool.install(|| solve_batch(&m, link, &targets, None, &o));
    let mut solver = IkSolver::new(&m);
    for (i, t) in targets.iter().enumerate() {
        let c = solver.solve(
            &m,
            link,
            t,
            None,
            &IkOptions {
                seed: o.seed + i as u64,
                ..o.clone()
            },
        );
        assert_eq!(a[i].q, b[i].q);
        assert_eq!(a[i].q, c.q);
        assert_eq!(a[i].iterations, c.iterations);
    }
}
