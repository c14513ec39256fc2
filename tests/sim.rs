//! Simulation: energy is conserved when nothing dissipates, computed torque tracks,
//! stiff joint springs blow up the explicit integrators (and the program says so) while
//! the implicit one stays stable, and effects that are left out never run.

mod common;

use armsim::core::spatial::Vec3;
use armsim::dynamics::{Effects, Elasticity, Friction};
use armsim::sim::{Controller, Hold, Integrator, SimConfig, SimError, Simulator};

fn cfg(dt: f64, duration: f64, integrator: Integrator, controller: Controller) -> SimConfig {
    SimConfig {
        dt,
        duration,
        integrator,
        controller,
        record_every: 10,
    }
}

#[test]
fn energy_is_conserved_in_free_motion_under_gravity() {
    let m = common::load("robots/ur5.urdf");
    let q0 = vec![0.3, -1.0, 1.2, -0.5, 0.8, 0.2];
    let g = Effects::gravity(Vec3::new(0.0, 0.0, -9.81));
    let mut sim = Simulator::new(&m, g.clone()).unwrap();
    let rk4 = sim
        .run(
            &q0,
            &cfg(1e-4, 1.0, Integrator::Rk4, Controller::None),
            &Hold(q0.clone()),
            |_| {},
        )
        .unwrap();
    let audit = rk4.energy.expect("conservative scene is audited");
    assert!(
        audit.max_relative_drift < 1e-8,
        "RK4 drift {:e}",
        audit.max_relative_drift
    );
    // The symplectic Euler's energy error stays bounded and small, not exact.
    let mut sim = Simulator::new(&m, g).unwrap();
    let se = sim
        .run(
            &q0,
            &cfg(1e-4, 1.0, Integrator::SemiImplicitEuler, Controller::None),
            &Hold(q0.clone()),
            |_| {},
        )
        .unwrap();
    let d = se.energy.unwrap().max_relative_drift;
    assert!(
        d < 1e-2 && d > audit.max_relative_drift,
        "semi-implicit drift {d:e}"
    );
    assert!(rk4.real_time_factor > 0.0 && rk4.steps == 10_000);
}

#[test]
fn actuator_work_balances_energy_under_pd_control() {
    let m = common::load("robots/iiwa14.urdf");
    let q0 = m.neutral();
    let target: Vec<f64> = q0.iter().map(|x| x + 0.2).collect();
    let mut sim = Simulator::new(&m, Effects::gravity(Vec3::new(0.0, 0.0, -9.81))).unwrap();
    let pd = Controller::PdGravity {
        kp: vec![200.0; 7],
        kd: vec![20.0; 7],
    };
    let r = sim
        .run(
            &q0,
            &cfg(1e-4, 1.5, Integrator::Rk4, pd),
            &Hold(target.clone()),
            |_| {},
        )
        .unwrap();
    // E(t) − E(0) equals the actuator work (trapezoidal quadrature of τ·q̇ on the grid).
    assert!(
        r.energy.as_ref().unwrap().max_relative_drift < 1e-5,
        "{:?}",
        r.energy
    );
    for (q, t) in r.final_q.iter().zip(&target) {
        assert!(
            (q - t).abs() < 1e-2,
            "PD + gravity compensation settles near the set point"
        );
    }
}

#[test]
fn computed_torque_tracks_with_the_exact_model_and_left_out_effects_never_run() {
    let m = common::load("robots/ur5.urdf");
    let q0 = vec![0.0, -1.2, 1.0, -0.4, 1.1, 0.0];
    let target: Vec<f64> = q0.iter().map(|x| x - 0.3).collect();
    let effects = Effects::gravity(Vec3::new(0.0, 0.0, -9.81));
    let mut sim = Simulator::new(&m, effects).unwrap();
    let ct = Controller::ComputedTorque {
        kp: vec![100.0; 6],
        kd: vec![20.0; 6],
    };
    let mut samples = 0;
    let r = sim
        .run(
            &q0,
            &cfg(1e-3, 2.0, Integrator::Rk4, ct),
            &Hold(target.clone()),
            |_| samples += 1,
        )
        .unwrap();
    // Critically damped error dynamics e'' + 20 e' + 100 e = 0 from e(0) = 0.3:
    // e(2) = 0.3 (1 + 10·2) e^{-20} ≈ 1.3e-8.
    for (q, t) in r.final_q.iter().zip(&target) {
        assert!((q - t).abs() < 1e-6, "{q} vs {t}");
    }
    assert_eq!(samples, 201);
    let runs = sim.effect_runs();
    assert!(runs.gravity > 0);
    assert_eq!(
        (
            runs.friction,
            runs.rotor,
            runs.elasticity,
            runs.payload,
            runs.external
        ),
        (0, 0, 0, 0, 0)
    );
    assert!(r.energy.is_some());
}

#[test]
fn stiff_springs_blow_up_explicit_integrators_but_not_the_implicit_one() {
    let m = common::load("robots/planar_2r.toml");
    let stiff = Effects {
        gravity: Some(Vec3::new(0.0, 0.0, -9.81)),
        elasticity: Some(Elasticity {
            stiffness: vec![2e6; 2],
            damping: vec![5.0; 2],
            motor_inertia: vec![1e-3; 2],
        }),
        ..Default::default()
    };
    let q0 = vec![0.2, 0.3];
    let pd = Controller::PdGravity {
        kp: vec![50.0; 2],
        kd: vec![5.0; 2],
    };
    // Fastest mode ≈ √(k/J_m) ≈ 4.5e4 rad/s: explicit methods need h < ~6e-5 s.
    for method in [Integrator::Rk4, Integrator::SemiImplicitEuler] {
        let mut sim = Simulator::new(&m, stiff.clone()).unwrap();
        let err = sim
            .run(
                &q0,
                &cfg(1e-3, 0.5, method, pd.clone()),
                &Hold(q0.clone()),
                |_| {},
            )
            .unwrap_err();
        match err {
            SimError::Diverged { hint, .. } => assert!(hint.contains("implicit"), "{hint}"),
            other => panic!("{method:?}: {other}"),
        }
    }
    let mut sim = Simulator::new(&m, stiff).unwrap();
    let r = sim
        .run(
            &q0,
            &cfg(1e-3, 0.5, Integrator::Implicit, pd),
            &Hold(q0.clone()),
            |_| {},
        )
        .unwrap();
    assert!(r.final_q.iter().all(|x| x.is_finite()));
    for (q, t) in r.final_q.iter().zip(&q0) {
        assert!(
            (q - t).abs() < 0.05,
            "the implicit run holds the set point: {q} vs {t}"
        );
    }
}

#[test]
fn friction_dissipates_and_switches_the_energy_audit_off() {
    let m = common::load("robots/planar_2r.toml");
    let n = m.nv;
    let e = Effects {
        gravity: Some(Vec3::new(0.0, 0.0, -9.81)),
        friction: Some(Friction {
            viscous: vec![0.5; n],
            coulomb: vec![0.2; n],
            stiction: vec![0.3; n],
            stribeck_velocity: vec![0.1; n],
            smoothing: 1e-3,
        }),
        ..Default::default()
    };
    let mut sim = Simulator::new(&m, e).unwrap();
    let r = sim
        .run(
            &[0.0, 0.0],
            &cfg(1e-3, 3.0, Integrator::Rk4, Controller::None),
            &Hold(vec![0.0; 2]),
            |_| {},
        )
        .unwrap();
    assert!(
        r.energy.is_none(),
        "a dissipative scene is not audited as conservative"
    );
    assert!(sim.effect_runs().friction > 0);
}
