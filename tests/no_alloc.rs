//! The hot paths allocate nothing per call: a counting global allocator watches FK,
//! frame updates, joint Jacobians, frame Jacobians and their time derivatives, RNEA,
//! CRBA, ABA, Cholesky forward dynamics and the effect-aware dynamics; the planner's
//! collision checks allocate nothing, and a planning query allocates the same few buffers
//! whatever its number of iterations.

#[path = "common/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::allocs;

mod common;
mod plan_common;

use armsim::core::spatial::{Inertia, Mat3, Vec3};
use armsim::dynamics;
use armsim::kinematics::{self, Expressed};
use armsim::model::data::Data;
use armsim::model::Model;
use armsim::planning::checker::EdgeMode;
use armsim::planning::rrt::RrtOptions;
use armsim::planning::{PlanOptions, PlanStatus, Planner};
use nalgebra::DMatrix;

/// The counter is global: the tests of this file run one at a time.
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn serial() -> std::sync::MutexGuard<'static, ()> {
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}

#[test]
fn kinematics_hot_paths_do_not_allocate() {
    let _serial = serial();
    for file in [
        "robots/ur5.urdf",
        "robots/panda.urdf",
        "tests/data/mimic_gripper.urdf",
    ] {
        let model = common::load(file);
        let mut data = Data::new(&model);
        let q = model.neutral();
        let qd: Vec<f64> = (0..model.nv).map(|k| 0.1 * k as f64 - 0.2).collect();
        assert_kinematics_allocate_nothing(file, &model, &mut data, &q, &qd);
        // Dynamics, bare and with every effect.
        let after = assert_dynamics_allocate_nothing(file, &model, &mut data, &q, &qd);
        // The counter works: a Vec allocates.
        let v: Vec<f64> = Vec::with_capacity(8);
        assert!(allocs() > after);
        drop(v);
    }
}

/// FK, frame velocities and accelerations, and the frame Jacobians (and their time
/// variation) at the last link, 100 times without an allocation.
fn assert_kinematics_allocate_nothing(
    file: &str,
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
) {
    let tool = model.links.len() - 1;
    let mut j = DMatrix::zeros(6, model.nv);
    let before = allocs();
    for _ in 0..100 {
        kinematics::forward_kinematics(model, data, q);
        kinematics::update_frames(model, data);
        kinematics::forward_kinematics_acc(model, data, q, qd, qd);
        let _ = kinematics::frame_velocity(model, data, tool, Expressed::Local);
        let _ = kinematics::frame_classical_acceleration(model, data, tool, Expressed::World);
        kinematics::compute_joint_jacobians(model, data, q);
        for ex in [Expressed::World, Expressed::Local, Expressed::WorldAligned] {
            kinematics::frame_jacobian(model, data, tool, ex, &mut j);
            kinematics::compute_frame_jacobian(model, data, q, tool, ex, j.as_mut_slice());
        }
        kinematics::compute_joint_jacobians_time_variation(model, data, q, qd);
        kinematics::frame_jacobian_time_variation(
            model,
            data,
            tool,
            Expressed::WorldAligned,
            &mut j,
        );
    }
    let after = allocs();
    assert_eq!(
        after - before,
        0,
        "{file}: {} allocations in the hot loop",
        after - before
    );
}

/// Every effect at once on the link of the last body.
fn every_effect(model: &Model) -> dynamics::Effects {
    let tool = model
        .links
        .iter()
        .position(|l| l.body == model.nbodies() - 1)
        .unwrap();
    let n = model.nv;
    dynamics::Effects {
        gravity: Some(Vec3::new(0.0, 0.0, -9.81)),
        friction: Some(dynamics::Friction {
            viscous: vec![0.1; n],
            coulomb: vec![0.2; n],
            stiction: vec![0.3; n],
            stribeck_velocity: vec![0.1; n],
            smoothing: 1e-3,
        }),
        rotor: Some(dynamics::Rotor {
            inertia: vec![1e-4; n],
            gear_ratio: vec![50.0; n],
            efficiency: vec![0.9; n],
        }),
        elasticity: Some(dynamics::Elasticity {
            stiffness: vec![1e4; n],
            damping: vec![1.0; n],
            motor_inertia: vec![0.25; n],
        }),
        payload: Some(
            dynamics::Payload::new(
                model,
                tool,
                Inertia::new(1.0, Vec3::new(0.0, 0.0, 0.05), Mat3::identity() * 1e-3),
            )
            .unwrap(),
        ),
        external: vec![dynamics::ExternalWrench {
            link: tool,
            force: Vec3::new(1.0, 2.0, 3.0),
            moment: Vec3::zeros(),
        }],
    }
}

/// The dynamics, bare and with every effect, and their derivatives (after the first call
/// sized their buffers), 100 times without an allocation; returns
/// the allocation count after the loop.
fn assert_dynamics_allocate_nothing(
    file: &str,
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
) -> usize {
    let n = model.nv;
    let all = every_effect(model);
    let g = Vec3::new(0.0, 0.0, -9.81);
    let mut thdd = vec![0.0; n];
    let f_ext = vec![armsim::core::spatial::Force::new(Vec3::x(), Vec3::y()); model.nbodies()];
    // The derivatives size their buffers on their first call.
    let _ = dynamics::aba_derivatives(model, data, q, qd, qd);
    let rigid = dynamics::Effects {
        elasticity: None,
        ..all.clone()
    };
    let mut steps = [
        dynamics::StepScheme::SemiImplicitEuler,
        dynamics::StepScheme::Rk4,
    ]
    .map(|s| dynamics::StepLinearisation::new(model, s, 1e-3).unwrap());
    let before = allocs();
    for _ in 0..100 {
        dynamics::rnea_derivatives(model, data, q, qd, qd);
        dynamics::rnea_derivatives_with_forces(model, data, q, qd, qd, &f_ext);
        let _ = dynamics::aba_derivatives(model, data, q, qd, qd);
        let _ = dynamics::compute_minverse(model, data, q);
        dynamics::rnea(model, data, q, qd, qd);
        dynamics::rnea_with_forces(model, data, q, qd, qd, &f_ext);
        dynamics::bias(model, data, q, qd);
        dynamics::gravity_torque(model, data, q);
        dynamics::crba(model, data, q);
        if !model.has_mimic {
            dynamics::aba(model, data, q, qd, qd);
            dynamics::aba_with_forces(model, data, q, qd, qd, &f_ext);
        }
        let _ = dynamics::forward_dynamics(model, data, q, qd, qd);
        let _ = dynamics::forward_dynamics_crba(model, data, q, qd, qd);
        dynamics::inverse_dynamics(model, data, &all, q, qd, qd);
        dynamics::inverse_dynamics_derivatives(model, data, &rigid, q, qd, qd);
        let _ = dynamics::forward_dynamics_derivatives(model, data, &rigid, q, qd, qd);
        for s in &mut steps {
            let _ = s.linearise(model, data, &rigid, q, qd, qd);
        }
        dynamics::mass_matrix(model, data, &all, q);
        let _ = dynamics::forward_dynamics_with(model, data, &all, q, qd, qd);
        let _ = dynamics::elastic_forward_dynamics(model, data, &all, q, qd, q, qd, qd, &mut thdd);
        let _ = dynamics::kinetic_energy(model, data, q, qd)
            + dynamics::potential_energy(model, data, q, &g);
    }
    let after = allocs();
    assert_eq!(
        after - before,
        0,
        "{file}: {} allocations in the dynamics loop",
        after - before
    );
    after
}

/// Allocations made by `f`.
fn allocations(f: impl FnOnce()) -> usize {
    let before = allocs();
    f();
    allocs() - before
}

#[test]
fn planner_collision_checks_allocate_nothing_after_warm_up() {
    let _serial = serial();
    let robot = plan_common::Robot::load("panda");
    let p = &plan_common::problems(&robot, "table_pick")[1];
    let pl = Planner::new(
        &robot.model,
        &p.obstacles,
        Some(&robot.disabled),
        PlanOptions::default(),
    )
    .unwrap();
    let c = &pl.checker;
    let mut s = c.scratch();
    // 64 configurations spread over the joint box (a fixed LCG), some free, some not.
    let mut x = 12345u64;
    let qs: Vec<Vec<f32>> = (0..64)
        .map(|_| {
            (0..robot.model.nv)
                .map(|k| {
                    x = x
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    let u = (x >> 40) as f64 / (1u64 << 24) as f64;
                    let (lo, hi) = (robot.model.lower[k], robot.model.upper[k]);
                    (lo + u * (hi - lo)) as f32
                })
                .collect()
        })
        .collect();
    let mut free = (0, 0);
    let mut sweep = |s: &mut armsim::planning::CheckScratch| {
        free = (0, 0);
        for i in 0..qs.len() {
            free.0 += usize::from(c.config_free(&qs[i], s));
            let (a, b) = (&qs[i], &qs[(i + 1) % qs.len()]);
            free.1 += usize::from(c.edge_free(a, b, EdgeMode::Continuous, s));
            free.1 += usize::from(c.edge_free(a, b, EdgeMode::Discrete, s));
        }
    };
    sweep(&mut s);
    let n = allocations(|| {
        for _ in 0..3 {
            sweep(&mut s);
        }
    });
    assert_eq!(
        n, 0,
        "{n} allocations in 3 × 64 configuration and edge checks"
    );
    // Both outcomes were exercised.
    assert!(free.0 > 0 && free.0 < 64, "{free:?}");
    assert!(free.1 < 128, "{free:?}");
}

#[test]
fn planner_allocations_do_not_grow_with_iterations() {
    let _serial = serial();
    let robot = plan_common::Robot::load("panda");
    let query = |pl: &mut Planner, start: &[f64], goal: &[f64]| {
        let mut r = None;
        let n = allocations(|| r = Some(pl.plan(start, goal)));
        (n, r.unwrap())
    };
    // The impossible problem under 1000 and 10000 iterations: the same allocations.
    let (obstacles, start, goal) = plan_common::panda_wall_problem();
    let mut per_limit = Vec::new();
    for max_iterations in [1000, 10_000] {
        let opts = PlanOptions {
            rrt: RrtOptions {
                max_iterations,
                ..Default::default()
            },
            ..Default::default()
        };
        let mut pl = Planner::new(&robot.model, &obstacles, Some(&robot.disabled), opts).unwrap();
        let _warm_up = pl.plan(&start, &goal);
        let (n, r) = query(&mut pl, &start, &goal);
        assert_eq!(r.status, PlanStatus::Failed);
        assert_eq!(r.iterations, max_iterations);
        per_limit.push(n);
    }
    eprintln!("failed queries: allocations {per_limit:?} for 1000 / 10000 iterations");
    assert_eq!(
        per_limit[0], per_limit[1],
        "allocations grow with iterations"
    );
    assert!(per_limit[0] <= 8, "{} allocations per query", per_limit[0]);
    // Solved problems, simplified: the result's path and a few per-query buffers only,
    // whether the straight edge is free (0001) or the search takes long (the most
    // iterations among the first problems).
    let problems = plan_common::problems(&robot, "table_pick");
    let mut most = (0, 0);
    for (i, p) in problems
        .iter()
        .enumerate()
        .take(20)
        .filter(|(_, p)| p.valid)
    {
        let mut pl = Planner::new(
            &robot.model,
            &p.obstacles,
            Some(&robot.disabled),
            PlanOptions::default(),
        )
        .unwrap();
        let _warm_up = pl.plan(&p.start, &p.goal);
        let (n, r) = query(&mut pl, &p.start, &p.goal);
        assert_eq!(r.status, PlanStatus::Solved);
        assert!(
            n <= 8 + r.path.len(),
            "table_pick {}: {n} allocations for a path of {} points after {} iterations",
            p.id,
            r.path.len(),
            r.iterations
        );
        if r.iterations > most.1 {
            most = (i, r.iterations);
        }
    }
    assert!(
        most.1 >= 300,
        "the hardest of the first 20 took only {} iterations",
        most.1
    );
}

#[test]
fn robot_facade_calls_allocate_nothing_after_warm_up() {
    let _g = serial();
    let mut robot =
        armsim::Robot::from_file(concat!(env!("CARGO_MANIFEST_DIR"), "/robots/ur5.urdf")).unwrap();
    let tool = robot.frame("tool0").unwrap();
    let q = [0.3, -1.1, 1.3, -0.5, 1.2, 0.4];
    let v = [0.2, -0.3, 0.5, 0.1, -0.4, 0.6];
    let mut sum = 0.0;
    let mut calls = |robot: &mut armsim::Robot| {
        sum += robot.fk(&q).unwrap().pose(tool).trans.x;
        sum += robot.jacobian(&q, tool, Expressed::WorldAligned).unwrap()[(0, 0)];
        sum += robot.rnea(&q, &v, &v).unwrap()[0];
        sum += robot.gravity_torque(&q).unwrap()[1];
        sum += robot.crba(&q).unwrap()[(0, 0)];
        sum += robot.aba(&q, &v, &v).unwrap()[2];
        sum += robot.kinetic_energy(&q, &v).unwrap();
    };
    calls(&mut robot); // warm up
    let n = allocations(|| calls(&mut robot));
    assert_eq!(n, 0, "the facade allocated {n} times");
    assert!(sum.is_finite());
}
