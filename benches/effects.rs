//! What each effect costs: one forward-dynamics evaluation (the work of a
//! semi-implicit-Euler step) and one inverse-dynamics evaluation on the iiwa 14, bare and
//! with each effect switched on alone, then all together. A left-out effect costs nothing.
//! Run: `cargo bench --bench effects`.

use armsim::core::spatial::Vec3;
use armsim::dynamics::{self, Effects, Elasticity};
use armsim::model::data::Data;
use armsim::model::Model;
use armsim::studies::tradeoffs::effects_study;
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

/// The trade-offs report's effect sets (bare, each effect alone), without the elastic ones
/// (their forward dynamics carries motor states: timed apart below), plus every rigid
/// effect at once.
fn effect_sets(m: &Model) -> Vec<(&'static str, Effects)> {
    let sets = effects_study::effect_sets(m).unwrap();
    let mut rigid: Vec<(&'static str, Effects)> = sets
        .into_iter()
        .map(|(name, _, e)| (name, e))
        .filter(|(name, _)| *name != "elasticity")
        .collect();
    for (name, e) in rigid.iter_mut().filter(|(name, _)| *name == "all") {
        *name = "all_rigid";
        e.elasticity = None;
    }
    rigid
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
