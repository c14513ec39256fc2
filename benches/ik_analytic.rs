//! Criterion benchmarks of the analytic IK: one call returns every solution inside the
//! limits (UR5: up to 8, Puma 560 and Stanford arm: up to 8), cycling over 256 targets
//! made by FK of random configurations inside the limits. The fixed-size solvers write
//! into a reused buffer (no allocation); `solve` is the convenience path (model-read
//! parameters, `Vec` output, branch labels).
//! Run: `cargo bench --bench ik_analytic`.

use armsim::core::spatial::Se3;
use armsim::kinematics::ik::analytic::{
    ur_ik, wrist_ik, AnalyticOptions, AnalyticSolver, UrParams, WristParams,
};
use armsim::kinematics::{forward_kinematics, frame_placement};
use armsim::model::data::Data;
use armsim::model::Model;
use armsim::studies::bench::{random_states, STATES};
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

fn load(file: &str) -> Model {
    let root = env!("CARGO_MANIFEST_DIR");
    Model::load(format!("{root}/robots/{file}"))
        .expect("robot loads")
        .0
}

fn targets(model: &Model, link: usize) -> Vec<Se3> {
    let qs = random_states(model, 0x1c_a7a1);
    let mut data = Data::new(model);
    (0..STATES)
        .map(|i| {
            forward_kinematics(model, &mut data, &qs[i * model.nv..(i + 1) * model.nv]);
            frame_placement(model, &data, link)
        })
        .collect()
}

fn ik_benches(c: &mut Criterion) {
    let mut out = Vec::with_capacity(8);

    let ur5 = load("ur5.urdf");
    let tool0 = ur5.link_id("tool0").unwrap();
    let ur_params = UrParams::from_model(&ur5, tool0).unwrap();
    let ur_targets = targets(&ur5, tool0);
    let ur_solver = AnalyticSolver::new(&ur5, tool0).unwrap();
    let opts = AnalyticOptions::default();
    let mut g = c.benchmark_group("ur5");
    let mut k = 0usize;
    g.bench_function("ur_ik_all", |b| {
        b.iter(|| {
            k = (k + 1) % STATES;
            black_box(ur_ik(&ur_params, black_box(&ur_targets[k]), &mut out)).ok();
        })
    });
    g.bench_function("solve_labelled", |b| {
        b.iter(|| {
            k = (k + 1) % STATES;
            black_box(ur_solver.solve(black_box(&ur_targets[k]), &opts)).ok();
        })
    });
    g.finish();

    for (file, params) in [
        ("puma560.toml", WristParams::puma560()),
        ("stanford.toml", WristParams::stanford()),
    ] {
        let model = load(file);
        let link = model.link_id("link6").unwrap();
        let tg = targets(&model, link);
        let mut g = c.benchmark_group(model.name.clone());
        g.bench_function("wrist_ik_all", |b| {
            b.iter(|| {
                k = (k + 1) % STATES;
                black_box(wrist_ik(&params, black_box(&tg[k]), &mut out)).ok();
            })
        });
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(50).warm_up_time(std::time::Duration::from_millis(500)).measurement_time(std::time::Duration::from_secs(2));
    targets = ik_benches
}
criterion_main!(benches);
