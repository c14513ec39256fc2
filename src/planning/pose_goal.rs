//! Goals given as a tool pose: the goal set of inverse-kinematics solutions the planner
//! searches to ([`goal_set`]), and the [`Goal`] of a query (joint values or a pose).
//!
//! **The goal set.** When the model has a closed form for the link
//! ([`crate::kinematics::ik::analytic`]: UR arms, Puma-like and Stanford-like wrists) every
//! branch inside the joint limits is a goal, each joint brought by multiples of 2π to the
//! value nearest the start. Otherwise the numeric solver
//! ([`crate::kinematics::ik::IkSolver`], Levenberg–Marquardt with restarts) is run from the
//! start (8 restarts) and then from [`NUMERIC_ATTEMPTS`]` − 1` configurations drawn from
//! the joint box with the query's seed ([`ATTEMPT_RESTARTS`] each; when none converges,
//! as many new draws with 8 restarts each); its converged answers, with duplicates (all
//! joints within 1e-3 rad) dropped, are the goals. The numeric solver runs on iteration
//! and restart counts only (no wall-clock budget), so a seed gives the same set
//! anywhere. Every goal is checked by forward kinematics to [`GOAL_TOLERANCE`] in
//! position and rotation. When the planner finds the whole set invalid, [`more_goals`]
//! draws further rounds.
//!
//! An empty set is an error that says why: the closed form's reason (out of reach), every
//! solution outside the limits, or the numeric solver's closest pose.

use crate::core::spatial::Se3;
use crate::kinematics::ik::analytic::{AnalyticOptions, AnalyticSolver, IkError};
use crate::kinematics::ik::{rotation_log, IkOptions, IkSolver, IkStatus};
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::model::data::Data;
use crate::model::Model;
use crate::planning::sampler::{bounds, uniform, Rng};
use std::time::Duration;

/// Numeric IK attempts (each with its own restarts) for a goal set.
pub const NUMERIC_ATTEMPTS: usize = 12;

/// Restarts of each numeric attempt after the first (which has 8): the later attempts
/// only add variety to the set, and one whose draw needs many restarts costs more than
/// the goal it might add (on the Panda, 12 attempts with 8 restarts each took 3 ms).
pub const ATTEMPT_RESTARTS: usize = 1;

/// Half-width (rad) per round of the IK starts drawn around the start ([`more_goals`]).
pub const NEAR_START_SPREAD: f64 = 0.3;

/// Largest position (m) and rotation (rad) error of a goal of the set.
pub const GOAL_TOLERANCE: f64 = 1e-9;

/// A tool pose to reach.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseGoal {
    /// The link (index into [`Model::links`]).
    pub link: usize,
    /// The pose of the link's frame in the world (its rotation is ignored when
    /// `position_only`).
    pub target: Se3,
    /// Reach the position only, in any orientation.
    pub position_only: bool,
}

/// What a query plans to.
#[derive(Clone, Debug, PartialEq)]
pub enum Goal {
    /// Joint values (model order).
    Joints(Vec<f64>),
    /// A tool pose: any of its inverse-kinematics solutions.
    Pose(PoseGoal),
}

/// Position and rotation error of `q` against the goal.
pub fn pose_error(model: &Model, data: &mut Data, goal: &PoseGoal, q: &[f64]) -> (f64, f64) {
    forward_kinematics(model, data, q);
    let t = frame_placement(model, data, goal.link);
    let ep = (t.trans - goal.target.trans).norm();
    let er = if goal.position_only {
        0.0
    } else {
        rotation_log(&(goal.target.rot * t.rot.transpose())).norm()
    };
    (ep, er)
}

/// The inverse-kinematics solutions of `goal` (module docs), nearest the start first, or
/// why there are none.
pub fn goal_set(
    model: &Model,
    goal: &PoseGoal,
    start: &[f64],
    seed: u64,
) -> Result<Vec<Vec<f64>>, String> {
    if goal.link >= model.links.len() {
        return Err(format!("link index {} is not in the model", goal.link));
    }
    let finite = goal
        .target
        .trans
        .iter()
        .chain(goal.target.rot.iter())
        .all(|x| x.is_finite());
    if !finite {
        return Err("the goal pose is not finite".into());
    }
    let analytic = (!goal.position_only)
        .then(|| AnalyticSolver::new(model, goal.link).ok())
        .flatten();
    let set = match analytic {
        Some(solver) => {
            let opts = AnalyticOptions {
                seed: Some(start.to_vec()),
                respect_limits: true,
            };
            match solver.solve(&goal.target, &opts) {
                Ok(sols) => sols.into_iter().map(|s| s.q).collect(),
                Err(IkError::Unreachable(why)) => return Err(format!("unreachable: {why}")),
                Err(IkError::OutsideLimits { candidates }) => {
                    return Err(format!(
                        "unreachable within the joint limits: all {candidates} inverse-kinematics solutions are outside them"
                    ))
                }
                Err(e) => return Err(e.to_string()),
            }
        }
        None => numeric_set(model, goal, start, seed)?,
    };
    let set = checked_nearest_first(model, goal, start, set);
    if set.is_empty() {
        return Err("no inverse-kinematics solution reaches the pose to 1e-9".into());
    }
    Ok(set)
}

/// The solutions of `set` that reach the goal to [`GOAL_TOLERANCE`], nearest `start`
/// first.
fn checked_nearest_first(
    model: &Model,
    goal: &PoseGoal,
    start: &[f64],
    mut set: Vec<Vec<f64>>,
) -> Vec<Vec<f64>> {
    let mut data = Data::new(model);
    set.retain(|q| {
        let (ep, er) = pose_error(model, &mut data, goal, q);
        ep <= GOAL_TOLERANCE && er <= GOAL_TOLERANCE
    });
    let d = |q: &Vec<f64>| {
        q.iter()
            .zip(start)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
    };
    set.sort_by(|a, b| d(a).total_cmp(&d(b)));
    set
}

/// The numeric solver's distinct converged solutions over [`NUMERIC_ATTEMPTS`] starts.
fn numeric_set(
    model: &Model,
    goal: &PoseGoal,
    start: &[f64],
    seed: u64,
) -> Result<Vec<Vec<f64>>, String> {
    let mut solver = IkSolver::new(model);
    let mut rng = Rng::new(seed ^ 0x9e37_79b9_7f4a_7c15);
    let mut q0 = start.to_vec();
    let mut set: Vec<Vec<f64>> = Vec::new();
    let mut closest: Option<(IkStatus, f64, f64)> = None;
    // Round one: the start with 8 restarts, the draws with ATTEMPT_RESTARTS. Only when it
    // finds nothing, round two: new draws with 8 restarts each (as many tries as ever).
    let mut attempts = 0;
    for attempt in 0..2 * NUMERIC_ATTEMPTS {
        if attempt == NUMERIC_ATTEMPTS && !set.is_empty() {
            break;
        }
        if attempt > 0 {
            uniform(model, &mut rng, &mut q0);
        }
        let hard = attempt == 0 || attempt >= NUMERIC_ATTEMPTS;
        let restarts = if hard { 8 } else { ATTEMPT_RESTARTS };
        attempts += 1;
        let r = attempt_ik(&mut solver, model, goal, &q0, restarts, seed, attempt);
        if r.status == IkStatus::Converged {
            add_distinct(&mut set, r.q);
        } else if closest.is_none_or(|c| r.position_error < c.1) {
            closest = Some((r.status, r.position_error, r.rotation_error));
        }
    }
    if set.is_empty() {
        let (status, ep, er) = closest.unwrap_or((IkStatus::Unreachable, f64::NAN, f64::NAN));
        let what = if status == IkStatus::Unreachable {
            "unreachable"
        } else {
            "no inverse-kinematics solution found"
        };
        return Err(format!(
            "{what}: over {attempts} numeric IK attempts the closest pose is {:.2} mm and {:.4} rad away",
            ep * 1e3,
            er
        ));
    }
    Ok(set)
}

/// One numeric IK run from `q0` to the goal, to 1e-10, on counts only (deterministic).
fn attempt_ik(
    solver: &mut IkSolver,
    model: &Model,
    goal: &PoseGoal,
    q0: &[f64],
    max_restarts: usize,
    seed: u64,
    attempt: usize,
) -> crate::kinematics::ik::IkResult {
    let opts = IkOptions {
        position_only: goal.position_only,
        tol_position: 1e-10,
        tol_rotation: 1e-10,
        max_restarts,
        time_budget: Duration::from_secs(3600),
        seed: seed.wrapping_add(attempt as u64),
        ..IkOptions::default()
    };
    solver.solve(model, goal.link, &goal.target, Some(q0), &opts)
}

/// Adds `q` unless a solution within 1e-3 rad in every joint is in `set` already.
fn add_distinct(set: &mut Vec<Vec<f64>>, q: Vec<f64>) {
    if set
        .iter()
        .all(|s| s.iter().zip(&q).any(|(a, b)| (a - b).abs() > 1e-3))
    {
        set.push(q);
    }
}

/// More goals for a redundant arm whose goal set was all invalid (in collision, say):
/// round `round ≥ 1` of [`NUMERIC_ATTEMPTS`] fresh starts ([`ATTEMPT_RESTARTS`] each),
/// half drawn from the joint box and half within `round ·` [`NEAR_START_SPREAD`] rad of
/// the start in each joint (the start's posture is free, and so, often, is a goal that
/// keeps it: MoveIt seeds its IK from the current state), checked to
/// [`GOAL_TOLERANCE`], nearest `start` first. A closed-form set is already complete:
/// nothing more.
pub fn more_goals(
    model: &Model,
    goal: &PoseGoal,
    start: &[f64],
    seed: u64,
    round: usize,
) -> Vec<Vec<f64>> {
    let analytic = !goal.position_only && AnalyticSolver::new(model, goal.link).is_ok();
    if analytic || goal.link >= model.links.len() {
        return Vec::new();
    }
    let mut solver = IkSolver::new(model);
    let round_seed = seed ^ (round as u64).wrapping_mul(0xd1b5_4a32_d192_ed03);
    let mut rng = Rng::new(round_seed ^ 0x9e37_79b9_7f4a_7c15);
    let mut q0 = start.to_vec();
    let mut set = Vec::new();
    let spread = NEAR_START_SPREAD * round as f64;
    for attempt in 0..NUMERIC_ATTEMPTS {
        if attempt % 2 == 0 {
            uniform(model, &mut rng, &mut q0);
        } else {
            near(model, &mut rng, start, spread, &mut q0);
        }
        let r = attempt_ik(
            &mut solver,
            model,
            goal,
            &q0,
            ATTEMPT_RESTARTS,
            round_seed,
            attempt,
        );
        if r.status == IkStatus::Converged {
            add_distinct(&mut set, r.q);
        }
    }
    checked_nearest_first(model, goal, start, set)
}

/// `q = start + u`, each `u_k` uniform in `[−spread, spread]`, clamped to the sampling
/// range.
fn near(model: &Model, rng: &mut Rng, start: &[f64], spread: f64, q: &mut [f64]) {
    for (k, (x, s)) in q.iter_mut().zip(start).enumerate() {
        let (lo, hi) = bounds(model, k);
        *x = (s + spread * (2.0 * rng.next_f64() - 1.0)).clamp(lo, hi);
    }
}
