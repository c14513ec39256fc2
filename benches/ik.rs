//! The IK benchmark of the issue: 10 000 random reachable poses per robot (FK of uniform
//! random q inside the limits), limits enforced, tolerance 1e-6 m / 1e-6 rad; success
//! rate, median, p99 and mean solve time; then the tolerance sweep 1e-3 … 1e-12 (what
//! accuracy costs in time). Single-threaded timings. Run: `cargo bench --bench ik`
//! (`ARMSIM_IK_TARGETS=N` to change the count).

use armsim::kinematics::ik::benchmark::{benchmark, random_targets};
use armsim::kinematics::ik::IkOptions;
use armsim::model::Model;

fn main() {
    let n: usize = std::env::var("ARMSIM_IK_TARGETS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10_000);
    let root = env!("CARGO_MANIFEST_DIR");
    println!("| robot | link | tolerance | targets | success % | median µs | p99 µs | mean µs | mean iterations |");
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|");
    for (file, link) in [
        ("ur5.urdf", "tool0"),
        ("panda.urdf", "panda_link8"),
        ("iiwa14.urdf", "iiwa_link_ee"),
    ] {
        let (m, _) = Model::load(format!("{root}/robots/{file}")).expect("robot loads");
        let l = m.link_id(link).unwrap();
        let targets = random_targets(&m, l, n, 2026);
        for tol in [1e-6, 1e-3, 1e-9, 1e-12] {
            let opts = IkOptions {
                tol_position: tol,
                tol_rotation: tol,
                ..Default::default()
            };
            let s = benchmark(&m, l, &targets, &opts);
            println!(
                "| {} | {link} | {tol:.0e} | {} | {:.2} | {:.1} | {:.1} | {:.1} | {:.1} |",
                m.name,
                s.targets,
                100.0 * s.success_rate,
                s.median_us,
                s.p99_us,
                s.mean_us,
                s.mean_iterations
            );
        }
    }
}
