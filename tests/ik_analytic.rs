//! Analytic IK: every returned solution is checked against the model's own forward
//! kinematics (not the solver's DH table), the configuration that produced the target
//! must be among the solutions, branch counts are compared with the geometry (and with an
//! independent Newton search from many starts), and the parameters read from the models
//! are compared with the numbers typed from the robot files.

mod common;

use armsim::core::spatial::{rot_z, Mat3, Se3, Vec3};
use armsim::kinematics::ik::analytic::{
    self, rrp_ik, ur_ik, ur_ik_with, wrist_ik, AnalyticKind, AnalyticOptions, AnalyticSolution,
    AnalyticSolver, DhChain, IkError, RawSolution, UrParams, WristParams,
};
use armsim::kinematics::{
    compute_joint_jacobians, forward_kinematics, frame_jacobian, frame_placement, Expressed,
};
use armsim::model::data::Data;
use armsim::model::Model;
use common::load;
use nalgebra::{DMatrix, Matrix6, Vector6};
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use std::collections::HashSet;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

const POSE_TOL: f64 = 1e-10;

fn fk(model: &Model, data: &mut Data, link: usize, q: &[f64]) -> Se3 {
    forward_kinematics(model, data, q);
    frame_placement(model, data, link)
}

/// Largest entry of the translation and rotation differences.
fn pose_err(a: &Se3, b: &Se3) -> f64 {
    (a.trans - b.trans).amax().max((a.rot - b.rot).amax())
}

/// Distance between two angles modulo 2π.
fn ang(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(TAU);
    d.min(TAU - d)
}

/// Joint-space distance, modulo 2π on revolute joints.
fn qdist(model: &Model, a: &[f64], b: &[f64]) -> f64 {
    (0..a.len())
        .map(|k| {
            if model.joints[model.dof_joints[k]].jtype == armsim::model::JointType::Prismatic {
                (a[k] - b[k]).abs()
            } else {
                ang(a[k], b[k])
            }
        })
        .fold(0.0, f64::max)
}

fn random_q(model: &Model, rng: &mut SmallRng) -> Vec<f64> {
    (0..model.nv)
        .map(|k| {
            let (lo, hi) = (model.lower[k].max(-PI), model.upper[k].min(PI));
            let (lo, hi) = if model.lower[k] >= -TAU && model.upper[k] <= TAU {
                (model.lower[k], model.upper[k])
            } else {
                (lo, hi)
            };
            rng.random_range(lo..hi)
        })
        .collect()
}

fn in_limits(model: &Model, q: &[f64]) -> bool {
    q.iter()
        .enumerate()
        .all(|(k, &v)| v >= model.lower[k] && v <= model.upper[k])
}

struct Stats {
    worst_pose: f64,
    worst_orig: f64,
    counts: [usize; 9],
}

/// FK → solve → check every solution, the original among them, and the count.
fn roundtrip(
    model: &Model,
    link: &str,
    samples: usize,
    seed: u64,
    respect_limits: bool,
    expect_count: Option<usize>,
) -> Stats {
    let link = model.link_id(link).expect("link exists");
    let solver = AnalyticSolver::new(model, link).expect("supported");
    let mut data = Data::new(model);
    let mut rng = SmallRng::seed_from_u64(seed);
    let opts = AnalyticOptions {
        seed: None,
        respect_limits,
    };
    let mut st = Stats {
        worst_pose: 0.0,
        worst_orig: 0.0,
        counts: [0; 9],
    };
    for _ in 0..samples {
        let q0 = random_q(model, &mut rng);
        let target = fk(model, &mut data, link, &q0);
        let sols = solver
            .solve(&target, &opts)
            .unwrap_or_else(|e| panic!("q0 = {q0:?}: {e}"));
        st.counts[sols.len()] += 1;
        let mut labels = HashSet::new();
        for s in &sols {
            assert!(s.q.iter().all(|v| v.is_finite()));
            if respect_limits {
                assert!(in_limits(model, &s.q), "{:?} outside the limits", s.q);
            }
            let got = fk(model, &mut data, link, &s.q);
            let e = if solver.kind().position_only() {
                (got.trans - target.trans).amax()
            } else {
                pose_err(&got, &target)
            };
            assert!(
                e <= POSE_TOL,
                "q0 = {q0:?}: solution {:?} ({}) misses the pose by {e:e}",
                s.q,
                s.branch
            );
            st.worst_pose = st.worst_pose.max(e);
            assert!(
                labels.insert(s.branch.clone()),
                "duplicate label {}",
                s.branch
            );
        }
        let d = sols
            .iter()
            .map(|s| qdist(model, &s.q, &q0))
            .fold(f64::INFINITY, f64::min);
        assert!(
            d < 1e-8,
            "q0 = {q0:?} not among the {} solutions (closest {d:e}): {:?}",
            sols.len(),
            sols.iter().map(|s| &s.q).collect::<Vec<_>>()
        );
        st.worst_orig = st.worst_orig.max(d);
        if let Some(n) = expect_count {
            if !sols.iter().any(|s| s.singular) {
                assert_eq!(sols.len(), n, "q0 = {q0:?}");
            }
        }
    }
    st
}

// ---------------------------------------------------------------- parameters

#[test]
fn ur5_parameters_read_from_both_models_match_the_dh_file() {
    let file = UrParams::ur5();
    for (path, link) in [("robots/ur5_dh.toml", "tool"), ("robots/ur5.urdf", "tool0")] {
        let m = load(path);
        let p = UrParams::from_model(&m, m.link_id(link).unwrap()).unwrap();
        for (k, (a, b)) in p.rows.iter().zip(&file.rows).enumerate() {
            for (x, y, what) in [
                (a.theta, b.theta, "theta"),
                (a.d, b.d, "d"),
                (a.a, b.a, "a"),
                (a.alpha, b.alpha, "alpha"),
            ] {
                assert!(
                    (x - y).abs() < 1e-12,
                    "{path} row {}: {what} {x} vs {y}",
                    k + 1
                );
            }
        }
        assert!(pose_err(&p.base, &Se3::from_rotation(rot_z(PI))) < 1e-12);
        assert!(pose_err(&p.tool, &Se3::identity()) < 1e-12, "{path}");
        assert_eq!(p.lower, [-TAU; 6]);
    }
    // The typed table reproduces the URDF's own FK (an independent description).
    let m = load("robots/ur5.urdf");
    let link = m.link_id("tool0").unwrap();
    let mut data = Data::new(&m);
    let mut rng = SmallRng::seed_from_u64(1);
    for _ in 0..100 {
        let q = random_q(&m, &mut rng);
        let qa: [f64; 6] = q.clone().try_into().unwrap();
        assert!(pose_err(&file.fk(&qa), &fk(&m, &mut data, link, &q)) < 1e-12);
    }
}

#[test]
fn puma_and_stanford_tables_read_from_the_models() {
    let m = load("robots/puma560.toml");
    let p = WristParams::from_model(&m, m.link_id("link6").unwrap()).unwrap();
    let file = WristParams::puma560();
    assert_eq!(p.arm, analytic::WristArm::Rrr);
    for (a, b) in p.rows.iter().zip(&file.rows) {
        assert!((a.theta - b.theta).abs() < 1e-12);
        assert!((a.d - b.d).abs() < 1e-12 && (a.a - b.a).abs() < 1e-12);
        assert!((a.alpha - b.alpha).abs() < 1e-12);
    }
    for k in 0..6 {
        assert!((p.lower[k] - file.lower[k]).abs() < 1e-12);
        assert!((p.upper[k] - file.upper[k]).abs() < 1e-12);
    }
    // Stanford: the rebuilt table may differ from the file by sign conventions; the
    // invariant lengths are the file's (d1 = 0.412, |d2| = 0.154, d6 = 0.263, a = 0).
    let m = load("robots/stanford.toml");
    let p = WristParams::from_model(&m, m.link_id("link6").unwrap()).unwrap();
    assert_eq!(p.arm, analytic::WristArm::Rrp);
    assert!((p.rows[0].d - 0.412).abs() < 1e-12);
    assert!((p.rows[1].d.abs() - 0.154).abs() < 1e-12);
    assert!((p.rows[5].d - 0.263).abs() < 1e-12);
    assert!(p.rows.iter().all(|r| r.a == 0.0));
    assert!(!p.rows[2].revolute && p.rows[2].d == 0.0);
    // Both typed tables reproduce the model FK.
    let mut rng = SmallRng::seed_from_u64(2);
    for (path, typed) in [
        ("robots/puma560.toml", WristParams::puma560()),
        ("robots/stanford.toml", WristParams::stanford()),
    ] {
        let m = load(path);
        let link = m.link_id("link6").unwrap();
        let mut data = Data::new(&m);
        for _ in 0..100 {
            let q = random_q(&m, &mut rng);
            let qa: [f64; 6] = q.clone().try_into().unwrap();
            assert!(pose_err(&typed.fk(&qa), &fk(&m, &mut data, link, &q)) < 1e-12);
        }
    }
}

#[test]
fn families_are_recognised_and_others_rejected() {
    let cases = [
        ("robots/ur5_dh.toml", "tool", AnalyticKind::Ur),
        ("robots/ur5.urdf", "tool0", AnalyticKind::Ur),
        ("robots/puma560.toml", "link6", AnalyticKind::WristRrr),
        ("robots/stanford.toml", "link6", AnalyticKind::WristRrp),
        (
            "robots/textbook_spherical_rrp.toml",
            "tool",
            AnalyticKind::SphericalRrp,
        ),
        ("robots/planar_2r.toml", "tool", AnalyticKind::Planar2r),
    ];
    for (path, link, kind) in cases {
        let m = load(path);
        let s = AnalyticSolver::new(&m, m.link_id(link).unwrap()).unwrap();
        assert_eq!(s.kind(), kind, "{path}");
    }
    for (path, link) in [
        ("robots/panda_mdh.toml", "tool"),
        ("robots/textbook_5r.toml", "tool"),
        ("robots/textbook_articulated_rrr.toml", "tool"),
    ] {
        let m = load(path);
        match AnalyticSolver::new(&m, m.link_id(link).unwrap()) {
            Err(IkError::Unsupported(msg)) => assert!(msg.contains("matches none"), "{msg}"),
            other => panic!("{path}: {other:?}"),
        }
    }
    // Asking for the wrong family names the mismatch.
    let m = load("robots/puma560.toml");
    let e = AnalyticSolver::with_kind(&m, m.link_id("link6").unwrap(), AnalyticKind::Ur);
    assert!(matches!(e, Err(IkError::Unsupported(ref s)) if s.contains("not a UR-type arm")));
    // A link short of the end of the chain has fewer joints than coordinates.
    let e = AnalyticSolver::new(&m, m.link_id("link3").unwrap());
    assert!(matches!(e, Err(IkError::Unsupported(ref s)) if s.contains("coordinates")));
}

// ---------------------------------------------------------------- UR

#[test]
fn ur5_dh_and_urdf_roundtrip_2000_poses() {
    // A UR has 8 solutions only where all four (shoulder, wrist) pairs leave the wrist-1
    // point within the elbow's reach: the wrist roots put it at p5 ∓ d5 (z1 × z6)/|z1 × z6|,
    // 2 d5 apart, so near the workspace boundary 6, 4 or 2 remain (always in elbow pairs).
    // The Newton test below checks that the missing ones do not exist.
    for (path, link) in [("robots/ur5_dh.toml", "tool"), ("robots/ur5.urdf", "tool0")] {
        let m = load(path);
        let st = roundtrip(&m, link, 2000, 11, true, None);
        eprintln!(
            "{path}: worst pose error {:.2e}, worst distance to q0 {:.2e}, counts {:?}",
            st.worst_pose, st.worst_orig, st.counts
        );
        assert!(
            st.counts.iter().skip(1).step_by(2).all(|&c| c == 0),
            "{:?}",
            st.counts
        );
        assert!(
            st.counts[8] > 1400,
            "most random poses have all 8: {:?}",
            st.counts
        );
    }
}

#[test]
fn ur5_labels_are_the_eight_combinations() {
    let m = load("robots/ur5_dh.toml");
    let link = m.link_id("tool").unwrap();
    let solver = AnalyticSolver::new(&m, link).unwrap();
    let mut data = Data::new(&m);
    let mut rng = SmallRng::seed_from_u64(3);
    let mut want = HashSet::new();
    for s in ["right", "left"] {
        for e in ["up", "down"] {
            for w in ["up", "down"] {
                want.insert(format!("shoulder-{s}/elbow-{e}/wrist-{w}"));
            }
        }
    }
    let mut full = 0;
    for _ in 0..300 {
        let q = random_q(&m, &mut rng);
        let sols = solver
            .solve(&fk(&m, &mut data, link, &q), &AnalyticOptions::default())
            .unwrap();
        let got: HashSet<String> = sols.iter().map(|s| s.branch.clone()).collect();
        assert_eq!(got.len(), sols.len(), "labels are distinct");
        assert!(got.is_subset(&want), "{got:?}");
        if sols.len() == 8 {
            assert_eq!(got, want);
            full += 1;
        }
    }
    assert!(full > 200);
}

#[test]
fn ur5_fast_path_with_typed_parameters() {
    let m = load("robots/ur5.urdf");
    let link = m.link_id("tool0").unwrap();
    let p = UrParams::ur5();
    let mut data = Data::new(&m);
    let mut rng = SmallRng::seed_from_u64(4);
    let mut out: Vec<RawSolution<6>> = Vec::with_capacity(8);
    let mut worst: f64 = 0.0;
    for _ in 0..2000 {
        let q = random_q(&m, &mut rng);
        let target = fk(&m, &mut data, link, &q);
        let n = ur_ik(&p, &target, &mut out).unwrap();
        assert_eq!(n, out.len(), "±2π limits keep every solution");
        assert!(n.is_multiple_of(2) && n >= 2);
        assert!(out.iter().any(|s| qdist(&m, &s.q, &q) < 1e-8));
        for s in &out {
            worst = worst.max(pose_err(&fk(&m, &mut data, link, &s.q), &target));
            assert!(
                s.q.iter().all(|v| v.abs() <= PI + 1e-12),
                "wrapped towards 0"
            );
        }
    }
    assert!(worst <= POSE_TOL, "{worst:e}");
}

/// An independent count of the solutions: Gauss–Newton on the model's FK and geometric
/// Jacobian, from many random starts. Every solution it converges to
/// must be one the closed form returned (nothing missed).
#[test]
fn ur5_newton_from_random_starts_finds_no_solution_the_closed_form_missed() {
    let m = load("robots/ur5_dh.toml");
    let link = m.link_id("tool").unwrap();
    let solver = AnalyticSolver::new(&m, link).unwrap();
    let mut data = Data::new(&m);
    let mut rng = SmallRng::seed_from_u64(5);
    let opts = AnalyticOptions {
        seed: None,
        respect_limits: false,
    };
    let (mut found_total, mut analytic_total) = (0, 0);
    let (mut full, mut partial) = (0, 0);
    while full + partial < 16 {
        let q0 = random_q(&m, &mut rng);
        let target = fk(&m, &mut data, link, &q0);
        let sols = solver.solve(&target, &opts).unwrap();
        // Half the targets with all 8 solutions, half with fewer.
        if sols.len() == 8 {
            if full == 8 {
                continue;
            }
            full += 1;
        } else {
            if partial == 8 {
                continue;
            }
            partial += 1;
        }
        let newton = newton_solutions(&m, &mut data, link, &target, 100, &mut rng);
        for qn in &newton {
            let d = sols
                .iter()
                .map(|s| qdist(&m, &s.q, qn))
                .fold(f64::INFINITY, f64::min);
            assert!(
                d < 1e-6,
                "Newton found {qn:?}, not among the closed-form solutions"
            );
        }
        found_total += newton.len();
        analytic_total += sols.len();
    }
    eprintln!("Newton found {found_total} distinct solutions, the closed form {analytic_total}");
    // The starts must cover most basins for the comparison to mean anything.
    assert!(found_total * 10 >= analytic_total * 8);
}

fn newton_solutions(
    m: &Model,
    data: &mut Data,
    link: usize,
    target: &Se3,
    starts: usize,
    rng: &mut SmallRng,
) -> Vec<Vec<f64>> {
    let mut jac = DMatrix::zeros(6, m.nv);
    let mut found: Vec<Vec<f64>> = Vec::new();
    for _ in 0..starts {
        let mut q: Vec<f64> = (0..6).map(|_| rng.random_range(-PI..PI)).collect();
        for _ in 0..60 {
            compute_joint_jacobians(m, data, &q);
            let t = frame_placement(m, data, link);
            // Position error and the small-angle rotation error, world axes.
            let dp = target.trans - t.trans;
            let mut dr = Vec3::zeros();
            for c in 0..3 {
                dr += t.rot.column(c).cross(&target.rot.column(c)) * 0.5;
            }
            let e = Vector6::new(dp.x, dp.y, dp.z, dr.x, dr.y, dr.z);
            if e.norm() < 1e-14 {
                break;
            }
            frame_jacobian(m, data, link, Expressed::WorldAligned, &mut jac);
            let j = Matrix6::from_iterator(jac.iter().copied());
            let a = j.transpose() * j + Matrix6::identity() * 1e-12;
            let Some(dq) = a.lu().solve(&(j.transpose() * e)) else {
                break;
            };
            let scale = (0.5 / dq.amax()).min(1.0);
            for k in 0..6 {
                q[k] += scale * dq[k];
            }
        }
        let t = fk(m, data, link, &q);
        if pose_err(&t, target) < 1e-9 {
            let q: Vec<f64> = q.iter().map(|v| (v + PI).rem_euclid(TAU) - PI).collect();
            if !found.iter().any(|f| qdist(m, f, &q) < 1e-6) {
                found.push(q);
            }
        }
    }
    found
}

// ---------------------------------------------------------------- Puma, Stanford

#[test]
fn puma_roundtrip_all_8_branches_and_inside_limits() {
    let m = load("robots/puma560.toml");
    let st = roundtrip(&m, "link6", 2000, 21, false, Some(8));
    eprintln!(
        "puma (no limits): worst pose {:.2e}, worst q0 distance {:.2e}, counts {:?}",
        st.worst_pose, st.worst_orig, st.counts
    );
    let st = roundtrip(&m, "link6", 2000, 22, true, None);
    eprintln!(
        "puma (limits): worst pose {:.2e}, counts {:?}",
        st.worst_pose, st.counts
    );
    assert_eq!(st.counts[0], 0);
}

#[test]
fn puma_zero_pose_is_the_righty_arm() {
    // Corke's Puma 560 is "righty" at its zero pose (robots/puma560.toml).
    let m = load("robots/puma560.toml");
    let link = m.link_id("link6").unwrap();
    let mut data = Data::new(&m);
    let q0 = [0.0, 0.3, -0.4, 0.2, 0.5, 0.1];
    let target = fk(&m, &mut data, link, &q0);
    let sols = analytic::solve(&m, link, &target).unwrap();
    let own = sols.iter().find(|s| qdist(&m, &s.q, &q0) < 1e-8).unwrap();
    assert!(own.branch.starts_with("shoulder-right"), "{}", own.branch);
    assert!(own.branch.ends_with("wrist-up"), "{}", own.branch);
}

#[test]
fn stanford_roundtrip_8_mathematical_4_with_positive_boom() {
    let m = load("robots/stanford.toml");
    let st = roundtrip(&m, "link6", 2000, 31, false, Some(8));
    eprintln!(
        "stanford (no limits): worst pose {:.2e}, counts {:?}",
        st.worst_pose, st.counts
    );
    let st = roundtrip(&m, "link6", 2000, 32, true, None);
    eprintln!(
        "stanford (limits): worst pose {:.2e}, counts {:?}",
        st.worst_pose, st.counts
    );
    // Exactly half of the mathematical solutions extend the boom positively.
    let link = m.link_id("link6").unwrap();
    let solver = AnalyticSolver::new(&m, link).unwrap();
    let mut data = Data::new(&m);
    let mut rng = SmallRng::seed_from_u64(33);
    for _ in 0..200 {
        let q = random_q(&m, &mut rng);
        let all = solver
            .solve(
                &fk(&m, &mut data, link, &q),
                &AnalyticOptions {
                    seed: None,
                    respect_limits: false,
                },
            )
            .unwrap();
        let pos: Vec<&AnalyticSolution> = all.iter().filter(|s| s.q[2] > 0.0).collect();
        assert_eq!(pos.len(), 4);
        assert!(pos.iter().all(|s| s.branch.contains("extension-positive")));
    }
}

#[test]
fn wrist_fast_path_with_typed_puma() {
    let m = load("robots/puma560.toml");
    let link = m.link_id("link6").unwrap();
    let p = WristParams::puma560();
    let mut data = Data::new(&m);
    let mut rng = SmallRng::seed_from_u64(6);
    let mut out = Vec::with_capacity(8);
    for _ in 0..500 {
        let q = random_q(&m, &mut rng);
        let target = fk(&m, &mut data, link, &q);
        let n = wrist_ik(&p, &target, &mut out).unwrap();
        assert_eq!(n, 8);
        assert!(out.iter().any(|s| qdist(&m, &s.q, &q) < 1e-8));
        for s in &out {
            assert!(pose_err(&fk(&m, &mut data, link, &s.q), &target) <= POSE_TOL);
        }
    }
}

// ---------------------------------------------------------------- singularities

#[test]
fn ur5_wrist_singular_exact_and_near() {
    let m = load("robots/ur5_dh.toml");
    let link = m.link_id("tool").unwrap();
    let solver = AnalyticSolver::new(&m, link).unwrap();
    let mut data = Data::new(&m);
    let q0 = [0.4, -1.1, 1.3, -0.6, 0.0, 0.9];
    let target = fk(&m, &mut data, link, &q0);
    let seed = vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.7];
    let sols = solver
        .solve(
            &target,
            &AnalyticOptions {
                seed: Some(seed),
                respect_limits: true,
            },
        )
        .unwrap();
    // θ5 depends on the shoulder root only: on q0's root the two wrist roots coincide
    // (2 elbow solutions, singular), the other root has 4 regular ones.
    assert_eq!(sols.len(), 6);
    let singular: Vec<&AnalyticSolution> = sols.iter().filter(|s| s.singular).collect();
    assert_eq!(singular.len(), 2);
    for s in &sols {
        assert!(pose_err(&fk(&m, &mut data, link, &s.q), &target) <= POSE_TOL);
        assert!(!s.singularity.shoulder && !s.singularity.elbow);
    }
    for s in &singular {
        assert!(s.singularity.wrist);
        assert_eq!(s.q[5], 0.7, "the free joint takes the seed");
        assert!(s.q[4].abs() < 1e-12);
        assert!(ang(s.q[0], q0[0]) < 1e-9);
    }
    // Default seed: the free joint is 0.
    let sols = analytic::solve(&m, link, &target).unwrap();
    assert!(sols.iter().filter(|s| s.singular).all(|s| s.q[5] == 0.0));
    // The family: axis 6 is parallel to axes 2-4, so only q2 + q3 + q4 + q6 is fixed.
    let sum = |q: &[f64]| q[1] + q[2] + q[3] + q[5];
    assert!(sols
        .iter()
        .filter(|s| s.singular)
        .all(|s| ang(sum(&s.q), sum(&q0)) < 1e-9));

    // 1e-12 away: two distinct wrist roots, flagged, exact.
    let q1 = [0.4, -1.1, 1.3, -0.6, 1e-12, 0.9];
    let target = fk(&m, &mut data, link, &q1);
    let sols = analytic::solve(&m, link, &target).unwrap();
    assert_eq!(sols.len(), 8);
    for s in &sols {
        assert!(s.q.iter().all(|v| v.is_finite()));
        assert!(pose_err(&fk(&m, &mut data, link, &s.q), &target) <= POSE_TOL);
    }
    let flagged: Vec<&AnalyticSolution> = sols.iter().filter(|s| s.singularity.wrist).collect();
    assert_eq!(flagged.len(), 4, "both wrist roots of q0's shoulder root");
    assert!(flagged
        .iter()
        .all(|s| s.q[4].abs() < 1e-11 && ang(s.q[0], q0[0]) < 1e-9));
    // Nearly stretched elbow: with q6 at a seed half a turn from q0's, the wrist-1 point
    // (on a circle of radius d5 as q6 varies) is out of the elbow's reach; the solver
    // takes the reachable member nearest the seed instead of dropping the branch.
    let q3 = [0.2, -0.8, 0.05, 0.3, 0.0, 1.0];
    let target = fk(&m, &mut data, link, &q3);
    let (mut kept, mut moved) = (0, 0);
    for k in 0..24 {
        let seed6 = -PI + k as f64 * PI / 12.0;
        let sols = solver
            .solve(
                &target,
                &AnalyticOptions {
                    seed: Some(vec![0.0, 0.0, 0.0, 0.0, 0.0, seed6]),
                    respect_limits: true,
                },
            )
            .unwrap();
        let singular: Vec<&AnalyticSolution> = sols.iter().filter(|s| s.singular).collect();
        assert_eq!(singular.len(), 2, "seed6 = {seed6}");
        for s in &sols {
            assert!(pose_err(&fk(&m, &mut data, link, &s.q), &target) <= POSE_TOL);
        }
        for s in &singular {
            assert!(ang(sum(&s.q), sum(&q3)) < 1e-9);
            if ang(s.q[5], seed6) < 1e-12 {
                kept += 1;
            } else {
                moved += 1;
            }
        }
    }
    assert!(kept > 0 && moved > 0, "kept {kept}, moved {moved}");

    // 1e-3 away: not flagged.
    let q2 = [0.4, -1.1, 1.3, -0.6, 1e-3, 0.9];
    let sols = analytic::solve(&m, link, &fk(&m, &mut data, link, &q2)).unwrap();
    assert!(sols.iter().all(|s| !s.singular));
    assert!(sols.iter().any(|s| qdist(&m, &s.q, &q2) < 1e-8));
}

#[test]
fn puma_wrist_singular_exact_and_near() {
    let m = load("robots/puma560.toml");
    let link = m.link_id("link6").unwrap();
    let mut data = Data::new(&m);
    for q5 in [0.0, 1e-12, -1e-12] {
        let q0 = [0.3, 0.5, -0.8, 0.4, q5, -0.2];
        let target = fk(&m, &mut data, link, &q0);
        let sols = analytic::solve_with(
            &m,
            link,
            &target,
            &AnalyticOptions {
                seed: Some(vec![0.0, 0.0, 0.0, 0.0, 0.0, 1.1]),
                respect_limits: false,
            },
        )
        .unwrap();
        // Each arm configuration has its own θ5: only q0's is singular (one solution
        // when exact, both wrist roots when 1e-12 away); the other three give 2 each.
        assert_eq!(sols.len(), if q5 == 0.0 { 7 } else { 8 }, "q5 = {q5}");
        let flagged: Vec<&AnalyticSolution> = sols.iter().filter(|s| s.singular).collect();
        assert_eq!(flagged.len(), if q5 == 0.0 { 1 } else { 2 });
        for s in &flagged {
            assert!(s.singularity.wrist);
            assert!(ang(s.q[1], q0[1]) < 1e-9 && ang(s.q[2], q0[2]) < 1e-9);
            if q5 == 0.0 {
                assert_eq!(s.q[5], 1.1);
            }
        }
        for s in &sols {
            assert!(s.q.iter().all(|v| v.is_finite()));
            let e = pose_err(&fk(&m, &mut data, link, &s.q), &target);
            assert!(e <= POSE_TOL, "q5 = {q5}: {e:e}");
        }
    }
}

#[test]
fn shoulder_singular_targets() {
    // UR5 with axes 2-3 vertical and 4 horizontal: the wrist point lies in the plane of
    // axes 1 and 2 (R = d4), where the two shoulder roots merge.
    let m = load("robots/ur5_dh.toml");
    let link = m.link_id("tool").unwrap();
    let mut data = Data::new(&m);
    let q0 = [0.3, FRAC_PI_2, 0.0, -FRAC_PI_2, 0.7, 0.2];
    let target = fk(&m, &mut data, link, &q0);
    let sols = analytic::solve(&m, link, &target).unwrap();
    assert!(!sols.is_empty());
    for s in &sols {
        assert!(s.singularity.shoulder, "{}", s.branch);
        assert!(pose_err(&fk(&m, &mut data, link, &s.q), &target) <= POSE_TOL);
    }
    assert!(sols.iter().any(|s| qdist(&m, &s.q, &q0) < 1e-6));

    // Puma: wrist centre in the plane of axes 1 and 2 (X = 0 in frame 1).
    let m = load("robots/puma560.toml");
    let link = m.link_id("link6").unwrap();
    let th3 = (-0.4318f64).atan2(0.0203);
    let q0 = [0.2, FRAC_PI_2, th3, 0.3, 0.6, 0.1];
    let target = fk(&m, &mut data_for(&m), link, &q0);
    let opts = AnalyticOptions {
        seed: None,
        respect_limits: false,
    };
    let sols = analytic::solve_with(&m, link, &target, &opts).unwrap();
    let mut d2 = Data::new(&m);
    for s in &sols {
        assert!(s.singularity.shoulder);
        assert!(pose_err(&fk(&m, &mut d2, link, &s.q), &target) <= POSE_TOL);
    }

    // Spherical RRP: target on axis 1; joint 1 is free and takes the seed.
    let m = load("robots/textbook_spherical_rrp.toml");
    let link = m.link_id("tool").unwrap();
    let target = Se3::from_translation(Vec3::new(0.0, 0.0, 1.0));
    let opts = AnalyticOptions {
        seed: Some(vec![0.4, 0.0, 0.0]),
        respect_limits: false,
    };
    let sols = analytic::solve_with(&m, link, &target, &opts).unwrap();
    assert_eq!(sols.len(), 2);
    let mut d3 = Data::new(&m);
    for s in &sols {
        assert!(s.singularity.shoulder);
        assert_eq!(s.q[0], 0.4);
        let got = fk(&m, &mut d3, link, &s.q);
        assert!((got.trans - target.trans).amax() <= POSE_TOL);
    }
    // Inside the limits (b2 ≤ 60°) the axis cannot be reached.
    let e = analytic::solve(&m, link, &target);
    assert!(
        matches!(e, Err(IkError::OutsideLimits { candidates: 2 })),
        "{e:?}"
    );

    // Planar 2R at its base: joint 1 free, folded elbow.
    let m = load("robots/planar_2r.toml");
    let link = m.link_id("tool").unwrap();
    let opts = AnalyticOptions {
        seed: Some(vec![-0.3, 0.0]),
        respect_limits: true,
    };
    let sols = analytic::solve_with(&m, link, &Se3::identity(), &opts).unwrap();
    assert_eq!(sols.len(), 1);
    assert_eq!(sols[0].q[0], -0.3);
    assert!((sols[0].q[1].abs() - PI).abs() < 1e-12);
    assert!(sols[0].singularity.shoulder && sols[0].singularity.elbow);
}

fn data_for(m: &Model) -> Data {
    Data::new(m)
}

#[test]
fn unreachable_targets_give_reasons_not_nan() {
    let m = load("robots/ur5_dh.toml");
    let link = m.link_id("tool").unwrap();
    let far = Se3::from_translation(Vec3::new(1.5, 0.3, 0.2));
    match analytic::solve(&m, link, &far) {
        Err(IkError::Unreachable(r)) => assert!(r.contains("reach"), "{r}"),
        other => panic!("{other:?}"),
    }
    // Flange pointing down right above the base: wrist point inside the d4 cylinder.
    let down = Se3::new(
        Mat3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0),
        Vec3::new(0.0, 0.0, 0.5),
    );
    match analytic::solve(&m, link, &down) {
        Err(IkError::Unreachable(r)) => assert!(r.contains("axis 1"), "{r}"),
        other => panic!("{other:?}"),
    }
    let nan = Se3::from_translation(Vec3::new(f64::NAN, 0.0, 0.0));
    assert!(matches!(
        analytic::solve(&m, link, &nan),
        Err(IkError::InvalidInput(_))
    ));
    // The fast path: empty output, a reason.
    let mut out = Vec::with_capacity(8);
    let p = UrParams::ur5();
    assert!(ur_ik(&p, &far, &mut out).is_err());
    assert!(out.is_empty());

    let m = load("robots/puma560.toml");
    let link = m.link_id("link6").unwrap();
    assert!(matches!(
        analytic::solve(&m, link, &Se3::from_translation(Vec3::new(2.0, 0.0, 0.7))),
        Err(IkError::Unreachable(_))
    ));
    let m = load("robots/planar_2r.toml");
    let link = m.link_id("tool").unwrap();
    match analytic::solve(&m, link, &Se3::from_translation(Vec3::new(0.3, 0.1, 0.2))) {
        Err(IkError::Unreachable(r)) => assert!(r.contains("plane"), "{r}"),
        other => panic!("{other:?}"),
    }
    match analytic::solve(&m, link, &Se3::from_translation(Vec3::new(0.8, 0.0, 0.7))) {
        Err(IkError::Unreachable(r)) => assert!(r.contains("reach"), "{r}"),
        other => panic!("{other:?}"),
    }
    // Stretched exactly: one solution, elbow singular.
    let sols = analytic::solve(&m, link, &Se3::from_translation(Vec3::new(0.6, 0.0, 0.8))).unwrap();
    assert_eq!(sols.len(), 1);
    assert!(sols[0].singularity.elbow);
    assert!(sols[0].q[1].abs() < 1e-7);
    assert!((sols[0].q[0] - 0.8f64.atan2(0.6)).abs() < 1e-7);
}

// ---------------------------------------------------------------- closed forms

#[test]
fn spherical_rrp_matches_the_textbook_inverse() {
    let m = load("robots/textbook_spherical_rrp.toml");
    let link = m.link_id("tool").unwrap();
    let solver = AnalyticSolver::new(&m, link).unwrap();
    let mut data = Data::new(&m);
    let mut rng = SmallRng::seed_from_u64(41);
    let all = AnalyticOptions {
        seed: None,
        respect_limits: false,
    };
    for _ in 0..1000 {
        let q0 = random_q(&m, &mut rng);
        let t = fk(&m, &mut data, link, &q0);
        let (x, y, z) = (t.trans.x, t.trans.y, t.trans.z);
        // The textbook's closed form, written out here independently.
        let g1 = y.atan2(x);
        let b2 = z.atan2(x.hypot(y));
        let r = t.trans.norm();
        assert!(ang(g1, q0[0]) < 1e-12 && ang(b2, q0[1]) < 1e-12 && (r - q0[2]).abs() < 1e-12);
        let sols = solver.solve(&t, &AnalyticOptions::default()).unwrap();
        assert_eq!(sols.len(), 1, "π − b2 ≥ 120° is outside the b2 limits");
        let s = &sols[0];
        assert!(ang(s.q[0], g1) < 1e-12 && ang(s.q[1], b2) < 1e-12 && (s.q[2] - r).abs() < 1e-12);
        assert_eq!(s.branch, "shoulder-front/extension-positive");
        let sols = solver.solve(&t, &all).unwrap();
        assert_eq!(sols.len(), 4);
        let other = [g1 + PI, PI - b2, r];
        assert!(sols.iter().any(|s| qdist(&m, &s.q, &other) < 1e-12));
        for s in &sols {
            let got = fk(&m, &mut data, link, &s.q);
            assert!((got.trans - t.trans).amax() <= POSE_TOL);
        }
        let neg = sols.iter().filter(|s| s.q[2] < 0.0).count();
        assert_eq!(neg, 2);
    }
    // The fast path takes world points.
    let p = analytic::RrpParams::from_model(&m, link).unwrap();
    let mut out = Vec::new();
    let target = Vec3::new(0.5, -0.6, 0.4);
    rrp_ik(&p, &target, None, true, &mut out).unwrap();
    assert_eq!(out.len(), 1);
    assert!((out[0].q[2] - target.norm()).abs() < 1e-12);
}

#[test]
fn planar_2r_elbow_up_and_down_match_the_closed_form() {
    let m = load("robots/planar_2r.toml");
    let link = m.link_id("tool").unwrap();
    let solver = AnalyticSolver::new(&m, link).unwrap();
    let mut data = Data::new(&m);
    let mut rng = SmallRng::seed_from_u64(51);
    let l = 0.5;
    for _ in 0..1000 {
        let q0 = [rng.random_range(-PI..PI), rng.random_range(-3.0..3.0)];
        let t = fk(&m, &mut data, link, &q0);
        // The arm moves in the world x-z plane, angles from +x towards +z.
        let (x, z) = (t.trans.x, t.trans.z);
        assert!(t.trans.y.abs() < 1e-15);
        let c2 = (x * x + z * z - 2.0 * l * l) / (2.0 * l * l);
        let sols = solver.solve(&t, &AnalyticOptions::default()).unwrap();
        assert_eq!(sols.len(), 2);
        for s in &sols {
            let q2 = s.q[1];
            assert!((q2.cos() - c2).abs() < 1e-12);
            let q1 = z.atan2(x) - (l * q2.sin()).atan2(l + l * q2.cos());
            assert!(ang(s.q[0], q1) < 1e-12);
            // Elbow up: the elbow above the shoulder-tip line, i.e. q2 < 0 when the tip is
            // ahead (x > 0); geometric label checked against the sign rule.
            let elbow = Vec3::new(l * s.q[0].cos(), 0.0, l * s.q[0].sin());
            let dir = Vec3::new(x, 0.0, z).normalize();
            let up = (elbow - dir * elbow.dot(&dir)).z > 0.0;
            assert_eq!(s.branch, if up { "elbow-up" } else { "elbow-down" });
        }
        assert_ne!(sols[0].branch, sols[1].branch);
        assert!(sols.iter().any(|s| qdist(&m, &s.q, &q0) < 1e-10));
    }
}

#[test]
fn seed_chooses_the_2pi_representative() {
    let m = load("robots/ur5_dh.toml");
    let link = m.link_id("tool").unwrap();
    let mut data = Data::new(&m);
    let q0 = [5.0, -1.0, 1.2, -4.0, 1.0, 3.5];
    let target = fk(&m, &mut data, link, &q0);
    let sols = analytic::solve_with(
        &m,
        link,
        &target,
        &AnalyticOptions {
            seed: Some(q0.to_vec()),
            respect_limits: true,
        },
    )
    .unwrap();
    let best = sols
        .iter()
        .map(|s| {
            s.q.iter()
                .zip(&q0)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        })
        .fold(f64::INFINITY, f64::min);
    assert!(best < 1e-8, "the seed's own representative: {best:e}");
    // Tighter limits drop the representatives that do not fit.
    let p = UrParams::ur5().with_limits([-PI; 6], [PI; 6]);
    let mut out = Vec::new();
    ur_ik_with(&p, &target, None, true, &mut out).unwrap();
    assert!(out.iter().all(|s| s.q.iter().all(|v| v.abs() <= PI)));
    let p = UrParams::ur5().with_limits([-0.1; 6], [0.1; 6]);
    let n = ur_ik_with(&p, &target, None, true, &mut out).unwrap();
    assert_eq!((n, out.len()), (8, 0));
}

#[test]
fn dh_chain_reproduces_the_models_it_reads() {
    for (path, link, on_axis) in [
        ("robots/ur5.urdf", "tool0", true),
        ("robots/puma560.toml", "link6", true),
        ("robots/stanford.toml", "link6", true),
        ("robots/textbook_spherical_rrp.toml", "tool", false),
        ("robots/planar_2r.toml", "tool", false),
        ("robots/textbook_articulated_rrr.toml", "tool", false),
        ("robots/scara.toml", "tool", false),
    ] {
        let m = load(path);
        let Some(l) = m.link_id(link) else {
            panic!("{path}: no link {link}")
        };
        let chain = DhChain::from_model(&m, l, on_axis).unwrap();
        let mut data = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(61);
        for _ in 0..50 {
            let q = random_q(&m, &mut rng);
            let e = pose_err(&chain.placement(&q), &fk(&m, &mut data, l, &q));
            assert!(e < 1e-12, "{path}: {e:e}");
        }
    }
}

/// Random targets, most of them unreachable, and degenerate ones (on axis 1, at the
/// origin, far away): never a panic or a NaN, and whatever is returned reproduces the
/// target.
#[test]
fn random_and_degenerate_targets_never_give_nan() {
    let mut rng = SmallRng::seed_from_u64(71);
    for (path, link) in [
        ("robots/ur5.urdf", "tool0"),
        ("robots/puma560.toml", "link6"),
        ("robots/stanford.toml", "link6"),
        ("robots/textbook_spherical_rrp.toml", "tool"),
        ("robots/planar_2r.toml", "tool"),
    ] {
        let m = load(path);
        let link = m.link_id(link).unwrap();
        let solver = AnalyticSolver::new(&m, link).unwrap();
        let mut data = Data::new(&m);
        let (mut ok, mut err) = (0, 0);
        for i in 0..3000 {
            let q = random_q(&m, &mut rng);
            let rot = fk(&m, &mut data, link, &q).rot;
            let mut trans = match i % 5 {
                0 => Vec3::zeros(),
                1 => Vec3::new(0.0, 0.0, rng.random_range(-1.5..1.5)),
                _ => Vec3::new(
                    rng.random_range(-1.2..1.2),
                    rng.random_range(-1.2..1.2),
                    rng.random_range(-0.5..1.8),
                ),
            };
            if solver.kind() == AnalyticKind::Planar2r {
                trans.y = 0.0;
            }
            let target = Se3::new(rot, trans);
            let opts = AnalyticOptions {
                seed: None,
                respect_limits: i % 2 == 0,
            };
            match solver.solve(&target, &opts) {
                Ok(sols) => {
                    ok += 1;
                    for s in &sols {
                        assert!(s.q.iter().all(|v| v.is_finite()), "{path}: {:?}", s.q);
                        let got = fk(&m, &mut data, link, &s.q);
                        let e = if solver.kind().position_only() {
                            (got.trans - target.trans).amax()
                        } else {
                            pose_err(&got, &target)
                        };
                        assert!(e <= POSE_TOL, "{path}: {e:e} for {target:?}");
                    }
                }
                Err(IkError::Unreachable(_)) | Err(IkError::OutsideLimits { .. }) => err += 1,
                Err(e) => panic!("{path}: {e}"),
            }
        }
        eprintln!("{path}: {ok} solved, {err} unreachable or outside the limits");
        assert!(ok > 0 && err > 0, "{path}: {ok} / {err}");
    }
}
