//! Criterion benchmark of the workspace volume pass on ONE thread (a one-thread rayon
//! pool), for the UR5 (URDF, tool0) with the default 2 cm voxels, random and Sobol'
//! sampling: the batched hot loop (eight configurations in SIMD lanes) on its default
//! instruction set (AVX2 where the CPU has it), on baseline x86-64 and on AVX-512, and
//! with the scalar FK one configuration at a time (`batched_fk: false`, the FK as before
//! batching). The Jacobian pass is off; `thrpt` is tool positions per second per core.
//!
//! Before criterion's wall-clock runs it prints the same passes timed in process CPU time
//! (Linux `/proc/self/stat`), which a loaded shared machine does not inflate.
//!
//! Run: `cargo bench --bench workspace` (figures in `BENCHMARKS.md`).

use armsim::model::Model;
use armsim::workspace::{sample_workspace, Isa, Sampling, WorkspaceOptions};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};

const SAMPLES: u64 = 1 << 21;

/// User + system CPU seconds of this process (Linux), `None` elsewhere.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let fields: Vec<&str> = stat.rsplit(')').next()?.split_whitespace().collect();
    let ticks: f64 = fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

/// A variant: batched FK or not, and the instruction set (`None`: the default).
type Variant = (Sampling, bool, Option<Isa>);

fn options(samples: u64, (sampling, batched_fk, max_isa): Variant) -> WorkspaceOptions {
    WorkspaceOptions {
        samples,
        replicates: 2,
        sampling,
        extras: false,
        quiet: true,
        batched_fk,
        max_isa,
        ..Default::default()
    }
}

fn name((sampling, batched, isa): Variant) -> String {
    let isa = match isa {
        None => String::new(),
        Some(i) => format!("_{i:?}"),
    };
    let fk = if batched { "" } else { "_scalar_fk" };
    format!("volume_{sampling:?}{fk}{isa}").to_lowercase()
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
    let mut variants: Vec<Variant> = Vec::new();
    for sampling in [Sampling::Random, Sampling::Sobol] {
        variants.push((sampling, true, None));
        variants.push((sampling, false, None));
        variants.push((sampling, true, Some(Isa::Baseline)));
        if Isa::detected() >= Isa::Avx512 {
            variants.push((sampling, true, Some(Isa::Avx512)));
        }
    }
    for &v in &variants {
        let opts = options(1 << 23, v);
        let t0 = cpu_seconds();
        let r = pool.install(|| sample_workspace(&model, &opts).expect("runs"));
        if let (Some(a), Some(b)) = (t0, cpu_seconds()) {
            let ns = (b - a) / r.samples as f64 * 1e9;
            eprintln!(
                "workspace_ur5/{}: {} samples, {:.2} s CPU: {ns:.1} ns/sample, {:.2} M samples/s/core",
                name(v),
                r.samples,
                b - a,
                1e3 / ns
            );
        }
    }
    let mut g = c.benchmark_group("workspace_ur5");
    g.sample_size(10);
    g.throughput(Throughput::Elements(SAMPLES));
    for &v in &variants {
        let opts = options(SAMPLES, v);
        g.bench_function(name(v), |b| {
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
