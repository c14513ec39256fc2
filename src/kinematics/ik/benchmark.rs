//! The IK benchmark: random reachable targets (FK of uniform random configurations inside
//! the limits), solved from the middle of the limits with joint limits enforced; success
//! rate and time statistics (median, p99, mean) of the single-target solve time.

use crate::core::spatial::Se3;
use crate::kinematics::ik::numeric::{IkOptions, IkSolver, IkStatus};
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::model::data::Data;
use crate::model::Model;
use rand::rngs::SmallRng;
use rand::SeedableRng;

/// Statistics of one benchmark run.
#[derive(Clone, Debug, serde::Serialize)]
pub struct IkBenchStats {
    /// Targets solved.
    pub targets: usize,
    /// Fraction converged within tolerance.
    pub success_rate: f64,
    /// Median solve time (µs).
    pub median_us: f64,
    /// 99th percentile solve time (µs).
    pub p99_us: f64,
    /// Mean solve time (µs).
    pub mean_us: f64,
    /// Mean iterations.
    pub mean_iterations: f64,
    /// Worst position error among converged solves (m).
    pub worst_position_error: f64,
    /// Worst rotation error among converged solves (rad).
    pub worst_rotation_error: f64,
}

/// `n` reachable targets for `link`: FK of uniform random configurations (seeded).
pub fn random_targets(model: &Model, link: usize, n: usize, seed: u64) -> Vec<Se3> {
    let mut rng = SmallRng::seed_from_u64(seed);
    let mut data = Data::new(model);
    (0..n)
        .map(|_| {
            let q = model.random_q(&mut rng);
            forward_kinematics(model, &mut data, &q);
            frame_placement(model, &data, link)
        })
        .collect()
}

/// Solves every target on this thread (timings are per single solve) and summarises.
pub fn benchmark(model: &Model, link: usize, targets: &[Se3], opts: &IkOptions) -> IkBenchStats {
    let mut solver = IkSolver::new(model);
    let mut times = Vec::with_capacity(targets.len());
    let (mut ok, mut iters) = (0usize, 0usize);
    let (mut wp, mut wr) = (0.0f64, 0.0f64);
    for (i, t) in targets.iter().enumerate() {
        let mut o = opts.clone();
        o.seed = opts.seed.wrapping_add(i as u64);
        let r = solver.solve(model, link, t, None, &o);
        times.push(r.time_us);
        iters += r.iterations;
        if r.status == IkStatus::Converged {
            ok += 1;
            wp = wp.max(r.position_error);
            wr = wr.max(r.rotation_error);
        }
    }
    times.sort_by(f64::total_cmp);
    let n = times.len().max(1);
    IkBenchStats {
        targets: targets.len(),
        success_rate: ok as f64 / n as f64,
        median_us: times[n / 2],
        p99_us: times[((n as f64 * 0.99) as usize).min(n - 1)],
        mean_us: times.iter().sum::<f64>() / n as f64,
        mean_iterations: iters as f64 / n as f64,
        worst_position_error: wp,
        worst_rotation_error: wr,
    }
}
