//! [`PlanOptions`]: everything a planning query can be told (seed, time limit, sampler,
//! search, collision-check, simplification and sphere settings, the stop flag), shared by
//! the robot's set-up and the planner.

use crate::planning::checker::CheckOptions;
use crate::planning::rrt::RrtOptions;
use crate::planning::sampler::SamplerKind;
use crate::planning::simplify::SimplifyOptions;
use crate::planning::spheres::SphereOptions;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

/// Largest wall-clock limit of a search the front ends accept (ms): about 11.6 days.
pub const MAX_TIME_LIMIT_MS: f64 = 1e9;

/// The RRT-Connect step (`range`, joint-space distance) a caller may set: below 1e-3 the
/// step rounds towards 0 in single precision and the trees stop growing (1e-300 became 0).
pub const RANGE_LIMITS: (f64, f64) = (1e-3, 100.0);

/// Which search answers a query.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PlannerKind {
    /// RRT-Connect: the first path found, simplified.
    #[default]
    RrtConnect,
    /// AORRTC: RRT-Connect's first path, then searches for cheaper ones until the
    /// [`OptimiseBudget`] is spent ([`crate::planning::improve`]).
    Aorrtc,
}

impl PlannerKind {
    /// The name the front ends use (`rrt-connect`, `aorrtc`).
    pub fn name(self) -> &'static str {
        match self {
            PlannerKind::RrtConnect => "rrt-connect",
            PlannerKind::Aorrtc => "aorrtc",
        }
    }

    /// The planner of a front-end name; `None` for an unknown one.
    pub fn from_name(name: &str) -> Option<PlannerKind> {
        [PlannerKind::RrtConnect, PlannerKind::Aorrtc]
            .into_iter()
            .find(|k| k.name() == name)
    }
}

/// Default iterations of the optimising mode, first search included (the budget at which
/// VAMP's AORRTC is compared in BENCHMARKS.md).
pub const DEFAULT_OPTIMISE_ITERATIONS: usize = 2000;

/// Largest iteration budget the front ends accept.
pub const MAX_OPTIMISE_ITERATIONS: usize = 100_000_000;

/// How long the optimising mode keeps improving: whichever runs out first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OptimiseBudget {
    /// Search iterations, the first path's included.
    pub iterations: usize,
    /// Wall-clock time from the query's start.
    pub time: Option<Duration>,
}

impl Default for OptimiseBudget {
    fn default() -> Self {
        Self {
            iterations: DEFAULT_OPTIMISE_ITERATIONS,
            time: None,
        }
    }
}

/// Everything a query can be told.
#[derive(Clone, Debug)]
pub struct PlanOptions {
    /// Seed of the sampler and of the simplifier's random choices.
    pub seed: u64,
    /// The search: RRT-Connect, or the optimising AORRTC.
    pub planner: PlannerKind,
    /// The optimising mode's budget (unused by RRT-Connect).
    pub budget: OptimiseBudget,
    /// Wall-clock limit of the search (simplification is not counted).
    pub time_limit: Option<Duration>,
    /// Simplify the path.
    pub simplify: bool,
    /// Sample sequence.
    pub sampler: SamplerKind,
    /// Search settings.
    pub rrt: RrtOptions,
    /// Collision-check settings.
    pub check: CheckOptions,
    /// Simplification settings.
    pub simplifier: SimplifyOptions,
    /// Sphere generation settings.
    pub spheres: SphereOptions,
    /// Raised (by a Ctrl-C handler, another thread) to stop the set-up's sampling and the
    /// search; the query then fails with the reason "interrupted".
    pub stop: Option<Arc<AtomicBool>>,
    /// Random configurations of the allowed-collision matrix's *Never* pass, when no SRDF
    /// is given (MoveIt's Setup Assistant's default density, 10 000).
    pub acm_samples: usize,
    /// The most pair tests the matrix's sampling may run
    /// ([`crate::planning::acm::MAX_PAIR_TESTS`]); `None`: no limit.
    pub acm_max_pair_tests: Option<u64>,
}

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            seed: 0,
            planner: PlannerKind::RrtConnect,
            budget: OptimiseBudget::default(),
            time_limit: None,
            simplify: true,
            sampler: SamplerKind::Halton,
            rrt: RrtOptions::default(),
            check: CheckOptions::default(),
            simplifier: SimplifyOptions::default(),
            spheres: SphereOptions::default(),
            stop: None,
            acm_samples: 10_000,
            acm_max_pair_tests: Some(crate::planning::acm::MAX_PAIR_TESTS),
        }
    }
}
