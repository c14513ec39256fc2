//! The hot paths allocate nothing per call: a counting global allocator watches FK,
//! frame updates, joint Jacobians, frame Jacobians and their time derivatives, RNEA,
//! CRBA, ABA, Cholesky forward dynamics and the effect-aware dynamics.

mod common;

use armsim::data::Data;
use armsim::dynamics;
use armsim::kinematics::{self, Expressed};
use armsim::spatial::{Inertia, Mat3, Vec3};
use nalgebra::DMatrix;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;
static ALLOCS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::SeqCst);
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::SeqCst);
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn kinematics_hot_paths_do_not_allocate() {
    for file in [
        "robots/ur5.urdf",
        "robots/panda.urdf",
        "tests/data/mimic_gripper.urdf",
    ] {
        let model = common::load(file);
        let mut data = Data::new(&model);
        let mut j = DMatrix::zeros(6, model.nv);
        let q = model.neutral();
        let qd: Vec<f64> = (0..model.nv).map(|k| 0.1 * k as f64 - 0.2).collect();
        let tool = model.links.len() - 1;
        let before = ALLOCS.load(Ordering::SeqCst);
        for _ in 0..100 {
            kinematics::forward_kinematics(&model, &mut data, &q);
            kinematics::update_frames(&model, &mut data);
            kinematics::forward_kinematics_acc(&model, &mut data, &q, &qd, &qd);
            let _ = kinematics::frame_velocity(&model, &data, tool, Expressed::Local);
            let _ = kinematics::frame_classical_acceleration(&model, &data, tool, Expressed::World);
            kinematics::compute_joint_jacobians(&model, &mut data, &q);
            for ex in [Expressed::World, Expressed::Local, Expressed::WorldAligned] {
                kinematics::frame_jacobian(&model, &data, tool, ex, &mut j);
            }
            kinematics::compute_joint_jacobians_time_variation(&model, &mut data, &q, &qd);
            kinematics::frame_jacobian_time_variation(
                &model,
                &data,
                tool,
                Expressed::WorldAligned,
                &mut j,
            );
        }
        let after = ALLOCS.load(Ordering::SeqCst);
        assert_eq!(
            after - before,
            0,
            "{file}: {} allocations in the hot loop",
            after - before
        );
        // Dynamics, bare and with every effect.
        let tool = model
            .links
            .iter()
            .position(|l| l.body == model.nbodies() - 1)
            .unwrap();
        let n = model.nv;
        let all = dynamics::Effects {
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
                    &model,
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
        };
        let g = Vec3::new(0.0, 0.0, -9.81);
        let mut thdd = vec![0.0; n];
        let before = ALLOCS.load(Ordering::SeqCst);
        for _ in 0..100 {
            dynamics::rnea(&model, &mut data, &q, &qd, &qd, &g, None);
            dynamics::bias(&model, &mut data, &q, &qd, &g);
            dynamics::gravity_torque(&model, &mut data, &q, &g);
            dynamics::crba(&model, &mut data, &q);
            if !model.has_mimic {
                dynamics::aba(&model, &mut data, &q, &qd, &qd, &g, None);
            }
            let _ = dynamics::forward_dynamics_crba(&model, &mut data, &q, &qd, &qd, &g);
            dynamics::inverse_dynamics(&model, &mut data, &all, &q, &qd, &qd);
            dynamics::mass_matrix(&model, &mut data, &all, &q);
            let _ = dynamics::forward_dynamics_with(&model, &mut data, &all, &q, &qd, &qd);
            let _ = dynamics::elastic_forward_dynamics(
                &model, &mut data, &all, &q, &qd, &q, &qd, &qd, &mut thdd,
            );
            let _ = dynamics::kinetic_energy(&model, &mut data, &q, &qd)
                + dynamics::potential_energy(&model, &mut data, &q, &g);
        }
        let after = ALLOCS.load(Ordering::SeqCst);
        assert_eq!(
            after - before,
            0,
            "{file}: {} allocations in the dynamics loop",
            after - before
        );
        // The counter works: a Vec allocates.
        let v: Vec<f64> = Vec::with_capacity(8);
        assert!(ALLOCS.load(Ordering::SeqCst) > after);
        drop(v);
    }
}
