//! QP IK (clarabel): converges on local targets, every step respects position and
//! velocity limits, and the secondary goals act in the null space of the task.

mod common;

use armsim::kinematics::ik::qp::{qp_ik, qp_step, QpIkOptions, Secondary};
use armsim::kinematics::ik::IkStatus;
use armsim::kinematics::{forward_kinematics, frame_placement};
use armsim::model::data::Data;
use armsim::model::Model;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};

/// A start and a target 0.3 rad away, both in the inner 80 % of every joint range (QP IK
/// is a local method: a start pinned against a limit can sit in a bound-constrained local
/// minimum, which is the restarting LM solver's job).
fn local_target(
    m: &Model,
    link: usize,
    rng: &mut SmallRng,
) -> (Vec<f64>, armsim::core::spatial::Se3) {
    let inner = |k: usize, x: f64| {
        let (l, u) = m.sampling_bounds(k);
        x.clamp(l + 0.1 * (u - l), u - 0.1 * (u - l))
    };
    let q0: Vec<f64> = m
        .random_q(rng)
        .iter()
        .enumerate()
        .map(|(k, x)| inner(k, *x))
        .collect();
    let q1: Vec<f64> = q0
        .iter()
        .enumerate()
        .map(|(k, x)| inner(k, x + rng.random_range(-0.3..0.3)))
        .collect();
    let mut d = Data::new(m);
    forward_kinematics(m, &mut d, &q1);
    (q0, frame_placement(m, &d, link))
}

#[test]
fn qp_ik_converges_and_every_step_respects_position_and_velocity_limits() {
    for (file, link) in [
        ("robots/ur5.urdf", "tool0"),
        ("robots/iiwa14.urdf", "iiwa_link_ee"),
    ] {
        let m = common::load(file);
        let link = m.link_id(link).unwrap();
        let mut rng = SmallRng::seed_from_u64(41);
        let opts = QpIkOptions::default();
        let mut d = Data::new(&m);
        for _ in 0..15 {
            let (q0, target) = local_target(&m, link, &mut rng);
            let r = qp_ik(&m, link, &target, &q0, &opts);
            assert_eq!(r.status, IkStatus::Converged, "{file}: {r:?}");
            assert!(m.within_limits(&r.q, 0.0));
            // Step by step: inside the position limits and the velocity limits.
            let mut q = q0.clone();
            for _ in 0..5 {
                let dq = qp_step(&m, &mut d, link, &target, &q, &opts).unwrap();
                for k in 0..m.nv {
                    let vmax = m.velocity_limit[k] * opts.dt;
                    assert!(
                        dq[k].abs() <= vmax * (1.0 + 1e-6) + 1e-9,
                        "joint {k}: {} > {vmax}",
                        dq[k]
                    );
                    q[k] += dq[k];
                    assert!(q[k] >= m.lower[k] - 1e-7 && q[k] <= m.upper[k] + 1e-7);
                }
            }
        }
    }
}

#[test]
fn secondary_goals_act_in_the_null_space() {
    let m = common::load("robots/iiwa14.urdf");
    let link = m.link_id("iiwa_link_ee").unwrap();
    let mut rng = SmallRng::seed_from_u64(43);
    let home = m.neutral();
    let (mut closer, mut farther_from_limits, mut n) = (0, 0, 0);
    for _ in 0..10 {
        let (q0, target) = local_target(&m, link, &mut rng);
        let plain = qp_ik(&m, link, &target, &q0, &QpIkOptions::default());
        let homed = qp_ik(
            &m,
            link,
            &target,
            &q0,
            &QpIkOptions {
                secondary: Secondary::Home(home.clone()),
                max_steps: 400,
                ..Default::default()
            },
        );
        let away = qp_ik(
            &m,
            link,
            &target,
            &q0,
            &QpIkOptions {
                secondary: Secondary::AwayFromLimits,
                max_steps: 400,
                ..Default::default()
            },
        );
        for r in [&plain, &homed, &away] {
            assert_eq!(r.status, IkStatus::Converged, "{r:?}");
        }
        let dist = |q: &[f64]| {
            q.iter()
                .zip(&home)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        // Liégeois' joint-range criterion, the quantity the secondary goal descends.
        let range_cost = |q: &[f64]| {
            (0..m.nv)
                .map(|k| {
                    let (l, u) = m.sampling_bounds(k);
                    ((q[k] - 0.5 * (l + u)) / (u - l)).powi(2)
                })
                .sum::<f64>()
        };
        n += 1;
        if dist(&homed.q) < dist(&plain.q) - 1e-6 {
            closer += 1;
        }
        if range_cost(&away.q) < range_cost(&plain.q) + 1e-12 {
            farther_from_limits += 1;
        }
    }
    // The secondary goal pulls the redundant DOF without disturbing the task.
    assert!(closer >= n * 8 / 10, "home goal closer in {closer}/{n}");
    assert!(
        farther_from_limits >= n * 8 / 10,
        "away from limits in {farther_from_limits}/{n}"
    );
}
