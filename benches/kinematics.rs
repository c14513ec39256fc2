//! Criterion benchmarks: forward kinematics and all joint Jacobians on UR5, Panda, iiwa
//! and generated 100-joint chain, cycling over 256 random states inside the limits.
//! Run: `cargo bench --bench kinematics`.

use armsim::kinematics;
use armsim::model::data::Data;
use armsim::model::Model;
use armsim::studies::bench::{random_states, STATES};
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

fn models() -> Vec<Model> {
    armsim::studies::bench::benchmark_models(&[100])
}

fn kinematics_benches(c: &mut Criterion) {
    for model in models() {
        let nv = model.nv;
        let qs = random_states(&model, 0x5eed);
        let mut data = Data::new(&model);
        let mut g = c.benchmark_group(model.name.clone());
        let mut k = 0usize;
        let mut next = move || {
            k = (k + 1) % STATES;
            k
        };
        g.bench_function("fk", |b| {
            b.iter(|| {
                let i = next();
                kinematics::forward_kinematics(
                    &model,
                    &mut data,
                    black_box(&qs[i * nv..(i + 1) * nv]),
                );
            })
        });
        g.bench_function("fk+frames", |b| {
            b.iter(|| {
                let i = next();
                kinematics::forward_kinematics(
                    &model,
                    &mut data,
                    black_box(&qs[i * nv..(i + 1) * nv]),
                );
                kinematics::update_frames(&model, &mut data);
            })
        });
        g.bench_function("jacobians", |b| {
            b.iter(|| {
                let i = next();
                kinematics::compute_joint_jacobians(
                    &model,
                    &mut data,
                    black_box(&qs[i * nv..(i + 1) * nv]),
                );
            })
        });
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(50).warm_up_time(std::time::Duration::from_millis(500)).measurement_time(std::time::Duration::from_secs(2));
    targets = kinematics_benches
}
criterion_main!(benches);
