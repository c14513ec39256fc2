//! Criterion benchmarks: forward kinematics and all joint Jacobians on UR5, Panda, iiwa
//! and generated 100-joint chain, cycling over 256 random states inside the limits.
//! Run: `cargo bench --bench kinematics`.

use armsim::bench::{random_states, STATES};
use armsim::data::Data;
use armsim::kinematics;
use armsim::model::{chain, LoadOptions, Model};
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

fn models() -> Vec<Model> {
    let root = env!("CARGO_MANIFEST_DIR");
    // Panda as Pinocchio loads it by default (fingers independent, 9 DOF), and with its
    // mimic finger (8 DOF) as `panda_mimic`.
    let opts = LoadOptions {
        strict: false,
        ignore_mimic: true,
    };
    let mut v: Vec<Model> = ["ur5.urdf", "panda.urdf", "iiwa14.urdf"]
        .iter()
        .map(|f| {
            Model::load_with(format!("{root}/robots/{f}"), &opts)
                .expect("robot loads")
                .0
        })
        .collect();
    let mut mimic = Model::load(format!("{root}/robots/panda.urdf")).unwrap().0;
    mimic.name = "panda_mimic".into();
    v.push(mimic);
    v.push(Model::build(chain::chain_spec(100)).unwrap().0);
    v
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
