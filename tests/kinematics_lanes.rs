//! Batched frame placements in SIMD lanes (`kinematics::pose_lanes::PoseLanes`) against the
//! scalar `forward_kinematics` + `frame_placement`, for every link of every test robot
//! (links on the world included), the tail rows, the out-of-range and NaN fallbacks; and
//! bitwise the same on every instruction set.

mod common;

use armsim::core::simd_lanes::Isa;
use armsim::kinematics::pose_lanes::{PoseLanes, POSE_VALUES};
use armsim::kinematics::{forward_kinematics, frame_placement};
use armsim::model::data::Data;
use armsim::model::Model;
use rand::rngs::SmallRng;
use rand::SeedableRng;

/// `n` random configurations, row-major.
fn rows(m: &Model, n: usize, seed: u64) -> Vec<f64> {
    let mut rng = SmallRng::seed_from_u64(seed);
    (0..n).flat_map(|_| m.random_q(&mut rng)).collect()
}

/// The scalar pose of `link` at `q`, row-major 4 × 4.
fn scalar_pose(m: &Model, d: &mut Data, link: usize, q: &[f64]) -> Vec<f64> {
    forward_kinematics(m, d, q);
    let p = frame_placement(m, d, link);
    let mut out = vec![0.0; 16];
    for r in 0..3 {
        for c in 0..3 {
            out[4 * r + c] = p.rot[(r, c)];
        }
        out[4 * r + 3] = p.trans[r];
    }
    out[15] = 1.0;
    out
}

#[test]
fn lane_poses_equal_the_scalar_frame_placements_for_every_link() {
    for (name, m) in common::test_models(12) {
        let n = 8 * 3 + 5;
        let q = rows(&m, n, 4);
        let mut d = Data::new(&m);
        for link in 0..m.links.len() {
            let mut lanes = PoseLanes::new(&m, link);
            let mut out = vec![f64::NAN; n * POSE_VALUES];
            lanes.frame_poses(&m, &q, &mut out);
            for r in 0..n {
                let want = scalar_pose(&m, &mut d, link, &q[r * m.nv..(r + 1) * m.nv]);
                let got = &out[r * POSE_VALUES..(r + 1) * POSE_VALUES];
                for (g, w) in got.iter().zip(&want) {
                    assert!(
                        (g - w).abs() <= 1e-12,
                        "{name} link {link} row {r}: {got:?} != {want:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn lane_poses_are_bitwise_the_same_on_every_instruction_set() {
    for (name, m) in common::test_models(12) {
        let n = 64;
        let q = rows(&m, n, 6);
        let link = m.links.len() - 1;
        let mut base = vec![0.0; n * POSE_VALUES];
        let mut lanes = PoseLanes::new(&m, link);
        lanes.limit_isa(Isa::Baseline);
        lanes.frame_poses(&m, &q, &mut base);
        for isa in [Isa::Avx2, Isa::Avx512] {
            let mut lanes = PoseLanes::new(&m, link);
            lanes.limit_isa(isa);
            let mut out = vec![0.0; n * POSE_VALUES];
            lanes.frame_poses(&m, &q, &mut out);
            let same = out
                .iter()
                .zip(&base)
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same, "{name}: {isa:?} differs from the baseline");
        }
    }
}

#[test]
fn out_of_range_and_nan_rows_go_through_the_scalar_fk() {
    let m = common::load("robots/panda.urdf");
    let link = m.links.len() - 1;
    let mut q = rows(&m, 16, 8);
    q[3 * m.nv + 2] = 3.0e6; // group 0: out of the lane sin_cos's range
    q[9 * m.nv + 1] = f64::NAN; // group 1: not finite
    let mut out = vec![0.0; 16 * POSE_VALUES];
    PoseLanes::new(&m, link).frame_poses(&m, &q, &mut out);
    let mut d = Data::new(&m);
    for r in 0..16 {
        let want = scalar_pose(&m, &mut d, link, &q[r * m.nv..(r + 1) * m.nv]);
        let got = &out[r * POSE_VALUES..(r + 1) * POSE_VALUES];
        for (g, w) in got.iter().zip(&want) {
            assert!(
                g.to_bits() == w.to_bits() || (g - w).abs() <= 1e-12,
                "row {r}: {g} != {w}"
            );
        }
    }
    assert!(out[9 * POSE_VALUES..10 * POSE_VALUES]
        .iter()
        .any(|x| x.is_nan()));
}
