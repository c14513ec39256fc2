//! What each effect costs: one forward-dynamics evaluation (the work of a
//! semi-implicit-Euler step) and one inverse-dynamics evaluation on the iiwa 14, bare and
//! with each effect switched on alone, then all together. A left-out effect costs nothing.
//! Run: `cargo bench --bench effects`.

use armsim::core::spatial::{Inertia, Mat3, Vec3};
use armsim::dynamics::{self, Effects, Elasticity, ExternalWrench, Friction, Payload, Rotor};
use armsim::model::data::Data;
use armsim::model::Model;
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

fn effect_sets(m: &Model) -> Vec<(&'static str, Effects)> {
    let n = m.nv;
    let tool = m
        .links
        .iter()
        .position(|l| l.body == m.nbodies() - 1)
        .unwrap();
    let g = Some(Vec3::new(0.0, 0.0, -9.81));
    let friction = Friction {
        viscous: vec![0.5; n],
        coulomb: vec![1.0; n],
        stiction: vec![1.5; n],
        stribeck_velocity: vec![0.1; n],
        smoothing: 1e-3,
    };
    let rotor = Rotor {
        inertia: vec![1e-4; n],
        gear_ratio: vec![100.0; n],
        efficiency: vec![0.9; n],
    };
    let payload = Payload::new(
        m,
        tool,
        Inertia::new(3.0, Vec3::new(0.0, 0.0, 0.08), Mat3::identity() * 5e-3),
    )
    .unwrap();
    let wrench = vec![ExternalWrench {
        link: tool,
        force: Vec3::new(0.0, 0.0, -20.0),
        moment: Vec3::zeros(),
    }];
    let bare = Effects::default();
    vec![
        ("bare", bare.clone()),
        (
            "gravity",
            Effects {
                gravity: g,
                ..bare.clone()
            },
        ),
        (
            "friction",
            Effects {
                friction: Some(friction.clone()),
                ..bare.clone()
            },
        ),
        (
            "rotor",
            Effects {
                rotor: Some(rotor.clone()),
                ..bare.clone()
            },
        ),
        (
            "payload",
            Effects {
                payload: Some(payload.clone()),
                ..bare.clone()
            },
        ),
        (
            "external",
            Effects {
                external: wrench.clone(),
                ..bare.clone()
            },
        ),
        (
            "all_rigid",
            Effects {
                gravity: g,
                friction: Some(friction),
                rotor: Some(rotor),
                elasticity: None,
                payload: Some(payload),
                external: wrench,
            },
        ),
    ]
}

fn effects_benches(c: &mut Criterion) {
    let root = env!("CARGO_MANIFEST_DIR");
    let (m, _) = Model::load(format!("{root}/robots/iiwa14.urdf")).unwrap();
    let mut d = Data::new(&m);
    let q = m.neutral();
    let qd: Vec<f64> = (0..m.nv).map(|k| 0.1 * k as f64 - 0.3).collect();
    let tau: Vec<f64> = (0..m.nv).map(|k| 1.0 - 0.2 * k as f64).collect();
    let mut g = c.benchmark_group("iiwa14_effects");
    for (name, e) in effect_sets(&m) {
        g.bench_function(format!("fd/{name}"), |b| {
            b.iter(|| {
                let _ = dynamics::forward_dynamics_with(&m, &mut d, &e, black_box(&q), &qd, &tau);
            })
        });
        g.bench_function(format!("id/{name}"), |b| {
            b.iter(|| {
                dynamics::inverse_dynamics(&m, &mut d, &e, black_box(&q), &qd, &tau);
            })
        });
    }
    let el = Effects {
        gravity: Some(Vec3::new(0.0, 0.0, -9.81)),
        elasticity: Some(Elasticity {
            stiffness: vec![5e3; m.nv],
            damping: vec![2.0; m.nv],
            motor_inertia: vec![0.5; m.nv],
        }),
        ..Default::default()
    };
    let mut thdd = vec![0.0; m.nv];
    let theta: Vec<f64> = q.iter().map(|x| x + 1e-3).collect();
    g.bench_function("fd/elastic_gravity", |b| {
        b.iter(|| {
            let _ = dynamics::elastic_forward_dynamics(
                &m,
                &mut d,
                &el,
                black_box(&q),
                &qd,
                &theta,
                &qd,
                &tau,
                &mut thdd,
            );
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(40).warm_up_time(std::time::Duration::from_millis(300)).measurement_time(std::time::Duration::from_secs(1));
    targets = effects_benches
}
criterion_main!(benches);
