//! Calibration of the workspace interval against closed forms: over 100 seeds per case,
//! the reported 95 % interval (or lower bound) must contain the true area or volume in at
//! least 95 runs, at budgets two orders of magnitude apart — from budgets where fewer
//! than half the voxels are hit (which must answer "lower bound" or a wide interval) to
//! budgets where the interval is two-sided and narrow. Also: the batched FK against the
//! scalar FK. Small models and coarse voxels keep it to seconds.

mod common;

use armsim::kinematics::fk_lanes::{Isa, ToolChain, LANES};
use armsim::kinematics::{forward_kinematics, frame_placement};
use armsim::model::data::Data;
use armsim::model::parse::dh_table as dh;
use armsim::model::Model;
use armsim::workspace::{sample_workspace, IntervalKind, Sampling, WorkspaceOptions};
use std::f64::consts::PI;

/// The planar 2R of `robots/planar_2r.toml` with link lengths `l1`, `l2`.
fn planar_2r_lengths(l1: f64, l2: f64) -> Model {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/planar_2r.toml");
    let text = std::fs::read_to_string(path).expect("readable");
    let text = text.replacen("a = 0.5", &format!("a = {l1}"), 1).replacen(
        "a = 0.5",
        &format!("a = {l2}"),
        1,
    );
    Model::build(dh::parse(&text, "planar_2r_lengths.toml").expect("parses"))
        .expect("builds")
        .0
}

/// One closed-form case.
struct Case {
    name: &'static str,
    model: Model,
    truth: f64,
    voxel: f64,
}

fn cases() -> Vec<Case> {
    let deg = |d: f64| d.to_radians();
    vec![
        Case {
            name: "2R disc (l = 0.5, 0.5)",
            model: planar_2r_lengths(0.5, 0.5),
            truth: PI,
            voxel: 0.05,
        },
        Case {
            name: "2R annulus (l = 0.6, 0.3)",
            model: planar_2r_lengths(0.6, 0.3),
            truth: PI * (0.81 - 0.09),
            voxel: 0.05,
        },
        Case {
            // r ∈ [0.6, 1.5], elevation [−45°, 60°], azimuth 340°.
            name: "R-R-P shell",
            model: common::load("robots/textbook_spherical_rrp.toml"),
            truth: (1.5f64.powi(3) - 0.6f64.powi(3)) / 3.0
                * (deg(60.0).sin() + deg(45.0).sin())
                * deg(340.0),
            voxel: 0.15,
        },
        Case {
            // Radius [0.3, 0.9], lift [0.2, 1.2], azimuth 340°.
            name: "R-P-P cylinder",
            model: common::load("robots/textbook_cylindrical_rpp.toml"),
            truth: 0.5 * (0.81 - 0.09) * deg(340.0) * 1.0,
            voxel: 0.1,
        },
    ]
}

/// Coverage of the truth over `seeds` runs of `samples` samples; returns (covered,
/// two-sided, median relative half-width of the two-sided ones, mean hit fraction).
fn calibrate(case: &Case, samples: u64, sampling: Sampling, seeds: u64) -> (u64, u64, f64, f64) {
    let (mut covered, mut two_sided, mut widths, mut hit) = (0, 0, Vec::new(), 0.0);
    let cells = case.truth
        / case
            .voxel
            .powi(if case.name.starts_with("2R") { 2 } else { 3 });
    for seed in 0..seeds {
        let o = WorkspaceOptions {
            samples,
            sampling,
            seed: 7919 * seed + samples,
            voxel: case.voxel,
            extras: false,
            quiet: true,
            ..Default::default()
        };
        let r = sample_workspace(&case.model, &o).expect("runs");
        let ok = r.interval_covers(case.truth);
        covered += u64::from(ok);
        hit += r.estimate.raw / case.voxel.powi(if r.planar { 2 } else { 3 }) / cells;
        if r.interval_kind == IntervalKind::Interval {
            two_sided += 1;
            widths.push(r.estimate.rel_half_width());
        }
        if !ok && std::env::var("WS_VERBOSE").is_ok() {
            eprintln!(
                "  miss: seed {seed}: {:.5} in {:?} ({:?}), truth {:.5}, C {:.5}, G {:?}",
                r.measure(),
                r.measure_interval(),
                r.interval_kind,
                case.truth,
                r.estimate.corrected,
                r.estimate.remaining
            );
        }
    }
    widths.sort_by(f64::total_cmp);
    let med = widths
        .get(widths.len() / 2)
        .copied()
        .unwrap_or(f64::INFINITY);
    (covered, two_sided, med, hit / seeds as f64)
}

/// The interval covers each closed form in at least 95 of 100 seeded runs at every
/// budget, from under-sampled (fewer than half the voxels hit: a lower bound) to covered
/// (a two-sided interval a few percent wide).
#[test]
fn interval_covers_the_closed_forms_at_every_budget() {
    let seeds: u64 = std::env::var("WS_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100);
    let mut failures = Vec::new();
    for case in cases() {
        for sampling in [Sampling::Random, Sampling::Sobol] {
            for samples in [1u64 << 9, 1 << 12, 1 << 15, 1 << 17] {
                let (cov, two, med, hit) = calibrate(&case, samples, sampling, seeds);
                eprintln!(
                    "{} {sampling:?} N = {samples}: covered {cov}/{seeds}, two-sided {two}, median half-width {:.2} %, voxels hit {:.0} %",
                    case.name,
                    100.0 * med,
                    100.0 * hit
                );
                if cov * 100 < 95 * seeds {
                    failures.push(format!(
                        "{} {sampling:?} N = {samples}: {cov}/{seeds}",
                        case.name
                    ));
                }
                if hit < 0.5 && two > 0 {
                    // Under-sampled: a two-sided interval must be wide.
                    assert!(
                        med > 0.1,
                        "{}: N = {samples} hits {hit:.2} of the voxels but claims ±{med:.3}",
                        case.name
                    );
                }
                if samples == 1 << 17 {
                    assert!(
                        two * 10 >= 9 * seeds,
                        "{}: {two}/{seeds} two-sided at N = {samples}",
                        case.name
                    );
                    // Covered: the interval is two-sided and does not balloon (measured
                    // medians: 2R 1.8–2.1 %, R-R-P 12–16 %, R-P-P 16–25 %).
                    let cap = if case.name.starts_with("2R") {
                        0.03
                    } else {
                        0.35
                    };
                    assert!(
                        med < cap,
                        "{}: median half-width {med} at N = {samples}",
                        case.name
                    );
                }
            }
        }
    }
    assert!(failures.is_empty(), "coverage below 95 %: {failures:?}");
}

/// The batched FK gives the scalar FK's tool positions to 1e-12 m on every robot.
#[test]
fn batched_fk_matches_scalar_fk() {
    for path in common::robot_files() {
        let model = common::load(path.to_str().expect("utf-8"));
        let tool = model.links.len() - 1;
        let Some(chain) = ToolChain::new(&model, tool) else {
            continue;
        };
        let mut data = Data::new(&model);
        let mut worst = 0.0f64;
        let mut x = 0.123_456_789f64;
        for _ in 0..64 {
            let mut q = vec![[0.0; LANES]; model.nv];
            for lanes in q.iter_mut() {
                for v in lanes.iter_mut() {
                    x = (x * 997.0 + 0.271).fract();
                    *v = (x - 0.5) * 8.0;
                }
            }
            let mut out = [[0.0; LANES]; 3];
            chain.positions(&q, &mut out);
            for l in 0..LANES {
                let ql: Vec<f64> = q.iter().map(|v| v[l]).collect();
                forward_kinematics(&model, &mut data, &ql);
                let p = frame_placement(&model, &data, tool).trans;
                for a in 0..3 {
                    worst = worst.max((out[a][l] - p[a]).abs());
                }
            }
        }
        eprintln!("{}: worst |batched − scalar| = {worst:e} m", path.display());
        assert!(worst < 1e-12, "{}: {worst:e}", path.display());
    }
}

/// Writes `docs/workspace_convergence.png` (the report's convergence plot for a run of
/// 2^25 samples on the R-R-P shell at 5 cm) — run by hand:
/// `cargo test --release --test workspace_calibration -- --ignored convergence_plot`.
#[test]
#[ignore = "writes the documentation's plot"]
fn convergence_plot_for_the_docs() {
    use armsim::studies::tradeoffs::markdown::workspace_convergence_png;
    use armsim::studies::tradeoffs::workspace_study as workspace;
    let model = common::load("robots/textbook_spherical_rrp.toml");
    let o = WorkspaceOptions {
        samples: 1 << 25,
        voxel: 0.05,
        extras: false,
        quiet: true,
        ..Default::default()
    };
    let r = sample_workspace(&model, &o).expect("runs");
    let run = workspace::ConvergenceRun {
        case: "textbook spherical R-R-P shell".into(),
        truth: workspace::rrp_truth(),
        voxel: 0.05,
        points: r.convergence.clone(),
    };
    for p in &run.points {
        eprintln!(
            "| {} | {:.4} | {} | {} |",
            p.samples,
            p.measure,
            p.interval[0].map_or("–".into(), |v| format!("{v:.4}")),
            p.interval[1].map_or("–".into(), |v| format!("{v:.4}"))
        );
    }
    let png = workspace_convergence_png(&run).expect("renders");
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/workspace_convergence.png");
    std::fs::write(path, png).expect("writes");
    assert!(r.interval_covers(run.truth));
}

/// User + system CPU seconds of this process (Linux), `None` elsewhere.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let fields: Vec<&str> = stat.rsplit(')').next()?.split_whitespace().collect();
    let ticks: f64 = fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

/// CPU time of the batched FK alone (UR5 tool0), per instruction set.
fn fk_only_throughput(model: &Model) {
    let tool = model.link_id("tool0").expect("tool0");
    let mut q = vec![[0.0; LANES]; model.nv];
    for (k, lanes) in q.iter_mut().enumerate() {
        for (l, v) in lanes.iter_mut().enumerate() {
            *v = 0.1 * (k * LANES + l) as f64 - 2.0;
        }
    }
    for isa in [Isa::Baseline, Isa::Avx2, Isa::Avx512] {
        if isa > Isa::detected() {
            continue;
        }
        let mut chain = ToolChain::new(model, tool).expect("moves");
        chain.limit_isa(isa);
        let batches = 1u64 << 21;
        let mut out = [[0.0; LANES]; 3];
        let mut sum = 0.0;
        let t0 = cpu_seconds().expect("linux");
        for _ in 0..batches {
            q[0][0] += 1e-9;
            chain.positions(std::hint::black_box(&q), &mut out);
            sum += out[0][0];
        }
        let t1 = cpu_seconds().expect("linux");
        eprintln!(
            "UR5 batched FK alone {isa:?}: {:.1} ns/configuration ({sum:.3})",
            (t1 - t0) / (batches * LANES as u64) as f64 * 1e9
        );
    }
}

/// Throughput of the volume pass on one core, UR5 at 2 cm, random and Sobol', batched
/// and scalar FK, in process CPU time (the figures of `BENCHMARKS.md`) — run by hand:
/// `cargo test --release --test workspace_calibration -- --ignored throughput --nocapture`.
#[test]
#[ignore = "a measurement"]
fn throughput_batched_and_scalar_fk() {
    let model = common::load("robots/ur5.urdf");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let variants = [
        (false, Isa::detected()),
        (true, Isa::Baseline),
        (true, Isa::Avx2),
        (true, Isa::Avx512),
    ];
    fk_only_throughput(&model);
    for (batched_fk, isa) in variants.into_iter().filter(|v| v.1 <= Isa::detected()) {
        for sampling in [Sampling::Random, Sampling::Sobol] {
            let o = WorkspaceOptions {
                samples: 1 << 23,
                replicates: 2,
                sampling,
                extras: false,
                quiet: true,
                batched_fk,
                max_isa: Some(isa),
                ..Default::default()
            };
            let mut per = Vec::new();
            for _ in 0..3 {
                let t0 = cpu_seconds().expect("linux");
                let r = pool.install(|| sample_workspace(&model, &o).expect("runs"));
                let t1 = cpu_seconds().expect("linux");
                per.push((t1 - t0) / r.samples as f64 * 1e9);
            }
            per.sort_by(f64::total_cmp);
            eprintln!(
                "UR5 {sampling:?} {} {isa:?}: median {:.1} ns/sample CPU ({:.2} M tool positions/s/core), runs {per:.1?}",
                if batched_fk { "batched FK" } else { "scalar FK" },
                per[1],
                1e3 / per[1]
            );
        }
    }
}

/// The volume pass on every instruction set this CPU has (baseline SSE2, AVX2, AVX-512),
/// with the batched and the scalar FK, on one thread and on two: bitwise the same result
/// (the whole JSON but the time and the thread count), for a 3-D arm (UR5) and a planar
/// one (2R), random and Sobol'.
#[test]
fn every_instruction_set_gives_bitwise_identical_estimates() {
    let best = Isa::detected();
    let isas: Vec<Isa> = [Isa::Baseline, Isa::Avx2, Isa::Avx512]
        .into_iter()
        .filter(|&i| i <= best)
        .collect();
    let fingerprint = |r: &armsim::workspace::WorkspaceResult| {
        let mut v = serde_json::to_value(r).expect("serializes");
        let o = v.as_object_mut().expect("object");
        o.remove("time_s");
        o.remove("threads");
        v.to_string()
    };
    for (model, voxel) in [
        (common::load("robots/ur5.urdf"), 0.05),
        (planar_2r_lengths(0.5, 0.3), 0.02),
    ] {
        for sampling in [Sampling::Random, Sampling::Sobol] {
            let run = |isa: Isa, batched_fk: bool, threads: usize| {
                let o = WorkspaceOptions {
                    samples: 1 << 17,
                    replicates: 3,
                    sampling,
                    seed: 5,
                    voxel,
                    extras: false,
                    quiet: true,
                    batched_fk,
                    max_isa: Some(isa),
                    ..Default::default()
                };
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .expect("pool");
                pool.install(|| sample_workspace(&model, &o).expect("runs"))
            };
            let reference = run(Isa::Baseline, false, 1);
            assert!(reference.occupied_voxels > 100);
            let want = fingerprint(&reference);
            for &isa in &isas {
                for (batched, threads) in [(true, 1), (true, 2), (false, 2)] {
                    let got = fingerprint(&run(isa, batched, threads));
                    assert!(
                        got == want,
                        "{} {sampling:?} {isa:?} batched {batched} threads {threads}",
                        model.name
                    );
                }
            }
            eprintln!(
                "{} {sampling:?}: {} voxels, identical on {isas:?}",
                model.name, reference.occupied_voxels
            );
        }
    }
}
