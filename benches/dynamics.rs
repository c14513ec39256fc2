//! Criterion benchmarks: RNEA and ABA (one state, and 256 states eight at a time in SIMD
//! lanes: `*_batch`, per 256 states), CRBA (one state, and `crba_batch`), the RNEA and ABA derivatives, `M⁻¹` and the linearised
//! semi-implicit Euler and RK4 steps (`linearise_euler`, `linearise_rk4`) on UR5, Panda (9 DOF, fingers as independent
//! joints as in Pinocchio), iiwa and generated 50-, 100- and 200-joint chains, cycling over
//! 256 random states. Run: `cargo bench --bench dynamics`.

use armsim::dynamics;
use armsim::model::data::Data;
use armsim::model::Model;
use armsim::studies::bench::{random_states, random_unit_states, STATES};
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

fn models() -> Vec<Model> {
    armsim::studies::bench::benchmark_models(&[50, 100, 200])
}

fn dynamics_benches(c: &mut Criterion) {
    for model in models() {
        let nv = model.nv;
        let qs = random_states(&model, 0x5eed);
        let vs = random_unit_states(nv, 0x5eee);
        let ws = random_unit_states(nv, 0x5eef);
        let mut data = Data::new(&model);
        let mut g_ = c.benchmark_group(model.name.clone());
        let mut k = 0usize;
        let mut next = move || {
            k = (k + 1) % STATES;
            k * nv..(k + 1) * nv
        };
        g_.bench_function("rnea", |b| {
            b.iter(|| {
                let s = next();
                dynamics::rnea(
                    &model,
                    &mut data,
                    black_box(&qs[s.clone()]),
                    &vs[s.clone()],
                    &ws[s],
                );
            })
        });
        // All 256 states through the eight-lane kernel: the median is per 256 states
        // (tools/bench_table.py divides by 256).
        let mut lanes = dynamics::RneaLanes::new(&model);
        let mut tau = vec![0.0; qs.len()];
        g_.bench_function("rnea_batch", |b| {
            b.iter(|| {
                dynamics::rnea_rows(&model, &mut lanes, black_box(&qs), &vs, &ws, &mut tau);
                black_box(&tau);
            })
        });
        g_.bench_function("crba", |b| {
            b.iter(|| {
                let s = next();
                dynamics::crba(&model, &mut data, black_box(&qs[s]));
            })
        });
        if model.has_mimic {
            g_.finish();
            continue;
        }
        let mut aba_lanes = dynamics::AbaLanes::new(&model);
        let mut qdd = vec![0.0; qs.len()];
        g_.bench_function("aba_batch", |b| {
            b.iter(|| {
                dynamics::aba_rows(&model, &mut aba_lanes, black_box(&qs), &vs, &ws, &mut qdd);
                black_box(&qdd);
            })
        });
        g_.bench_function("aba", |b| {
            b.iter(|| {
                let s = next();
                dynamics::aba(
                    &model,
                    &mut data,
                    black_box(&qs[s.clone()]),
                    &vs[s.clone()],
                    &ws[s],
                );
            })
        });
        g_.bench_function("rnea_derivatives", |b| {
            b.iter(|| {
                let s = next();
                dynamics::rnea_derivatives(
                    &model,
                    &mut data,
                    black_box(&qs[s.clone()]),
                    &vs[s.clone()],
                    &ws[s],
                );
            })
        });
        g_.bench_function("aba_derivatives", |b| {
            b.iter(|| {
                let s = next();
                let _ = dynamics::aba_derivatives(
                    &model,
                    &mut data,
                    black_box(&qs[s.clone()]),
                    &vs[s.clone()],
                    &ws[s],
                );
            })
        });
        g_.bench_function("minverse", |b| {
            b.iter(|| {
                let s = next();
                let _ = dynamics::compute_minverse(&model, &mut data, black_box(&qs[s]));
            })
        });
        g_.finish();
    }
}

/// CRBA on the 256 states in SIMD lanes (`crba_batch`, per 256 states), and the MPC step
/// linearisation (A, B) with the model's gravity, 1 ms step, in the same groups as the
/// algorithms they rest on.
fn crba_batch_and_linearisation_benches(c: &mut Criterion) {
    for model in models() {
        let nv = model.nv;
        let qs = random_states(&model, 0x5eed);
        let vs = random_unit_states(nv, 0x5eee);
        let ws = random_unit_states(nv, 0x5eef);
        let mut data = Data::new(&model);
        let mut g_ = c.benchmark_group(model.name.clone());
        let mut k = 0usize;
        let mut next = move || {
            k = (k + 1) % STATES;
            k * nv..(k + 1) * nv
        };
        let mut crba_lanes = dynamics::CrbaLanes::new(&model);
        let mut mass = vec![0.0; qs.len() * nv];
        g_.bench_function("crba_batch", |b| {
            b.iter(|| {
                dynamics::crba_rows(&model, &mut crba_lanes, black_box(&qs), &mut mass);
                black_box(&mass);
            })
        });
        let fx = dynamics::Effects::gravity(model.gravity);
        for (label, scheme) in [
            ("linearise_euler", dynamics::StepScheme::SemiImplicitEuler),
            ("linearise_rk4", dynamics::StepScheme::Rk4),
        ] {
            let mut lin = dynamics::StepLinearisation::new(&model, scheme, 1e-3).unwrap();
            g_.bench_function(label, |b| {
                b.iter(|| {
                    let s = next();
                    let _ = lin.linearise(
                        &model,
                        &mut data,
                        &fx,
                        black_box(&qs[s.clone()]),
                        &vs[s.clone()],
                        &ws[s],
                    );
                })
            });
        }
        g_.finish();
    }
}

/// The trace-form Lagrange reference (O(n⁴)): few samples, it is slow by design.
fn lagrange_benches(c: &mut Criterion) {
    for model in models() {
        let nv = model.nv;
        let qs = random_states(&model, 0x5eed);
        let vs = random_unit_states(nv, 0x5eee);
        let ws = random_unit_states(nv, 0x5eef);
        let g = model.gravity;
        let mut data = Data::new(&model);
        let mut grp = c.benchmark_group(model.name.clone());
        grp.sample_size(10);
        grp.bench_function("lagrange_trace", |b| {
            b.iter(|| {
                black_box(dynamics::lagrange_trace(
                    &model,
                    &mut data,
                    black_box(&qs[..nv]),
                    &vs[..nv],
                    &ws[..nv],
                    &g,
                ));
            })
        });
        grp.finish();
    }
}

criterion_group! {
    name = lagrange;
    config = Criterion::default().warm_up_time(std::time::Duration::from_millis(100)).measurement_time(std::time::Duration::from_millis(500));
    targets = lagrange_benches
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(40).warm_up_time(std::time::Duration::from_millis(400)).measurement_time(std::time::Duration::from_secs(2));
    targets = dynamics_benches, crba_batch_and_linearisation_benches
}
criterion_main!(benches, lagrange);
