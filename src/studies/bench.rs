//! The in-program timer behind `armsim bench`: time `N` calls of one algorithm cycling
//! over 256 random states inside the limits, after a warm-up, and report the median
//! nanoseconds per call over several rounds (the machines are shared and noisy; criterion
//! benches under `benches/` are the reference figures).

use crate::dynamics;
use crate::kinematics;
use crate::model::data::Data;
use crate::model::Model;
use rand::rngs::SmallRng;
use rand::SeedableRng;
use std::hint::black_box;
use std::time::Instant;

/// Algorithms `armsim bench` can time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Algo {
    /// Forward kinematics: every body placement and every link frame.
    Fk,
    /// Forward kinematics plus every joint's world Jacobian column.
    Jacobians,
    /// Inverse dynamics (RNEA) at random q, q̇, q̈.
    Rnea,
    /// RNEA over the 256 states eight at a time in SIMD lanes
    /// ([`dynamics::rnea_rows`]); a "call" is one state.
    RneaBatch,
    /// The full mass matrix (CRBA).
    Crba,
    /// CRBA over the 256 states eight at a time in SIMD lanes ([`dynamics::crba_rows`]);
    /// a "call" is one state.
    CrbaBatch,
    /// Forward dynamics (ABA) at random q, q̇, τ.
    Aba,
    /// ABA over the 256 states eight at a time in SIMD lanes ([`dynamics::aba_rows`]);
    /// a "call" is one state.
    AbaBatch,
    /// The textbook's trace-form Lagrange inverse dynamics (O(n⁴) reference).
    Lagrange,
}

impl Algo {
    /// CLI spelling.
    pub fn as_str(&self) -> &'static str {
        match self {
            Algo::Fk => "fk",
            Algo::Jacobians => "jacobians",
            Algo::Rnea => "rnea",
            Algo::RneaBatch => "rnea-batch",
            Algo::Crba => "crba",
            Algo::CrbaBatch => "crba-batch",
            Algo::Aba => "aba",
            Algo::AbaBatch => "aba-batch",
            Algo::Lagrange => "lagrange",
        }
    }

    /// Whether a "call" is one state of a SIMD pass over eight.
    pub fn is_batch(&self) -> bool {
        matches!(self, Algo::RneaBatch | Algo::AbaBatch | Algo::CrbaBatch)
    }
}

/// Number of random states cycled over.
pub const STATES: usize = 256;
/// Number of timing rounds whose median is reported.
pub const ROUNDS: usize = 11;

/// `STATES` random configurations, flattened (`STATES × nv`), from a fixed seed.
pub fn random_states(model: &Model, seed: u64) -> Vec<f64> {
    let mut rng = SmallRng::seed_from_u64(seed);
    (0..STATES).flat_map(|_| model.random_q(&mut rng)).collect()
}

/// `STATES × n` values uniform in [−1, 1] (velocities, accelerations, torques).
pub fn random_unit_states(n: usize, seed: u64) -> Vec<f64> {
    use rand::Rng;
    let mut rng = SmallRng::seed_from_u64(seed);
    (0..STATES * n)
        .map(|_| rng.random_range(-1.0..1.0))
        .collect()
}

/// Median nanoseconds per call of `algo` over [`ROUNDS`] rounds of `iters / ROUNDS` calls.
pub fn ns_per_call(model: &Model, algo: Algo, iters: usize) -> f64 {
    if algo.is_batch() {
        return ns_per_batched_state(model, algo, iters);
    }
    let mut data = Data::new(model);
    let nv = model.nv;
    let qs = random_states(model, 0x5eed);
    let vs = random_unit_states(model.nv, 0x5eee);
    let ws = random_unit_states(model.nv, 0x5eef);
    let g = model.gravity;
    let run = |data: &mut Data, n: usize| {
        for k in 0..n {
            let s = (k % STATES) * nv..(k % STATES + 1) * nv;
            let q = black_box(&qs[s.clone()]);
            match algo {
                Algo::Fk => {
                    kinematics::forward_kinematics(model, data, q);
                    kinematics::update_frames(model, data);
                }
                Algo::Jacobians => kinematics::compute_joint_jacobians(model, data, q),
                Algo::Rnea => {
                    dynamics::rnea(model, data, q, &vs[s.clone()], &ws[s]);
                }
                Algo::RneaBatch | Algo::AbaBatch | Algo::CrbaBatch => {
                    unreachable!("timed by ns_per_batched_state")
                }
                Algo::Crba => {
                    dynamics::crba(model, data, q);
                }
                Algo::Aba => {
                    dynamics::aba(model, data, q, &vs[s.clone()], &ws[s]);
                }
                Algo::Lagrange => {
                    black_box(dynamics::lagrange_trace(
                        model,
                        data,
                        q,
                        &vs[s.clone()],
                        &ws[s],
                        &g,
                    ));
                }
            }
            black_box(&mut *data);
        }
    };
    let per_round = (iters / ROUNDS).max(1);
    median_ns(per_round, |n| run(&mut data, n))
}

/// Median nanoseconds per state of [`dynamics::rnea_rows`], [`dynamics::aba_rows`] or
/// [`dynamics::crba_rows`] over the [`STATES`] states (whole passes: at least one per
/// round).
fn ns_per_batched_state(model: &Model, algo: Algo, iters: usize) -> f64 {
    let qs = random_states(model, 0x5eed);
    let vs = random_unit_states(model.nv, 0x5eee);
    let ws = random_unit_states(model.nv, 0x5eef);
    let mut out = vec![0.0; qs.len()];
    let passes = (iters / ROUNDS).div_ceil(STATES).max(1);
    let per_pass = if algo == Algo::CrbaBatch {
        let mut lanes = dynamics::CrbaLanes::new(model);
        let mut mass = vec![0.0; qs.len() * model.nv];
        median_ns(passes, |n| {
            for _ in 0..n {
                dynamics::crba_rows(model, &mut lanes, black_box(&qs), &mut mass);
                black_box(&mut mass);
            }
        })
    } else if algo == Algo::AbaBatch {
        let mut lanes = dynamics::AbaLanes::new(model);
        median_ns(passes, |n| {
            for _ in 0..n {
                dynamics::aba_rows(model, &mut lanes, black_box(&qs), &vs, &ws, &mut out);
                black_box(&mut out);
            }
        })
    } else {
        let mut lanes = dynamics::RneaLanes::new(model);
        median_ns(passes, |n| {
            for _ in 0..n {
                dynamics::rnea_rows(model, &mut lanes, black_box(&qs), &vs, &ws, &mut out);
                black_box(&mut out);
            }
        })
    };
    per_pass / STATES as f64
}

/// Median over [`ROUNDS`] rounds of the time per unit of `run(units)`, after a warm-up.
fn median_ns(per_round: usize, mut run: impl FnMut(usize)) -> f64 {
    run(per_round.min(100_000));
    let mut times: Vec<f64> = (0..ROUNDS)
        .map(|_| {
            let t = Instant::now();
            run(per_round);
            t.elapsed().as_nanos() as f64 / per_round as f64
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[ROUNDS / 2]
}

/// The models the criterion benches time, loaded like Pinocchio loads them: UR5, Panda
/// (fingers as independent joints, 9 DOF), iiwa 14, the Panda with its mimic finger as
/// `panda_mimic` (8 DOF), and generated chains of the given lengths.
pub fn benchmark_models(chains: &[usize]) -> Vec<Model> {
    use crate::model::{chain, LoadOptions};
    let root = env!("CARGO_MANIFEST_DIR");
    let opts = LoadOptions {
        strict: false,
        ignore_mimic: true,
    };
    let mut v: Vec<Model> = ["ur5.urdf", "panda.urdf", "iiwa14.urdf"]
        .iter()
        .map(|f| {
            Model::load_with(format!("{root}/robots/{f}"), &opts)
                .expect("bundled robot loads")
                .0
        })
        .collect();
    let mut mimic = Model::load(format!("{root}/robots/panda.urdf"))
        .expect("bundled robot loads")
        .0;
    mimic.name = "panda_mimic".into();
    v.push(mimic);
    for &n in chains {
        v.push(
            Model::build(chain::chain_spec(n))
                .expect("generated chain")
                .0,
        );
    }
    v
}
