//! Criterion benchmark of the workspace volume pass: forward kinematics of the tool link,
//! RNG or scrambled Sobol', and voxel insertion, per sample, on ONE thread (a one-thread
//! rayon pool), for the UR5 (URDF, tool0) with the default 2 cm voxels. The Jacobian pass
//! is off; `thrpt` is FK samples per second per core.
//!
//! Before criterion's wall-clock runs it prints the same pass timed in process CPU time
//! (Linux `/proc/self/stat`), which a loaded shared machine does not inflate.
//!
//! Run: `cargo bench --bench workspace` (figures in `docs/workspace.md`).

use armsim::model::Model;
use armsim::workspace::{sample_workspace, Sampling, WorkspaceOptions};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};

const SAMPLES: u64 = 1 << 21;

/// User + system CPU seconds of this process (Linux), `None` elsewhere.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let fields: Vec<&str> = stat.rsplit(')').next()?.split_whitespace().collect();
    let ticks: f64 = fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

fn workspace_benches(c: &mut Criterion) {
    let root = env!("CARGO_MANIFEST_DIR");
    let model = Model::load(format!("{root}/robots/ur5.urdf"))
        .expect("UR5 loads")
        .0;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    for sampling in [Sampling::Random, Sampling::Sobol] {
        let opts = WorkspaceOptions {
            samples: 1 << 23,
            replicates: 2,
            sampling,
            extras: false,
            quiet: true,
            ..Default::default()
        };
        let t0 = cpu_seconds();
        let r = pool.install(|| sample_workspace(&model, &opts).expect("runs"));
        if let (Some(a), Some(b)) = (t0, cpu_seconds()) {
            let ns = (b - a) / r.samples as f64 * 1e9;
            eprintln!(
                "workspace_ur5 {sampling:?}: {} samples, {:.2} s CPU: {ns:.0} ns/sample, {:.2} M samples/s/core",
                r.samples,
                b - a,
                1e3 / ns
            );
        }
    }
    let mut g = c.benchmark_group("workspace_ur5");
    g.sample_size(10);
    g.throughput(Throughput::Elements(SAMPLES));
    for sampling in [Sampling::Random, Sampling::Sobol] {
        let opts = WorkspaceOptions {
            samples: SAMPLES,
            replicates: 2,
            sampling,
            extras: false,
            quiet: true,
            ..Default::default()
        };
        let name = format!("volume_{sampling:?}").to_lowercase();
        g.bench_function(name, |b| {
            b.iter(|| pool.install(|| sample_workspace(&model, &opts).expect("runs")))
        });
    }
    let opts = WorkspaceOptions {
        samples: 1 << 18,
        replicates: 2,
        extras: true,
        extras_samples: Some(1 << 18),
        quiet: true,
        ..Default::default()
    };
    g.throughput(Throughput::Elements(1 << 18));
    g.bench_function("volume_and_jacobians_sobol", |b| {
        b.iter(|| pool.install(|| sample_workspace(&model, &opts).expect("runs")))
    });
    g.finish();
}

criterion_group!(benches, workspace_benches);
criterion_main!(benches);
