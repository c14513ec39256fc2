//! Switchable effects, each against an independent route: friction and rotor terms by
//! their formulas, the payload against a model with the payload merged into the link,
//! external wrenches against `−Jᵀ F`, forward dynamics against inverse dynamics with
//! everything on, the flexible joint's free oscillation against `ω = √(k (1/J_m + 1/J_l))`,
//! and counters proving a left-out effect's code never runs.

mod common;

use armsim::core::spatial::{Inertia, Mat3, Vec3};
use armsim::dynamics::{self, Effects, Elasticity, ExternalWrench, Friction, Payload, Rotor};
use armsim::kinematics::{self, Expressed};
use armsim::model::data::Data;
use armsim::model::Model;
use nalgebra::DMatrix;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};

fn rv(rng: &mut SmallRng, n: usize, s: f64) -> Vec<f64> {
    (0..n).map(|_| rng.random_range(-s..s)).collect()
}

fn all_effects(m: &Model) -> Effects {
    let n = m.nv;
    // A link on the last body (the tool side of the chain).
    let tool = m
        .links
        .iter()
        .position(|l| l.body == m.nbodies() - 1)
        .unwrap();
    let payload_inertia = Inertia::new(
        2.0,
        Vec3::new(0.01, -0.02, 0.05),
        Mat3::from_diagonal(&Vec3::new(0.004, 0.005, 0.003)),
    );
    Effects {
        gravity: Some(Vec3::new(0.0, 0.0, -9.81)),
        friction: Some(Friction {
            viscous: vec![0.7; n],
            coulomb: vec![1.5; n],
            stiction: vec![2.0; n],
            stribeck_velocity: vec![0.05; n],
            smoothing: 1e-3,
        }),
        rotor: Some(Rotor {
            inertia: vec![2e-5; n],
            gear_ratio: vec![100.0; n],
            efficiency: vec![0.9; n],
        }),
        elasticity: None,
        payload: Some(Payload::new(m, tool, payload_inertia).unwrap()),
        external: vec![ExternalWrench {
            link: tool,
            force: Vec3::new(3.0, -2.0, 5.0),
            moment: Vec3::new(0.2, 0.1, -0.3),
        }],
    }
}

#[test]
fn left_out_effects_never_run_and_included_ones_do() {
    let m = common::load("robots/ur5.urdf");
    let mut d = Data::new(&m);
    let q = m.neutral();
    let v = vec![0.3; m.nv];
    dynamics::inverse_dynamics(&m, &mut d, &Effects::default(), &q, &v, &v);
    dynamics::forward_dynamics_with(&m, &mut d, &Effects::default(), &q, &v, &v).unwrap();
    dynamics::mass_matrix(&m, &mut d, &Effects::default(), &q);
    assert_eq!(
        d.effect_runs,
        Default::default(),
        "a bare rigid computation ran effect code"
    );
    let e = all_effects(&m);
    dynamics::inverse_dynamics(&m, &mut d, &e, &q, &v, &v);
    let r = d.effect_runs;
    assert_eq!(
        (
            r.gravity,
            r.friction,
            r.rotor,
            r.payload,
            r.external,
            r.elasticity
        ),
        (1, 1, 1, 1, 1, 0)
    );
    assert_eq!(
        d.effects_used,
        e.set(),
        "the result records what it included"
    );
    assert!(d.effects_used.contains("payload") && !d.effects_used.contains("joint_elasticity"));
    assert_eq!(
        e.names(),
        [
            "gravity",
            "friction",
            "rotor_inertia",
            "payload",
            "external_wrench"
        ]
    );
}

#[test]
fn friction_and_rotor_add_exactly_their_terms() {
    let m = common::load("robots/ur5.urdf");
    let mut d = Data::new(&m);
    let mut rng = SmallRng::seed_from_u64(21);
    let e = all_effects(&m);
    let (fr, ro) = (e.friction.clone().unwrap(), e.rotor.clone().unwrap());
    for _ in 0..20 {
        let q = m.random_q(&mut rng);
        let qd = rv(&mut rng, m.nv, 1.0);
        let qdd = rv(&mut rng, m.nv, 3.0);
        let g = Effects::gravity(Vec3::new(0.0, 0.0, -9.81));
        let base = dynamics::inverse_dynamics(&m, &mut d, &g, &q, &qd, &qdd).to_vec();
        let with = Effects {
            friction: Some(fr.clone()),
            rotor: Some(ro.clone()),
            ..g.clone()
        };
        let tau = dynamics::inverse_dynamics(&m, &mut d, &with, &q, &qd, &qdd).to_vec();
        for k in 0..m.nv {
            let r = qd[k] / 0.05;
            let f = 0.7 * qd[k] + (1.5 + 0.5 * (-r * r).exp()) * (qd[k] / 1e-3).tanh();
            let expect = base[k] + f + 2e-5 * 100.0 * 100.0 * qdd[k];
            assert!((tau[k] - expect).abs() < 1e-12, "{} vs {expect}", tau[k]);
        }
        // Gear stage: I_m N² on the diagonal of M and nowhere else.
        let m0 = dynamics::mass_matrix(&m, &mut d, &Effects::default(), &q).clone();
        let m1 = dynamics::mass_matrix(&m, &mut d, &with, &q).clone();
        let diff = m1 - m0;
        assert!((diff - DMatrix::identity(m.nv, m.nv) * 0.2).abs().max() < 1e-15);
    }
    // Friction is continuous and zero at rest; gear efficiency splits motoring/braking.
    assert_eq!(fr.torque(0, 0.0), 0.0);
    assert!((fr.torque(0, 1e-9) - fr.torque(0, -1e-9)).abs() < 1e-5);
    assert!((ro.motor_torque(0, 10.0, 1.0) - 10.0 / 90.0).abs() < 1e-15);
    assert!((ro.motor_torque(0, 10.0, -1.0) - 0.09).abs() < 1e-15);
}

#[test]
fn payload_equals_a_model_with_the_payload_merged_into_the_link() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/panda.urdf");
    let spec = Model::read_spec(&path).unwrap();
    let (m, _) = Model::build(spec.clone()).unwrap();
    let link = m.link_id("panda_hand").unwrap();
    let pi = Inertia::new(
        3.0,
        Vec3::new(0.0, 0.02, 0.1),
        Mat3::new(0.01, 0.001, 0.0, 0.001, 0.012, 0.0, 0.0, 0.0, 0.008),
    );
    let mut merged = spec;
    let l = merged
        .links
        .iter_mut()
        .find(|l| l.name == "panda_hand")
        .unwrap();
    l.inertial = l.inertial.combined(&pi);
    let (m2, _) = Model::build(merged).unwrap();
    let e = Effects {
        payload: Some(Payload::new(&m, link, pi).unwrap()),
        ..Effects::gravity(Vec3::new(0.0, 0.0, -9.81))
    };
    let g = Effects::gravity(Vec3::new(0.0, 0.0, -9.81));
    let (mut d, mut d2) = (Data::new(&m), Data::new(&m2));
    let mut rng = SmallRng::seed_from_u64(22);
    for _ in 0..20 {
        let q = m.random_q(&mut rng);
        let qd = rv(&mut rng, m.nv, 1.0);
        let qdd = rv(&mut rng, m.nv, 3.0);
        let a = dynamics::inverse_dynamics(&m, &mut d, &e, &q, &qd, &qdd).to_vec();
        let b = dynamics::inverse_dynamics(&m2, &mut d2, &g, &q, &qd, &qdd).to_vec();
        for k in 0..m.nv {
            assert!(
                (a[k] - b[k]).abs() < 1e-10 * b[k].abs().max(1.0),
                "{a:?} vs {b:?}"
            );
        }
        let ma = dynamics::mass_matrix(&m, &mut d, &e, &q).clone();
        let mb = dynamics::crba(&m2, &mut d2, &q).clone();
        assert!((ma - mb).abs().max() < 1e-12);
    }
}

#[test]
fn external_wrench_equals_minus_jacobian_transpose_times_wrench() {
    let m = common::load("robots/iiwa14.urdf");
    let mut d = Data::new(&m);
    let mut rng = SmallRng::seed_from_u64(23);
    let link = m.link_id("iiwa_link_5").unwrap();
    let (f, n) = (Vec3::new(4.0, -1.0, 2.5), Vec3::new(0.3, -0.7, 0.2));
    let e = Effects {
        external: vec![ExternalWrench {
            link,
            force: f,
            moment: n,
        }],
        ..Default::default()
    };
    for _ in 0..20 {
        let q = m.random_q(&mut rng);
        let qd = rv(&mut rng, m.nv, 1.0);
        let qdd = rv(&mut rng, m.nv, 3.0);
        let base =
            dynamics::inverse_dynamics(&m, &mut d, &Effects::default(), &q, &qd, &qdd).to_vec();
        let tau = dynamics::inverse_dynamics(&m, &mut d, &e, &q, &qd, &qdd).to_vec();
        let mut j = DMatrix::zeros(6, m.nv);
        kinematics::compute_joint_jacobians(&m, &mut d, &q);
        kinematics::frame_jacobian(&m, &d, link, Expressed::WorldAligned, &mut j);
        for k in 0..m.nv {
            let jt = j[(0, k)] * f.x
                + j[(1, k)] * f.y
                + j[(2, k)] * f.z
                + j[(3, k)] * n.x
                + j[(4, k)] * n.y
                + j[(5, k)] * n.z;
            assert!(
                (tau[k] - (base[k] - jt)).abs() < 1e-12,
                "joint {k}: {} vs {}",
                tau[k],
                base[k] - jt
            );
        }
    }
}

#[test]
fn forward_dynamics_inverts_inverse_dynamics_with_every_effect() {
    for file in [
        "robots/ur5.urdf",
        "robots/iiwa14.urdf",
        "tests/data/mimic_gripper.urdf",
    ] {
        let m = common::load(file);
        let e = all_effects(&m);
        let mut d = Data::new(&m);
        let mut rng = SmallRng::seed_from_u64(24);
        for _ in 0..20 {
            let q = m.random_q(&mut rng);
            let qd = rv(&mut rng, m.nv, 1.0);
            let qdd = rv(&mut rng, m.nv, 3.0);
            let tau = dynamics::inverse_dynamics(&m, &mut d, &e, &q, &qd, &qdd).to_vec();
            let back = dynamics::forward_dynamics_with(&m, &mut d, &e, &q, &qd, &tau)
                .unwrap()
                .to_vec();
            for k in 0..m.nv {
                assert!(
                    (back[k] - qdd[k]).abs() < 1e-9 * qdd[k].abs().max(1.0),
                    "{file}: {back:?} vs {qdd:?}"
                );
            }
        }
    }
}

#[test]
fn flexible_joint_oscillates_at_the_two_mass_frequency() {
    let (jl, jm, k) = (0.8, 0.2, 400.0);
    let m = common::single_joint(jl);
    let e = Effects {
        elasticity: Some(Elasticity {
            stiffness: vec![k],
            damping: vec![0.0],
            motor_inertia: vec![jm],
        }),
        ..Default::default()
    };
    let mut d = Data::new(&m);
    // State (q, qd, θ, θd); RK4 with a step far below the period.
    let f = |s: [f64; 4], d: &mut Data| -> [f64; 4] {
        let mut thdd = [0.0];
        let qdd = dynamics::elastic_forward_dynamics(
            &m,
            d,
            &e,
            &[s[0]],
            &[s[1]],
            &[s[2]],
            &[s[3]],
            &[0.0],
            &mut thdd,
        )
        .unwrap()[0];
        [s[1], qdd, s[3], thdd[0]]
    };
    let h = 1e-5;
    let mut s = [0.0, 0.0, 0.01, 0.0];
    let mut crossings = Vec::new();
    let mut prev = s[2] - s[0];
    for n in 0..200_000 {
        let k1 = f(s, &mut d);
        let add = |s: [f64; 4], k: [f64; 4], c: f64| {
            [
                s[0] + c * k[0],
                s[1] + c * k[1],
                s[2] + c * k[2],
                s[3] + c * k[3],
            ]
        };
        let k2 = f(add(s, k1, h / 2.0), &mut d);
        let k3 = f(add(s, k2, h / 2.0), &mut d);
        let k4 = f(add(s, k3, h), &mut d);
        for i in 0..4 {
            s[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        let defl = s[2] - s[0];
        if prev > 0.0 && defl <= 0.0 {
            // Linear interpolation of the downward zero crossing.
            crossings.push((n as f64 + prev / (prev - defl)) * h);
        }
        prev = defl;
    }
    assert!(crossings.len() >= 10);
    let period = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    let omega = 2.0 * std::f64::consts::PI / period;
    let expect = (k * (1.0 / jm + 1.0 / jl)).sqrt();
    assert!(
        (omega - expect).abs() < 1e-6 * expect,
        "ω = {omega}, expected {expect}"
    );
    // Momentum is conserved (no external torque): J_l q̇ + J_m θ̇ = 0.
    assert!((jl * s[1] + jm * s[3]).abs() < 1e-9);
}

#[test]
fn power_balance_holds_along_a_simulated_motion() {
    // E(T) − E(0) = ∫ q̇ᵀ τ dt along an RK4 simulation of the UR5 with gravity and a
    // time-varying torque; the integral by Simpson's rule on the same grid.
    let m = common::load("robots/ur5.urdf");
    let g = Vec3::new(0.0, 0.0, -9.81);
    let e = Effects::gravity(g);
    let mut d = Data::new(&m);
    let n = m.nv;
    let tau_at =
        |t: f64| -> Vec<f64> { (0..n).map(|k| 5.0 * (1.3 * t + k as f64).sin()).collect() };
    let rhs = |q: &[f64], qd: &[f64], t: f64, d: &mut Data| -> Vec<f64> {
        dynamics::forward_dynamics_with(&m, d, &e, q, qd, &tau_at(t))
            .unwrap()
            .to_vec()
    };
    let energy = |q: &[f64], qd: &[f64], d: &mut Data| {
        dynamics::kinetic_energy(&m, d, q, qd) + dynamics::potential_energy(&m, d, q, &g)
    };
    let (h, steps) = (1e-4, 10_000);
    let mut q = m.neutral();
    let mut qd = vec![0.0; n];
    let e0 = energy(&q, &qd, &mut d);
    let mut powers = vec![tau_at(0.0).iter().zip(&qd).map(|(a, b)| a * b).sum::<f64>()];
    for s in 0..steps {
        let t = s as f64 * h;
        let k1v = rhs(&q, &qd, t, &mut d);
        let q2: Vec<f64> = (0..n).map(|i| q[i] + h / 2.0 * qd[i]).collect();
        let v2: Vec<f64> = (0..n).map(|i| qd[i] + h / 2.0 * k1v[i]).collect();
        let k2v = rhs(&q2, &v2, t + h / 2.0, &mut d);
        let q3: Vec<f64> = (0..n).map(|i| q[i] + h / 2.0 * v2[i]).collect();
        let v3: Vec<f64> = (0..n).map(|i| qd[i] + h / 2.0 * k2v[i]).collect();
        let k3v = rhs(&q3, &v3, t + h / 2.0, &mut d);
        let q4: Vec<f64> = (0..n).map(|i| q[i] + h * v3[i]).collect();
        let v4: Vec<f64> = (0..n).map(|i| qd[i] + h * k3v[i]).collect();
        let k4v = rhs(&q4, &v4, t + h, &mut d);
        for i in 0..n {
            q[i] += h / 6.0 * (qd[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i]);
            qd[i] += h / 6.0 * (k1v[i] + 2.0 * k2v[i] + 2.0 * k3v[i] + k4v[i]);
        }
        powers.push(tau_at(t + h).iter().zip(&qd).map(|(a, b)| a * b).sum());
    }
    let work: f64 = h / 3.0
        * powers
            .iter()
            .enumerate()
            .map(|(i, p)| {
                p * if i == 0 || i == steps {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                }
            })
            .sum::<f64>();
    let de = energy(&q, &qd, &mut d) - e0;
    assert!(qd.iter().any(|v| v.abs() > 0.1), "the arm moved");
    assert!(
        (de - work).abs() < 1e-6 * work.abs().max(1.0),
        "ΔE = {de}, ∫ q̇ᵀτ = {work}"
    );
}
