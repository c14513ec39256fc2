//! What an arm scenario's task asks of the planner, as validated: the `[planner]`
//! settings ([`PlannerSettings`]) and the part the tool grasps ([`Part`]).

use crate::planning::plan_options::{OptimiseBudget, PlannerKind};
use std::time::Duration;

/// `[planner]` settings, validated.
#[derive(Clone, Debug)]
pub struct PlannerSettings {
    /// Sampler and simplifier seed.
    pub seed: u64,
    /// Search time limit per planned segment.
    pub time_limit: Duration,
    /// Shortcut and smooth the paths.
    pub simplify: bool,
    /// Longest RRT-Connect step (joint-space distance).
    pub range: f64,
    /// Overshoot of the sphere cover (m).
    pub max_overshoot: f64,
    /// The SRDF's disabled pairs, when one is given (with its path for the report).
    pub srdf: Option<(String, Vec<(String, String)>)>,
    /// RRT-Connect or the optimising AORRTC.
    pub algorithm: PlannerKind,
    /// AORRTC's budget.
    pub budget: OptimiseBudget,
}

/// The grasped part: a box in the tool link's frame.
#[derive(Clone, Copy, Debug)]
pub struct Part {
    /// Edge lengths (m).
    pub size: [f64; 3],
    /// Centre in the tool frame (m).
    pub xyz: [f64; 3],
}
