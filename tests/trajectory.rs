//! Trajectories, TOPP and the torque check, against independent references: closed-form
//! minimum times, a direct solve of the minimum-jerk spline's coefficients, nalgebra's
//! quaternion slerp, analytic time-optimal motions, RNEA plus hand-written friction and
//! rotor terms, and analytic violation times.

#[path = "common/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::allocs;

mod common;

use armsim::core::spatial::{Se3, Vec3};
use armsim::dynamics::{rnea, Effects, Friction, Rotor};
use armsim::io::plots::torque_chart::{write_torque_plot, PlotFormat};
use armsim::kinematics::{forward_kinematics, frame_placement};
use armsim::model::data::Data;
use armsim::model::Model;
use armsim::motion::topp;
use armsim::motion::{
    cartesian_line, check_torques, CartesianOptions, JointLimits, LinearPath, MinJerk, Path,
    Quintic, TimeScaled, ToppOptions, TorqueCheckOptions, Trajectory, TrajectoryError, Trapezoidal,
};
use nalgebra::{DMatrix, DVector, Rotation3, UnitQuaternion};

/// Peaks of `|q̇_j|` and `|q̈_j|` on a uniform grid of `k + 1` samples.
fn peaks(traj: &dyn Trajectory, k: usize) -> (Vec<f64>, Vec<f64>) {
    let n = traj.dof();
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut pv, mut pa) = (vec![0.0f64; n], vec![0.0f64; n]);
    for i in 0..=k {
        traj.sample(
            traj.duration() * i as f64 / k as f64,
            &mut q,
            &mut qd,
            &mut qdd,
        );
        for j in 0..n {
            pv[j] = pv[j].max(qd[j].abs());
            pa[j] = pa[j].max(qdd[j].abs());
        }
    }
    (pv, pa)
}

/// Integrates `q̇` and `q̈` (trapezoidal rule, `k` steps) and returns the largest
/// mismatch with `q(t) − q(0)` and `q̇(t) − q̇(0)`: the derivatives belong to the positions.
fn derivative_consistency(traj: &dyn Trajectory, k: usize) -> (f64, f64) {
    let n = traj.dof();
    let dt = traj.duration() / k as f64;
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    traj.sample(0.0, &mut q, &mut qd, &mut qdd);
    let (q0, qd0) = (q.clone(), qd.clone());
    let (mut iq, mut iqd) = (q0.clone(), qd0.clone());
    let (mut pqd, mut pqdd) = (qd.clone(), qdd.clone());
    let (mut eq, mut eqd) = (0.0f64, 0.0f64);
    for i in 1..=k {
        traj.sample(i as f64 * dt, &mut q, &mut qd, &mut qdd);
        for j in 0..n {
            iq[j] += 0.5 * dt * (pqd[j] + qd[j]);
            iqd[j] += 0.5 * dt * (pqdd[j] + qdd[j]);
            eq = eq.max((iq[j] - q[j]).abs());
            eqd = eqd.max((iqd[j] - qd[j]).abs());
        }
        pqd.copy_from_slice(&qd);
        pqdd.copy_from_slice(&qdd);
    }
    (eq, eqd)
}

fn ur5() -> (Model, usize) {
    let m = common::load("robots/ur5.urdf");
    let l = m.link_id("tool0").unwrap();
    (m, l)
}

fn planar() -> Model {
    common::load("robots/planar_2r.toml")
}

fn ur5_waypoints() -> Vec<Vec<f64>> {
    vec![
        vec![0.0, -1.57, 1.57, -1.57, -1.57, 0.0],
        vec![0.8, -1.2, 1.2, -1.0, -1.2, 0.5],
        vec![1.5, -1.8, 0.9, -1.4, -1.6, 1.2],
        vec![0.5, -1.0, 1.8, -2.0, -1.0, 0.3],
    ]
}

fn ur5_limits(m: &Model) -> JointLimits {
    JointLimits::from_model(m, vec![3.0, 3.0, 3.0, 6.0, 6.0, 6.0])
}

fn planar_waypoints() -> Vec<Vec<f64>> {
    vec![
        vec![0.0, 0.0],
        vec![1.0, 0.8],
        vec![2.0, -0.5],
        vec![0.5, 0.3],
    ]
}

fn planar_limits() -> JointLimits {
    JointLimits {
        velocity: vec![2.0, 3.0],
        acceleration: vec![5.0, 8.0],
        effort: vec![f64::INFINITY; 2],
        jerk: None,
    }
}

// ---------------------------------------------------------------------------------------
// Profiles

#[test]
fn trapezoidal_segment_times_are_the_slowest_joints_minimum() {
    let w = vec![
        vec![0.0, 0.0, 0.0],
        vec![1.0, -0.2, 0.05],
        vec![1.0, 0.5, 0.05],
        vec![-0.3, 0.5, 0.4],
        vec![-0.3, 0.5, 0.4],
    ];
    let lim = JointLimits {
        velocity: vec![1.0, 2.0, 0.5],
        acceleration: vec![2.0, 1.0, 4.0],
        effort: vec![f64::INFINITY; 3],
        jerk: None,
    };
    let tr = Trapezoidal::new(&w, &lim).unwrap();
    // Closed form of the fastest rest-to-rest move per joint.
    let tmin = |d: f64, v: f64, a: f64| {
        if d >= v * v / a {
            d / v + v / a
        } else {
            2.0 * (d / a).sqrt()
        }
    };
    let mut t = 0.0;
    for (k, seg) in w.windows(2).enumerate() {
        let segt = (0..3)
            .map(|j| {
                tmin(
                    (seg[1][j] - seg[0][j]).abs(),
                    lim.velocity[j],
                    lim.acceleration[j],
                )
            })
            .fold(0.0, f64::max);
        t += segt;
        assert!((tr.knot_times()[k + 1] - t).abs() < 1e-12, "segment {k}");
    }
    // Waypoint 1 → 2: joint 0 still, joint 1 moves 0.7 with v²/a = 4 > d: triangle.
    assert!((tr.knot_times()[2] - tr.knot_times()[1] - 2.0 * (0.7f64).sqrt()).abs() < 1e-12);
    // At every waypoint: there, at rest.
    let (mut q, mut qd, mut qdd) = (vec![0.0; 3], vec![0.0; 3], vec![0.0; 3]);
    for (k, &tk) in tr.knot_times().iter().enumerate() {
        tr.sample(tk, &mut q, &mut qd, &mut qdd);
        for j in 0..3 {
            assert!((q[j] - w[k][j]).abs() < 1e-12, "waypoint {k} joint {j}");
            assert!(qd[j].abs() < 1e-12);
        }
    }
    // Limits hold; the slowest joint of segment 0 (joint 0: 1.5 s vs 0.894 s and 0.35 s)
    // cruises at its limit.
    let (pv, pa) = peaks(&tr, 20_000);
    for j in 0..3 {
        assert!(
            pv[j] <= lim.velocity[j] * (1.0 + 1e-12),
            "joint {j} speed {}",
            pv[j]
        );
        assert!(pa[j] <= lim.acceleration[j] * (1.0 + 1e-12));
    }
    assert!((pv[0] - 1.0).abs() < 1e-12);
    // Velocities integrate to the positions, accelerations to the velocities.
    // (q̈ jumps at the blend points: the trapezoidal rule errs by up to ½ Δt × jump there.)
    let (eq, eqd) = derivative_consistency(&tr, 200_000);
    assert!(eq < 1e-6 && eqd < 1e-3, "{eq} {eqd}");
}

#[test]
fn quintic_segments_reach_the_binding_limit() {
    let w = planar_waypoints();
    let lim = planar_limits();
    let qu = Quintic::new(&w, &lim).unwrap();
    for (k, seg) in w.windows(2).enumerate() {
        let h = qu.knot_times()[k + 1] - qu.knot_times()[k];
        let need = (0..2)
            .map(|j| {
                let d = (seg[1][j] - seg[0][j]).abs();
                (15.0 / 8.0 * d / lim.velocity[j])
                    .max((10.0 / 3f64.sqrt() * d / lim.acceleration[j]).sqrt())
            })
            .fold(0.0, f64::max);
        assert!((h - need).abs() < 1e-12);
    }
    let (pv, pa) = peaks(&qu, 200_000);
    let worst = (0..2)
        .map(|j| (pv[j] / lim.velocity[j]).max(pa[j] / lim.acceleration[j]))
        .fold(0.0, f64::max);
    assert!(worst <= 1.0 + 1e-12 && worst > 1.0 - 1e-6, "{worst}");
    let (eq, eqd) = derivative_consistency(&qu, 200_000);
    assert!(eq < 1e-8 && eqd < 1e-7, "{eq} {eqd}");
}

/// The minimum-jerk spline against a direct solve for all `6M` coefficients: positions at
/// both ends of every segment, derivatives 1–4 continuous at interior knots, velocity and
/// acceleration zero at both ends.
#[test]
fn min_jerk_matches_direct_coefficient_solve() {
    let w = vec![
        vec![0.0, 1.0],
        vec![0.7, 0.2],
        vec![0.1, -0.4],
        vec![1.3, 0.5],
        vec![0.9, 0.9],
    ];
    let h = [0.8, 1.3, 0.6, 1.1];
    let mj = MinJerk::with_durations(&w, &h).unwrap();
    let m = h.len();
    // d-th derivative of t^i at t.
    let dmono = |i: usize, d: usize, t: f64| -> f64 {
        if d > i {
            return 0.0;
        }
        let c: f64 = ((i - d + 1)..=i).map(|x| x as f64).product();
        c * t.powi((i - d) as i32)
    };
    #[allow(clippy::needless_range_loop)]
    for j in 0..2 {
        let mut a = DMatrix::zeros(6 * m, 6 * m);
        let mut b = DVector::zeros(6 * m);
        let mut r = 0;
        for k in 0..m {
            for i in 0..6 {
                a[(r, 6 * k + i)] = dmono(i, 0, 0.0);
                a[(r + 1, 6 * k + i)] = dmono(i, 0, h[k]);
            }
            b[r] = w[k][j];
            b[r + 1] = w[k + 1][j];
            r += 2;
        }
        for k in 0..m - 1 {
            for d in 1..=4 {
                for i in 0..6 {
                    a[(r, 6 * k + i)] = dmono(i, d, h[k]);
                    a[(r, 6 * (k + 1) + i)] = -dmono(i, d, 0.0);
                }
                r += 1;
            }
        }
        for d in 1..=2 {
            for i in 0..6 {
                a[(r, i)] = dmono(i, d, 0.0);
                a[(r + 1, 6 * (m - 1) + i)] = dmono(i, d, h[m - 1]);
            }
            r += 2;
        }
        assert_eq!(r, 6 * m);
        let x = a.lu().solve(&b).unwrap();
        for k in 0..m {
            let c = mj.coefficients(k, j);
            for i in 0..6 {
                let want = x[6 * k + i];
                assert!(
                    (c[i] - want).abs() < 1e-9 * (1.0 + want.abs()),
                    "joint {j} segment {k} c{i}: {} vs {want}",
                    c[i]
                );
            }
        }
    }
    // One segment: the Flash–Hogan profile 10u³ − 15u⁴ + 6u⁵.
    let one = MinJerk::with_durations(&[vec![0.2], vec![1.4]], &[2.0]).unwrap();
    let (mut q, mut qd, mut qdd) = ([0.0], [0.0], [0.0]);
    for i in 0..=20 {
        let u = i as f64 / 20.0;
        one.sample(2.0 * u, &mut q, &mut qd, &mut qdd);
        let want = 0.2 + 1.2 * (10.0 * u.powi(3) - 15.0 * u.powi(4) + 6.0 * u.powi(5));
        assert!((q[0] - want).abs() < 1e-13);
    }
}

#[test]
fn min_jerk_time_scaling_meets_the_limits_with_one_active() {
    for (w, lim) in [
        (planar_waypoints(), planar_limits()),
        (ur5_waypoints(), ur5_limits(&ur5().0)),
    ] {
        let mj = MinJerk::new(&w, &lim).unwrap();
        let n = lim.velocity.len();
        let (pv, pa) = peaks(&mj, 400_000);
        let ratio = (0..n)
            .map(|j| (pv[j] / lim.velocity[j]).max(pa[j] / lim.acceleration[j]))
            .fold(0.0, f64::max);
        assert!(ratio <= 1.0 + 1e-9, "limit exceeded: {ratio}");
        assert!(ratio >= 1.0 - 1e-6, "no limit active: {ratio}");
        // It passes the via points without stopping, so it beats stopping at each.
        let quintic = Quintic::new(&w, &lim).unwrap();
        println!(
            "min-jerk {:.4} s, quintic stop-at-waypoints {:.4} s",
            mj.duration(),
            quintic.duration()
        );
        assert!(mj.duration() < quintic.duration());
        // Knots are the waypoints.
        let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for (k, &tk) in mj.knot_times().iter().enumerate() {
            mj.sample(tk, &mut q, &mut qd, &mut qdd);
            for j in 0..n {
                assert!((q[j] - w[k][j]).abs() < 1e-12);
            }
        }
        let (eq, eqd) = derivative_consistency(&mj, 200_000);
        assert!(eq < 1e-8 && eqd < 1e-7, "{eq} {eqd}");
    }
}

#[test]
fn bad_inputs_are_clear_errors() {
    let m = planar();
    // The planar arm's file has no velocity limits.
    let lim = JointLimits::from_model(&m, vec![1.0, 1.0]);
    let e = Trapezoidal::new(&planar_waypoints(), &lim).unwrap_err();
    assert!(e.to_string().contains("velocity limit"), "{e}");
    let e = Quintic::new(&[vec![0.0, 0.0]], &planar_limits()).unwrap_err();
    assert!(e.to_string().contains("at least two waypoints"), "{e}");
    let e = MinJerk::new(&[vec![0.0, 0.0], vec![0.0, 0.0]], &planar_limits()).unwrap_err();
    assert!(e.to_string().contains("coincide"), "{e}");
    let e = Quintic::new(&[vec![0.0, 0.0], vec![0.0]], &planar_limits()).unwrap_err();
    assert!(matches!(e, TrajectoryError::Invalid(_)));
}

// ---------------------------------------------------------------------------------------
// Cartesian moves

#[test]
fn cartesian_line_follows_the_line_and_the_slerp() {
    let (m, tool) = ur5();
    let q0 = vec![0.3, -1.3, 1.5, -1.8, -1.57, 0.2];
    let mut d = Data::new(&m);
    forward_kinematics(&m, &mut d, &q0);
    let start = frame_placement(&m, &d, tool);
    let turn = Rotation3::from_axis_angle(
        &nalgebra::Unit::new_normalize(Vec3::new(0.3, -0.5, 0.8)),
        0.4,
    );
    let goal = Se3::new(
        turn.matrix() * start.rot,
        start.trans + Vec3::new(0.12, 0.15, -0.1),
    );
    let opts = CartesianOptions::default();
    let mv = cartesian_line(&m, tool, &q0, &goal, &opts).unwrap();
    let rep = &mv.report;
    println!("{rep:?}");
    assert!(rep.worst_position_error <= 1e-9 && rep.worst_rotation_error <= 1e-9);
    // Independent reference: nalgebra's quaternion slerp, linear position, quintic σ(t).
    let qa = UnitQuaternion::from_matrix(&start.rot);
    let qb = UnitQuaternion::from_matrix(&goal.rot);
    let big_t = mv.duration();
    let n = m.nv;
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut worst_p, mut worst_r, mut peak_v) = (0.0f64, 0.0f64, 0.0f64);
    let mut prev: Option<Vec3> = None;
    let k = 2000;
    for i in 0..=k {
        let t = big_t * i as f64 / k as f64;
        let u = t / big_t;
        let s = 10.0 * u.powi(3) - 15.0 * u.powi(4) + 6.0 * u.powi(5);
        mv.sample(t, &mut q, &mut qd, &mut qdd);
        forward_kinematics(&m, &mut d, &q);
        let pose = frame_placement(&m, &d, tool);
        let want_p = start.trans + (goal.trans - start.trans) * s;
        let want_r = qa.slerp(&qb, s);
        worst_p = worst_p.max((pose.trans - want_p).norm());
        worst_r = worst_r.max(UnitQuaternion::from_matrix(&pose.rot).angle_to(&want_r));
        if let Some(p) = prev {
            peak_v = peak_v.max((pose.trans - p).norm() / (big_t / k as f64));
        }
        prev = Some(pose.trans);
    }
    println!("line deviation {worst_p:.3e} m, {worst_r:.3e} rad; peak tool speed {peak_v:.5}");
    assert!(worst_p < 1e-5 && worst_r < 1e-5, "{worst_p} {worst_r}");
    // Duration from the limits: 15/8 L / v or √(10/√3 L / a) (or the angular ones).
    let l = (goal.trans - start.trans).norm();
    let want_t = [
        15.0 / 8.0 * l / opts.max_linear_speed,
        (10.0 / 3f64.sqrt() * l / opts.max_linear_acceleration).sqrt(),
        15.0 / 8.0 * 0.4 / opts.max_angular_speed,
        (10.0 / 3f64.sqrt() * 0.4 / opts.max_angular_acceleration).sqrt(),
    ]
    .into_iter()
    .fold(0.0, f64::max);
    assert!(
        (big_t - want_t).abs() < 1e-9 * want_t,
        "{big_t} vs {want_t}"
    );
    if rep.limited_by == "linear_speed" {
        assert!((peak_v - opts.max_linear_speed).abs() < 1e-3 * opts.max_linear_speed);
    }
    assert!(peak_v <= opts.max_linear_speed * (1.0 + 1e-4));
}

#[test]
fn cartesian_line_with_joint_limits_slows_down_to_them() {
    let (m, tool) = ur5();
    let q0 = vec![0.3, -1.3, 1.5, -1.8, -1.57, 0.2];
    let mut d = Data::new(&m);
    forward_kinematics(&m, &mut d, &q0);
    let start = frame_placement(&m, &d, tool);
    let goal = Se3::new(start.rot, start.trans + Vec3::new(0.0, 0.3, 0.0));
    let lim = JointLimits::uniform(6, 0.3, 0.6, f64::INFINITY);
    let opts = CartesianOptions {
        max_linear_speed: 10.0,
        max_linear_acceleration: 100.0,
        joint_limits: Some(lim.clone()),
        ..Default::default()
    };
    let mv = cartesian_line(&m, tool, &q0, &goal, &opts).unwrap();
    assert!(
        mv.report.limited_by.starts_with("joint_"),
        "{}",
        mv.report.limited_by
    );
    let (pv, pa) = peaks(&mv, 20_000);
    let ratio = (0..6)
        .map(|j| (pv[j] / lim.velocity[j]).max(pa[j] / lim.acceleration[j]))
        .fold(0.0, f64::max);
    assert!(ratio <= 1.0 + 1e-3 && ratio > 0.99, "{ratio}");
}

#[test]
fn cartesian_line_to_an_unreachable_pose_fails_at_the_first_bad_sample() {
    let (m, tool) = ur5();
    let q0 = vec![0.3, -1.3, 1.5, -1.8, -1.57, 0.2];
    let mut d = Data::new(&m);
    forward_kinematics(&m, &mut d, &q0);
    let start = frame_placement(&m, &d, tool);
    // 2 m away along x: the UR5 reaches about 0.85 m.
    let goal = Se3::new(start.rot, start.trans + Vec3::new(2.0, 0.0, 0.0));
    let e = cartesian_line(&m, tool, &q0, &goal, &CartesianOptions::default()).unwrap_err();
    match &e {
        TrajectoryError::Unreachable { index, s, .. } => {
            // The line leaves the workspace after about 0.5–1.2 m of 2 m.
            assert!(*index > 1 && *s < 0.7, "{e}");
        }
        other => panic!("expected Unreachable, got {other}"),
    }
    assert!(e.to_string().contains("unreachable"));
}

// ---------------------------------------------------------------------------------------
// TOPP

/// 200 grid intervals (the default is 400): the tests run unoptimised, and the limits are
/// verified independently whatever the grid.
fn test_opts() -> ToppOptions {
    ToppOptions {
        segments: 200,
        ..Default::default()
    }
}

/// Independent limit check of a trajectory: velocities, accelerations and RNEA torques
/// (with gravity `g`, no other effect) on a uniform grid. Returns the largest ratio of each.
fn verify(
    m: &Model,
    traj: &dyn Trajectory,
    lim: &JointLimits,
    g: Option<Vec3>,
    k: usize,
) -> [f64; 3] {
    let n = m.nv;
    let mut d = Data::new(m);
    let mut with_g = m.clone();
    with_g.gravity = g.unwrap_or_else(Vec3::zeros);
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut r = [0.0f64; 3];
    for i in 0..=k {
        traj.sample(
            traj.duration() * i as f64 / k as f64,
            &mut q,
            &mut qd,
            &mut qdd,
        );
        let tau = rnea(&with_g, &mut d, &q, &qd, &qdd);
        for j in 0..n {
            r[0] = r[0].max(qd[j].abs() / lim.velocity[j]);
            r[1] = r[1].max(qdd[j].abs() / lim.acceleration[j]);
            r[2] = r[2].max(tau[j].abs() / lim.effort[j]);
        }
    }
    r
}

/// Along a straight joint line with velocity and acceleration limits only, the optimum is
/// the bang–coast–bang profile of the line parameter with `V = min v_j/|Δ_j|` and
/// `A = min a_j/|Δ_j|`.
#[test]
fn topp_on_a_line_matches_bang_coast_bang() {
    let m = planar();
    let (q0, q1) = (vec![0.0, 0.0], vec![1.2, -0.6]);
    let lim = JointLimits {
        velocity: vec![1.0, 1.5],
        acceleration: vec![2.0, 3.0],
        effort: vec![f64::INFINITY; 2],
        jerk: None,
    };
    let path = LinearPath::new(q0.clone(), q1.clone()).unwrap();
    let tp = topp(&m, path, &lim, &Effects::default(), &ToppOptions::default()).unwrap();
    let v = (0..2)
        .map(|j| lim.velocity[j] / (q1[j] - q0[j]).abs())
        .fold(f64::INFINITY, f64::min);
    let a = (0..2)
        .map(|j| lim.acceleration[j] / (q1[j] - q0[j]).abs())
        .fold(f64::INFINITY, f64::min);
    let want = if 1.0 >= v * v / a {
        1.0 / v + v / a
    } else {
        2.0 / a.sqrt()
    };
    let got = tp.duration();
    println!(
        "TOPP on a line: {got:.6} s, bang-coast-bang {want:.6} s, {:?}",
        tp.stats()
    );
    assert!(
        got >= want * (1.0 - 1e-6) && got <= want * (1.0 + 2e-3),
        "{got} vs {want}"
    );
    // The synchronised trapezoid on the same segment is that same optimum.
    let tr = Trapezoidal::new(&[q0, q1], &lim).unwrap();
    assert!((tr.duration() - want).abs() < 1e-12);
}

/// The trapezoidal motion slowed down uniformly (the smallest factor, by bisection on the
/// torque check) until it also meets the torque limits: the fair comparison once torque
/// limits bind, since the trapezoidal profile itself ignores them.
fn torque_feasible_trapezoid(
    m: &Model,
    trap: Trapezoidal,
    effort: &[f64],
    eff: &Effects,
) -> TimeScaled<Trapezoidal> {
    let feasible = |traj: &TimeScaled<Trapezoidal>| {
        let opts = TorqueCheckOptions {
            dt: 2e-3,
            effort_limit: Some(effort.to_vec()),
            velocity_limit: Some(vec![f64::INFINITY; m.nv]),
            keep_series: true,
        };
        check_torques(m, traj, eff, &opts).unwrap().ok
    };
    let mut traj = TimeScaled::new(trap, 1.0).unwrap();
    if feasible(&traj) {
        return traj;
    }
    let (mut lo, mut hi) = (1.0, 2.0);
    loop {
        traj = TimeScaled::new(traj.into_inner(), hi).unwrap();
        if feasible(&traj) {
            break;
        }
        (lo, hi) = (hi, 2.0 * hi);
    }
    while hi - lo > 1e-4 {
        let mid = 0.5 * (lo + hi);
        traj = TimeScaled::new(traj.into_inner(), mid).unwrap();
        if feasible(&traj) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    TimeScaled::new(traj.into_inner(), hi).unwrap()
}

/// TOPP along the minimum-jerk path: every limit holds to 1e-6 (velocities, accelerations
/// and RNEA torques re-evaluated independently on a fine time grid), the binding limit is
/// active, and the motion is faster than the trapezoidal one through the same waypoints
/// (stopping at each; with torque limits, slowed down until it meets them too).
/// `torque_joints` are the joints that get a torque limit.
fn topp_case(name: &str, m: &Model, w: &[Vec<f64>], lim: &JointLimits, torque_joints: &[usize]) {
    let g = Effects::gravity(m.gravity);
    let opts = test_opts();
    let n = m.nv;
    let trap = Trapezoidal::new(w, lim).unwrap();
    let path = MinJerk::new(w, lim).unwrap();
    let mut free = lim.clone();
    free.effort = vec![f64::INFINITY; n];
    let tp = topp(m, path.clone(), &free, &g, &opts).unwrap();
    let r = verify(m, &tp, &free, Some(m.gravity), 40_000);
    println!(
        "{name}, no torque limits: TOPP {:.4} s, trapezoidal {:.4} s, min-jerk {:.4} s; \
         ratios {r:.7?}; {} solves, {} iterations, solver {:.3} s, wall {:.3} s",
        tp.duration(),
        trap.duration(),
        path.duration(),
        tp.stats().solves,
        tp.stats().solver_iterations,
        tp.stats().solve_time_s,
        tp.stats().wall_time_s
    );
    assert!(r[0] <= 1.0 + 1e-6 && r[1] <= 1.0 + 1e-6, "{r:?}");
    assert!(r[0].max(r[1]) > 1.0 - 1e-3, "no limit active: {r:?}");
    assert!(tp.duration() < trap.duration());
    assert!(tp.duration() <= path.duration() * (1.0 + 1e-9));

    // Torque limits that bind: 80 % of the peak torque the unconstrained optimum needs,
    // but at least 1.2 × the largest static torque along the path (so it can hold still).
    let mut d = Data::new(m);
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut peak, mut stat) = (vec![0.0f64; n], vec![0.0f64; n]);
    let z = vec![0.0; n];
    for i in 0..=4000 {
        tp.sample(tp.duration() * i as f64 / 4000.0, &mut q, &mut qd, &mut qdd);
        let tau = rnea(m, &mut d, &q, &qd, &qdd).to_vec();
        let gq = rnea(m, &mut d, &q, &z, &z).to_vec();
        for j in 0..n {
            peak[j] = peak[j].max(tau[j].abs());
            stat[j] = stat[j].max(gq[j].abs());
        }
    }
    let mut tight = lim.clone();
    tight.effort = (0..n)
        .map(|j| {
            if torque_joints.contains(&j) {
                (0.8 * peak[j]).max(1.2 * stat[j])
            } else {
                f64::INFINITY
            }
        })
        .collect();
    let tq = topp(m, path.clone(), &tight, &g, &opts).unwrap();
    let r = verify(m, &tq, &tight, Some(m.gravity), 40_000);
    let slow = torque_feasible_trapezoid(m, trap, &tight.effort, &g);
    println!(
        "{name}, torque limits {:.3?}: TOPP {:.4} s, trapezoidal slowed to the torque limits \
         {:.4} s (x{:.4}); ratios {r:.7?}; {} solves, solver {:.3} s, wall {:.3} s",
        tight.effort,
        tq.duration(),
        slow.duration(),
        slow.factor(),
        tq.stats().solves,
        tq.stats().solve_time_s,
        tq.stats().wall_time_s
    );
    assert!(r.iter().all(|x| *x <= 1.0 + 1e-6), "{r:?}");
    assert!(r[2] > 1.0 - 1e-3, "torque limit not active: {r:?}");
    assert!(tq.duration() > tp.duration());
    assert!(
        slow.factor() > 1.0,
        "the torque limits should bind the trapezoid too"
    );
    assert!(tq.duration() < slow.duration());
}

#[test]
fn topp_planar_2r_meets_limits_and_beats_trapezoidal() {
    topp_case(
        "planar 2R",
        &planar(),
        &planar_waypoints(),
        &planar_limits(),
        &[0, 1],
    );
}

#[test]
fn topp_ur5_meets_limits_and_beats_trapezoidal() {
    let m = ur5().0;
    topp_case("UR5", &m, &ur5_waypoints(), &ur5_limits(&m), &[0, 1, 2]);
}

/// Friction is not convex in the path speed; TOPP iterates on it and verifies with the
/// exact model. Checked here against RNEA plus hand-written friction and armature terms.
#[test]
fn topp_with_friction_and_rotor_meets_the_limits() {
    let m = planar();
    let fr = Friction {
        viscous: vec![0.8, 0.5],
        coulomb: vec![0.6, 0.3],
        stiction: vec![0.9, 0.4],
        stribeck_velocity: vec![0.1, 0.1],
        smoothing: 1e-3,
    };
    let ro = Rotor {
        inertia: vec![2e-5, 1e-5],
        gear_ratio: vec![50.0, 40.0],
        efficiency: vec![0.9, 0.9],
    };
    let eff = Effects {
        gravity: Some(m.gravity),
        friction: Some(fr.clone()),
        rotor: Some(ro.clone()),
        ..Default::default()
    };
    // Exact torque with friction and armature, by hand around RNEA.
    let torque = |d: &mut Data, q: &[f64], qd: &[f64], qdd: &[f64]| -> Vec<f64> {
        let tau = rnea(&m, d, q, qd, qdd).to_vec();
        (0..2)
            .map(|j| {
                let v = qd[j];
                let f = fr.viscous[j] * v
                    + (fr.coulomb[j]
                        + (fr.stiction[j] - fr.coulomb[j])
                            * (-(v / fr.stribeck_velocity[j]).powi(2)).exp())
                        * (v / fr.smoothing).tanh();
                tau[j] + f + ro.inertia[j] * ro.gear_ratio[j] * ro.gear_ratio[j] * qdd[j]
            })
            .collect()
    };
    let peak_torques = |traj: &dyn Trajectory| -> Vec<f64> {
        let mut d = Data::new(&m);
        let (mut q, mut qd, mut qdd) = ([0.0; 2], [0.0; 2], [0.0; 2]);
        let mut peak = vec![0.0f64; 2];
        for i in 0..=40_000 {
            traj.sample(
                traj.duration() * i as f64 / 40_000.0,
                &mut q,
                &mut qd,
                &mut qdd,
            );
            for (p, t) in peak.iter_mut().zip(torque(&mut d, &q, &qd, &qdd)) {
                *p = p.max(t.abs());
            }
        }
        peak
    };
    let lim = planar_limits();
    let path = MinJerk::new(&planar_waypoints(), &lim).unwrap();
    let free = topp(&m, path.clone(), &lim, &eff, &test_opts()).unwrap();
    let mut tight = lim.clone();
    // 80 % of what the unconstrained optimum needs (above the static 12.3 and 2.5 N m).
    tight.effort = peak_torques(&free).iter().map(|p| 0.8 * p).collect();
    let tp = topp(&m, path, &tight, &eff, &test_opts()).unwrap();
    let peak = peak_torques(&tp);
    let worst = (0..2)
        .map(|j| peak[j] / tight.effort[j])
        .fold(0.0, f64::max);
    println!(
        "friction + rotor: limits {:.3?}, TOPP {:.4} s (free {:.4} s), torque ratio {worst:.7}, {:?}",
        tight.effort,
        tp.duration(),
        free.duration(),
        tp.stats()
    );
    assert!(worst <= 1.0 + 1e-6 && worst > 0.999, "{worst}");
    assert!(tp.duration() > free.duration());
}

#[test]
fn topp_reports_a_path_it_cannot_hold() {
    let m = planar();
    let mut lim = planar_limits();
    // Holding the arm horizontal needs (m1/2 + m2) g l + (m2/2) g l = 12.26 N m on joint 1.
    lim.effort = vec![5.0, 5.0];
    let path = LinearPath::new(vec![0.0, 0.0], vec![0.5, 0.0]).unwrap();
    let e = topp(
        &m,
        path,
        &lim,
        &Effects::gravity(m.gravity),
        &ToppOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("cannot even hold still"), "{e}");
}

// ---------------------------------------------------------------------------------------
// Torque check

/// `q₁ = A sin ωt` (optionally), `q₂ = B sin ωt`.
struct Sine {
    a: f64,
    b: f64,
    w: f64,
    t: f64,
}

impl Trajectory for Sine {
    fn dof(&self) -> usize {
        2
    }
    fn duration(&self) -> f64 {
        self.t
    }
    fn sample(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        let t = t.clamp(0.0, self.t);
        let (s, c) = (self.w * t).sin_cos();
        for (j, amp) in [self.a, self.b].into_iter().enumerate() {
            q[j] = amp * s;
            qd[j] = amp * self.w * c;
            qdd[j] = -amp * self.w * self.w * s;
        }
    }
}

#[test]
fn torque_check_agrees_with_an_independent_recomputation() {
    let (m, _) = ur5();
    let n = m.nv;
    let fr = Friction {
        viscous: vec![2.0, 2.0, 1.5, 0.5, 0.5, 0.3],
        coulomb: vec![3.0, 3.0, 2.0, 1.0, 1.0, 0.5],
        stiction: vec![4.0, 4.0, 2.5, 1.2, 1.2, 0.6],
        stribeck_velocity: vec![0.05; 6],
        smoothing: 1e-3,
    };
    let ro = Rotor {
        inertia: vec![1e-4, 1e-4, 1e-4, 2e-5, 2e-5, 2e-5],
        gear_ratio: vec![100.0; 6],
        efficiency: vec![0.9; 6],
    };
    let eff = Effects {
        gravity: Some(m.gravity),
        friction: Some(fr.clone()),
        rotor: Some(ro.clone()),
        ..Default::default()
    };
    let traj = MinJerk::new(&ur5_waypoints(), &ur5_limits(&m)).unwrap();
    let opts = TorqueCheckOptions {
        dt: 0.01,
        ..Default::default()
    };
    let rep = check_torques(&m, &traj, &eff, &opts).unwrap();
    assert_eq!(rep.effects, vec!["gravity", "friction", "rotor_inertia"]);
    let ns = rep.t.len();
    assert!((rep.t[ns - 1] - traj.duration()).abs() < 1e-12 && rep.dt <= 0.01);
    let mut d = Data::new(&m);
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut peak, mut speed, mut power, mut sq) = (
        vec![0.0f64; n],
        vec![0.0f64; n],
        vec![0.0f64; n],
        vec![0.0f64; n],
    );
    for (k, &t) in rep.t.iter().enumerate() {
        traj.sample(t, &mut q, &mut qd, &mut qdd);
        let tau = rnea(&m, &mut d, &q, &qd, &qdd).to_vec();
        for j in 0..n {
            let v = qd[j];
            let f = fr.viscous[j] * v
                + (fr.coulomb[j]
                    + (fr.stiction[j] - fr.coulomb[j])
                        * (-(v / fr.stribeck_velocity[j]).powi(2)).exp())
                    * (v / fr.smoothing).tanh();
            let want = tau[j] + f + ro.inertia[j] * ro.gear_ratio[j].powi(2) * qdd[j];
            let got = rep.torque(k, j);
            assert!(
                (got - want).abs() < 1e-9 * (1.0 + want.abs()),
                "t {t} joint {j}"
            );
            peak[j] = peak[j].max(want.abs());
            speed[j] = speed[j].max(v.abs());
            power[j] = power[j].max((want * v).abs());
            let w = if k == 0 || k == ns - 1 { 0.5 } else { 1.0 };
            sq[j] += w * want * want * rep.dt;
        }
    }
    for j in 0..n {
        let r = &rep.joints[j];
        assert_eq!(r.joint, m.dof_names()[j]);
        assert!((r.peak_torque - peak[j]).abs() < 1e-9 * peak[j]);
        assert!((r.peak_speed - speed[j]).abs() < 1e-12);
        assert!((r.peak_power - power[j]).abs() < 1e-9 * (1.0 + power[j]));
        let rms = (sq[j] / traj.duration()).sqrt();
        assert!((r.rms_torque - rms).abs() < 1e-9 * rms);
        assert_eq!(r.limit, m.effort_limit[j]);
        assert!((r.margin - 100.0 * (1.0 - peak[j] / m.effort_limit[j])).abs() < 1e-9);
        assert_eq!(
            r.ok,
            peak[j] <= m.effort_limit[j] && speed[j] <= m.velocity_limit[j]
        );
    }
    println!("{}", rep.table());
}

/// The planar arm without gravity, `q₁ = A sin ωt`, `q₂ = 0`: `τ₁ = −M₁₁(0) A ω² sin ωt`
/// and `τ₂ = −M₁₂(0) A ω² sin ωt` exactly (closed forms of `robots/planar_2r.toml`). With
/// `τ_max,1 = ½ M₁₁ A ω²` joint 1 first exceeds its limit at `t* = π / (6ω)`.
#[test]
fn first_violation_is_found_where_the_torque_crosses_the_limit() {
    let m = planar();
    let (a, w) = (0.8, 3.0);
    let (l, m1, m2) = (0.5f64, 2.0, 1.0);
    let m11 = m1 * l * l / 3.0 + m2 * l * l * (4.0 / 3.0 + 1.0);
    let m12 = m2 * l * l * (1.0 / 3.0 + 0.5);
    let peak1 = m11 * a * w * w;
    let peak2 = m12 * a * w * w;
    let traj = Sine {
        a,
        b: 0.0,
        w,
        t: 2.0,
    };
    let dt = 0.01;
    let opts = TorqueCheckOptions {
        dt,
        effort_limit: Some(vec![0.5 * peak1, 2.0 * peak2]),
        velocity_limit: Some(vec![10.0, 10.0]),
        keep_series: true,
    };
    let rep = check_torques(&m, &traj, &Effects::default(), &opts).unwrap();
    let t_star = std::f64::consts::PI / (6.0 * w);
    let r1 = &rep.joints[0];
    let first = r1.first_violation_s.expect("joint 1 violates");
    // The first sample over the limit, found independently, and the one before it.
    let k = rep
        .t
        .iter()
        .position(|&t| (m11 * a * w * w * (w * t).sin()).abs() > 0.5 * peak1)
        .unwrap();
    println!(
        "first violation {first:.6} s, exact {t_star:.6} s, bracket [{}, {}]",
        rep.t[k - 1],
        rep.t[k]
    );
    assert!(first >= rep.t[k - 1] && first <= rep.t[k]);
    assert!((first - t_star).abs() < dt, "{first} vs {t_star}");
    // Linear interpolation of a smooth crossing errs by about |f''/2f'| (t* − t₋)(t₊ − t*)
    // ≤ ω tan(π/6) dt²/8 here: second order in dt.
    assert!(
        (first - t_star).abs() <= w * (std::f64::consts::PI / 6.0).tan() * dt * dt / 8.0,
        "{first} vs {t_star}"
    );
    assert_eq!(r1.first_torque_violation_s, Some(first));
    assert_eq!(r1.first_speed_violation_s, None);
    assert!(!r1.ok && !rep.ok);
    assert!(
        r1.margin < 0.0
            && (r1.margin - 100.0 * (1.0 - r1.peak_torque / (0.5 * peak1))).abs() < 1e-12
    );
    assert!((r1.peak_torque - peak1).abs() < 1e-3 * peak1);
    let r2 = &rep.joints[1];
    assert!(r2.ok && r2.first_violation_s.is_none());
    assert!((r2.peak_torque - peak2).abs() < 1e-3 * peak2);
    assert!((r2.margin - 50.0).abs() < 0.1);

    // Speed: q₂ = B sin ωt alone with velocity limit ½ B ω: |q̇₂| = Bω|cos ωt| is over it
    // at the first sample, so the first violation is t = 0.
    let traj = Sine {
        a: 0.0,
        b: 0.5,
        w,
        t: 2.0,
    };
    let opts = TorqueCheckOptions {
        dt,
        effort_limit: Some(vec![f64::INFINITY; 2]),
        velocity_limit: Some(vec![10.0, 0.5 * 0.5 * w]),
        keep_series: true,
    };
    let rep = check_torques(&m, &traj, &Effects::default(), &opts).unwrap();
    let r2 = &rep.joints[1];
    assert_eq!(r2.first_speed_violation_s, Some(0.0));
    assert_eq!(r2.first_violation_s, Some(0.0));
    assert!(rep.joints[0].ok);
    let json = rep.json_rows();
    assert!(
        json[0]["limit"].is_null(),
        "infinite limits serialise as null"
    );
}

/// A speed crossing on the way up: `q₂ = B(1 − cos ωt)`, `|q̇₂| = Bω sin ωt` crosses
/// `½ Bω` at `t* = π/(6ω)`.
#[test]
fn first_speed_violation_is_interpolated() {
    struct Cos(f64, f64);
    impl Trajectory for Cos {
        fn dof(&self) -> usize {
            2
        }
        fn duration(&self) -> f64 {
            1.0
        }
        fn sample(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
            let (s, c) = (self.1 * t).sin_cos();
            q[0] = 0.0;
            qd[0] = 0.0;
            qdd[0] = 0.0;
            q[1] = self.0 * (1.0 - c);
            qd[1] = self.0 * self.1 * s;
            qdd[1] = self.0 * self.1 * self.1 * c;
        }
    }
    let m = planar();
    let (b, w, dt) = (0.4, 2.5, 0.005);
    let opts = TorqueCheckOptions {
        dt,
        effort_limit: Some(vec![f64::INFINITY; 2]),
        velocity_limit: Some(vec![1.0, 0.5 * b * w]),
        keep_series: true,
    };
    let rep = check_torques(&m, &Cos(b, w), &Effects::default(), &opts).unwrap();
    let t_star = std::f64::consts::PI / (6.0 * w);
    let got = rep.joints[1].first_speed_violation_s.unwrap();
    assert!(
        (got - t_star).abs() <= w * (std::f64::consts::PI / 6.0).tan() * dt * dt / 8.0,
        "{got} vs {t_star}"
    );
    assert!(rep.joints[1].first_torque_violation_s.is_none());
}

#[test]
fn torque_report_json_table_and_plots() {
    let (m, _) = ur5();
    let traj = MinJerk::new(&ur5_waypoints(), &ur5_limits(&m)).unwrap();
    let mut eff_lim = m.effort_limit.clone();
    eff_lim[1] = 20.0; // the shoulder cannot hold the arm with this: a violation to show
    let opts = TorqueCheckOptions {
        dt: 0.005,
        effort_limit: Some(eff_lim),
        velocity_limit: None,
        keep_series: true,
    };
    let rep = check_torques(&m, &traj, &Effects::gravity(m.gravity), &opts).unwrap();
    let rows = rep.json_rows();
    let keys: Vec<&str> = rows[0]
        .as_object()
        .unwrap()
        .keys()
        .map(|k| k.as_str())
        .collect();
    assert_eq!(
        &keys[..10],
        [
            "joint",
            "peak_torque",
            "rms_torque",
            "peak_speed",
            "peak_power",
            "limit",
            "velocity_limit",
            "margin",
            "ok",
            "first_violation_s"
        ]
    );
    assert_eq!(rows.as_array().unwrap().len(), 6);
    assert_eq!(rows[1]["ok"], false);
    assert!(rows[1]["first_violation_s"].is_number());
    assert!(rows[0]["first_violation_s"].is_null());
    let table = rep.table();
    assert!(
        table.contains("shoulder_lift_joint") && table.contains("NO"),
        "{table}"
    );
    assert!(table.contains("LIMITS EXCEEDED"));

    let dir = std::env::temp_dir().join(format!("armsim-traj-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png_path = dir.join("torques.png");
    assert_eq!(PlotFormat::from_path(&png_path), Some(PlotFormat::Png));
    write_torque_plot(&rep, &png_path, PlotFormat::Png, None).unwrap();
    let file = std::fs::File::open(&png_path).unwrap();
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (960, 220 * 6 + 40));
    let px = &buf[..info.buffer_size()];
    let count = |pred: &dyn Fn(&[u8]) -> bool| px.chunks(3).filter(|p| pred(p)).count();
    let red = count(&|p| p[0] > 200 && p[1] < 60 && p[2] < 60);
    let blue = count(&|p| p[2] > 200 && p[0] < 60 && p[1] < 60);
    let dark = count(&|p| p[0] < 60 && p[1] < 60 && p[2] < 60);
    assert!(
        red > 1000 && blue > 1000 && dark > 1000,
        "red {red} blue {blue} text {dark}"
    );
    let svg_path = dir.join("torques.svg");
    write_torque_plot(&rep, &svg_path, PlotFormat::Svg, None).unwrap();
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("shoulder_lift_joint"));
    // Written atomically: nothing but the two plots is left in the directory.
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["torques.png", "torques.svg"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn topp_path_derivatives_match_finite_differences() {
    // The path interface TOPP relies on: q' and q'' of the minimum-jerk path in s.
    let lim = planar_limits();
    let p = MinJerk::new(&planar_waypoints(), &lim).unwrap();
    let (mut q, mut dq, mut ddq) = ([0.0; 2], [0.0; 2], [0.0; 2]);
    let (mut qa, mut qb, mut da, mut db, mut x) =
        ([0.0; 2], [0.0; 2], [0.0; 2], [0.0; 2], [0.0; 2]);
    let h = 1e-6;
    for s in [0.1, 0.33, 0.5, 0.77, 0.9] {
        p.eval(s, &mut q, &mut dq, &mut ddq);
        p.eval(s + h, &mut qa, &mut da, &mut x);
        p.eval(s - h, &mut qb, &mut db, &mut x);
        for j in 0..2 {
            assert!(((qa[j] - qb[j]) / (2.0 * h) - dq[j]).abs() < 1e-6 * (1.0 + dq[j].abs()));
            assert!(((da[j] - db[j]) / (2.0 * h) - ddq[j]).abs() < 1e-5 * (1.0 + ddq[j].abs()));
        }
    }
}

/// Sampling any trajectory allocates nothing, and the torque check's allocations do not
/// grow with the number of samples (nothing is allocated per sample).
#[test]
fn sampling_and_checking_do_not_allocate_per_sample() {
    let (m, tool) = ur5();
    let w = ur5_waypoints();
    let lim = ur5_limits(&m);
    let trap = Trapezoidal::new(&w, &lim).unwrap();
    let quin = Quintic::new(&w, &lim).unwrap();
    let mj = MinJerk::new(&w, &lim).unwrap();
    let mut d = Data::new(&m);
    forward_kinematics(&m, &mut d, &w[0]);
    let start = frame_placement(&m, &d, tool);
    let goal = Se3::new(start.rot, start.trans + Vec3::new(0.05, 0.05, 0.0));
    let cart = cartesian_line(&m, tool, &w[0], &goal, &CartesianOptions::default()).unwrap();
    let tp = topp(&m, mj.clone(), &lim, &Effects::default(), &test_opts()).unwrap();
    let scaled = TimeScaled::new(quin.clone(), 1.3).unwrap();
    let trajs: [&dyn Trajectory; 6] = [&trap, &quin, &mj, &cart, &tp, &scaled];
    let (mut q, mut qd, mut qdd) = (vec![0.0; 6], vec![0.0; 6], vec![0.0; 6]);
    for traj in trajs {
        let before = allocs();
        for i in 0..=1000 {
            traj.sample(
                traj.duration() * i as f64 / 1000.0,
                &mut q,
                &mut qd,
                &mut qdd,
            );
        }
        assert_eq!(allocs(), before, "sampling allocated");
    }
    let eff = Effects::gravity(m.gravity);
    let count = |dt: f64| {
        let opts = TorqueCheckOptions {
            dt,
            ..Default::default()
        };
        let before = allocs();
        let rep = check_torques(&m, &mj, &eff, &opts).unwrap();
        let n = allocs() - before;
        drop(rep);
        n
    };
    let (coarse, fine) = (count(0.1), count(0.0001));
    assert_eq!(coarse, fine, "allocations grow with the samples");
}

#[test]
fn cartesian_line_reports_a_joint_jump() {
    let (m, tool) = ur5();
    let q0 = vec![0.3, -1.3, 1.5, -1.8, -1.57, 0.2];
    let mut d = Data::new(&m);
    forward_kinematics(&m, &mut d, &q0);
    let start = frame_placement(&m, &d, tool);
    let goal = Se3::new(start.rot, start.trans + Vec3::new(0.0, 0.2, 0.0));
    // 0.2 m in 100 steps moves some joint by more than 1e-4 rad per step.
    let opts = CartesianOptions {
        max_joint_step: 1e-4,
        ..Default::default()
    };
    let e = cartesian_line(&m, tool, &q0, &goal, &opts).unwrap_err();
    assert!(
        matches!(e, TrajectoryError::BranchJump { index: 0, .. }),
        "{e}"
    );
    assert!(e.to_string().contains("changed branch"));
}

#[test]
fn time_scaling_divides_velocities_and_accelerations() {
    let lim = planar_limits();
    let inner = Quintic::new(&planar_waypoints(), &lim).unwrap();
    let slow = TimeScaled::new(inner.clone(), 2.5).unwrap();
    assert!((slow.duration() - 2.5 * inner.duration()).abs() < 1e-12);
    let (mut q, mut qd, mut qdd) = ([0.0; 2], [0.0; 2], [0.0; 2]);
    let (mut p, mut pd, mut pdd) = ([0.0; 2], [0.0; 2], [0.0; 2]);
    for t in [0.3, 1.1, 2.0] {
        inner.sample(t, &mut q, &mut qd, &mut qdd);
        slow.sample(2.5 * t, &mut p, &mut pd, &mut pdd);
        for j in 0..2 {
            assert_eq!(p[j], q[j]);
            assert!((pd[j] * 2.5 - qd[j]).abs() < 1e-12);
            assert!((pdd[j] * 6.25 - qdd[j]).abs() < 1e-12);
        }
    }
    assert!(TimeScaled::new(inner, 0.0).is_err());
}

/// Without the stored series the figures are the same (they are computed streaming) and
/// the plot says why it cannot be drawn; a long chain plots its 24 most loaded joints.
#[test]
fn torque_check_streams_and_caps_the_plot() {
    let (m, _) = Model::build(armsim::model::chain::chain_spec(30)).unwrap();
    let n = m.nv;
    let w = vec![vec![0.0; n], (0..n).map(|k| 0.02 * k as f64).collect()];
    let traj = Quintic::new(&w, &JointLimits::uniform(n, 1.0, 2.0, f64::INFINITY)).unwrap();
    let eff = Effects::gravity(Vec3::new(0.0, 0.0, -9.81));
    let effort: Vec<f64> = (0..n).map(|k| 50.0 + k as f64).collect();
    let with = |keep_series: bool| {
        let opts = TorqueCheckOptions {
            dt: 0.01,
            effort_limit: Some(effort.clone()),
            velocity_limit: None,
            keep_series,
        };
        check_torques(&m, &traj, &eff, &opts).unwrap()
    };
    let (full, lean) = (with(true), with(false));
    assert_eq!(full.joints, lean.joints);
    assert!(lean.t.is_empty() && lean.tau.is_empty());
    assert_eq!(lean.samples, full.t.len());
    let dir = std::env::temp_dir().join(format!("armsim-traj-cap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let e = write_torque_plot(&lean, &dir.join("x.png"), PlotFormat::Png, None).unwrap_err();
    assert!(e.to_string().contains("keep_series"), "{e}");
    let png_path = dir.join("chain.png");
    write_torque_plot(&full, &png_path, PlotFormat::Png, None).unwrap();
    let dec = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(&png_path).unwrap(),
    ));
    let info = dec.read_info().unwrap();
    assert_eq!(info.info().height, 220 * 24 + 40);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Every profile holds its end points at rest: sampled before the start or after the end,
/// the velocity and acceleration are exactly zero (a held trapezoid used to report its
/// last deceleration forever, which a computed-torque controller tracked as a 1.5 cm
/// steady-state error).
#[test]
fn profiles_hold_their_end_points_at_rest() {
    let w = planar_waypoints();
    let lim = planar_limits();
    let n = w[0].len();
    let profiles: Vec<Box<dyn Trajectory>> = vec![
        Box::new(Trapezoidal::new(&w, &lim).unwrap()),
        Box::new(Quintic::new(&w, &lim).unwrap()),
        Box::new(MinJerk::new(&w, &lim).unwrap()),
        Box::new(
            topp(
                &planar(),
                LinearPath::new(w[0].clone(), w[1].clone()).unwrap(),
                &lim,
                &Effects::default(),
                &ToppOptions::default(),
            )
            .unwrap(),
        ),
    ];
    for p in &profiles {
        let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let mut last = vec![0.0; n];
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        p.sample(p.duration(), &mut last, &mut a, &mut b);
        for (t, end) in [(-1.0, &w[0]), (p.duration() + 0.5, &last)] {
            p.sample(t, &mut q, &mut qd, &mut qdd);
            for j in 0..n {
                assert!((q[j] - end[j]).abs() < 1e-12, "q at {t}: {q:?} vs {end:?}");
                assert!(qd[j].abs() < 1e-12, "qd at {t}: {qd:?}");
                assert!(qdd[j].abs() < 1e-9, "qdd at {t}: {qdd:?}");
            }
        }
    }
}
