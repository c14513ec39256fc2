//! The `[task]` section: the task type and its steps (joint or Cartesian waypoints, a
//! line, pick and place, a planned move, a sequence), poses moved into the robot's base
//! frame; the grasped part; and the `[planner]` settings when the task plans.

use crate::core::diag::{fmt_num, LocatedError as ScenarioError};
use crate::model::Model;
use crate::planning::plan_options::{
    OptimiseBudget, PlannerKind, MAX_OPTIMISE_ITERATIONS, MAX_TIME_LIMIT_MS, RANGE_LIMITS,
};
use crate::planning::spheres::OVERSHOOT_RANGE;
use crate::scenarios::arm::scene::arm_scene::{PlanQuery, QueryGoal, Step, TaskStep};
use crate::scenarios::arm::scene::limits::check_in_limits;
use crate::scenarios::arm::scene::section_reader::{
    finite_pos, finite_pose, per_joint, pose_of, to_radians_if, Sections,
};
use crate::scenarios::arm::schema::PerJoint;
use crate::scenarios::arm::schema::*;
use crate::scenarios::source::Source;
use std::ops::Range;
use std::path::Path;

/// The task's steps, and its type.
// One match over the six task types, each arm a short list of steps sharing the closures
// above it; splitting it would pass those closures around.
#[allow(clippy::too_many_lines)]
pub(super) fn steps(
    sx: &Sections,
    q0: &[f64],
    lower: &[f64],
    upper: &[f64],
) -> Result<Vec<TaskStep>, ScenarioError> {
    let cx = &sx.cx;
    let file = sx.file;
    let model = sx.model;
    let names = &sx.names;
    let base_inv = &sx.base_inv;
    let deg = |x: f64, k: usize, degrees: bool| to_radians_if(model, x, k, degrees);
    let tsec = file.task.get_ref();
    let tdeg = tsec.degrees;
    let joint_row = |v: &PerJoint, key: &str| -> Result<Vec<f64>, ScenarioError> {
        let raw = per_joint(cx, v, key, names, q0)?;
        let q: Vec<f64> = raw
            .iter()
            .enumerate()
            .map(|(k, x)| deg(*x, k, tdeg))
            .collect();
        check_in_limits(cx, v, key, names, &q, lower, upper)?;
        Ok(q)
    };
    let to_base = |p: &PoseSec| base_inv.mul(&pose_of(p));
    let kind = tsec.kind.get_ref().as_str();
    task_keys_apply(cx, file.task.span(), tsec)?;
    let need = |what: &str| {
        cx.at(
            file.task.span(),
            format!("task.{what}"),
            format!("task type '{kind}' needs task.{what}"),
        )
    };
    let mut steps = Vec::new();
    let push = |steps: &mut Vec<TaskStep>, step: Step, key: String, span: Range<usize>| {
        steps.push(TaskStep {
            step,
            key,
            line: Some(cx.line(&span)),
        })
    };
    let check_pose = |p: &PoseSec, key: &str, span: Range<usize>| -> Result<(), ScenarioError> {
        if finite_pose(p) {
            Ok(())
        } else {
            Err(cx.at(span, key, "pose is not finite"))
        }
    };
    match kind {
        "joint_waypoints" => {
            let w = tsec.waypoints.as_ref().ok_or_else(|| need("waypoints"))?;
            if w.get_ref().is_empty() {
                return Err(cx.at(w.span(), "task.waypoints", "no waypoints"));
            }
            too_many(cx, w.span(), "task.waypoints", w.get_ref().len())?;
            for (i, row) in w.get_ref().iter().enumerate() {
                let key = format!("task.waypoints[{i}]");
                let q = joint_row(row, &key)?;
                push(&mut steps, Step::Joint(q), key, row.span());
            }
        }
        "cartesian_waypoints" => {
            let w = tsec.poses.as_ref().ok_or_else(|| need("poses"))?;
            if w.get_ref().is_empty() {
                return Err(cx.at(w.span(), "task.poses", "no poses"));
            }
            too_many(cx, w.span(), "task.poses", w.get_ref().len())?;
            for (i, p) in w.get_ref().iter().enumerate() {
                let key = format!("task.poses[{i}]");
                check_pose(p, &key, w.span())?;
                push(&mut steps, Step::Pose(to_base(p)), key, w.span());
            }
        }
        "line" => {
            let g = tsec.goal.as_ref().ok_or_else(|| need("goal"))?;
            check_pose(g.get_ref(), "task.goal", g.span())?;
            push(&mut steps, Step::Line(to_base(g.get_ref())), "task.goal".into(), g.span());
        }
        "pick_and_place" => {
            let pick = tsec.pick.as_ref().ok_or_else(|| need("pick"))?;
            let place = tsec.place.as_ref().ok_or_else(|| need("place"))?;
            check_pose(pick.get_ref(), "task.pick", pick.span())?;
            check_pose(place.get_ref(), "task.place", place.span())?;
            let a = match &tsec.approach {
                None => 0.1,
                Some(s) if s.get_ref().is_finite() && *s.get_ref() >= 0.0 => *s.get_ref(),
                Some(s) => return Err(cx.at(s.span(), "task.approach", "must be finite and >= 0")),
            };
            let dwell = match &tsec.dwell {
                None => 0.3,
                Some(s) if s.get_ref().is_finite() && *s.get_ref() >= 0.0 => *s.get_ref(),
                Some(s) => return Err(cx.at(s.span(), "task.dwell", "must be finite and >= 0")),
            };
            let above = |p: &PoseSec| {
                let mut p = *p;
                p.xyz[2] += a;
                p
            };
            let planned = uses_planner(cx, tsec)?;
            for (label, p) in [("pick", pick), ("place", place)] {
                let key = format!("task.{label}");
                let approach = to_base(&above(p.get_ref()));
                let step = if planned { Step::Plan(Err(approach)) } else { Step::Pose(approach) };
                push(&mut steps, step, format!("{key} (approach)"), p.span());
                push(&mut steps, Step::Line(to_base(p.get_ref())), key.clone(), p.span());
                if dwell > 0.0 {
                    push(&mut steps, Step::Dwell(dwell), key.clone(), p.span());
                }
                let grip = if label == "pick" { Step::Attach } else { Step::Detach };
                push(&mut steps, grip, key.clone(), p.span());
                push(&mut steps, Step::Line(to_base(&above(p.get_ref()))), format!("{key} (retreat)"), p.span());
            }
            let back = if planned { Step::Plan(Ok(q0.to_vec())) } else { Step::Joint(q0.to_vec()) };
            push(&mut steps, back, "initial.q (return)".into(), pick.span());
        }
        "plan" => {
            let constraints = super::constraint_sections::path_constraints(sx)?;
            let target = match (&tsec.goal, &tsec.goal_q, &tsec.goal_pose) {
                (Some(g), None, None) => {
                    check_pose(g.get_ref(), "task.goal", g.span())?;
                    QueryGoal::IkPose(to_base(g.get_ref()))
                }
                (None, Some(j), None) => QueryGoal::Joints(joint_row(j, "task.goal_q")?),
                (None, None, Some(g)) => {
                    check_pose(g.get_ref(), "task.goal_pose", g.span())?;
                    QueryGoal::Pose(to_base(g.get_ref()))
                }
                _ => {
                    return Err(cx.at(
                        file.task.span(),
                        "task.goal",
                        "task type 'plan' needs exactly one of task.goal (a tool pose reached through IK from the current configuration), task.goal_pose (a tool pose reached through any IK solution) and task.goal_q (joint values)",
                    ))
                }
            };
            let step = match target {
                QueryGoal::Joints(q) if constraints.is_empty() => Step::Plan(Ok(q)),
                QueryGoal::IkPose(p) if constraints.is_empty() => Step::Plan(Err(p)),
                goal => Step::PlanTo(Box::new(PlanQuery { goal, constraints })),
            };
            push(&mut steps, step, "task.goal".into(), file.task.span());
        }
        "sequence" => {
            let list = tsec.steps.as_ref().ok_or_else(|| need("steps"))?;
            if list.get_ref().is_empty() {
                return Err(cx.at(list.span(), "task.steps", "no steps"));
            }
            too_many(cx, list.span(), "task.steps", list.get_ref().len())?;
            for (i, s) in list.get_ref().iter().enumerate() {
                let key = format!("task.steps[{i}]");
                let st = s.get_ref();
                let count = [st.joint.is_some(), st.pose.is_some(), st.line.is_some(), st.dwell.is_some()]
                    .iter()
                    .filter(|b| **b)
                    .count();
                if count != 1 {
                    return Err(cx.at(
                        s.span(),
                        &key,
                        "each step has exactly one of joint, pose, line, dwell",
                    ));
                }
                let step = if let Some(j) = &st.joint {
                    Step::Joint(joint_row(j, &format!("{key}.joint"))?)
                } else if let Some(p) = &st.pose {
                    check_pose(p, &key, s.span())?;
                    Step::Pose(to_base(p))
                } else if let Some(p) = &st.line {
                    check_pose(p, &key, s.span())?;
                    Step::Line(to_base(p))
                } else {
                    let d = st.dwell.expect("counted");
                    if !(d.is_finite() && d > 0.0) {
                        return Err(cx.at(s.span(), format!("{key}.dwell"), "must be positive"));
                    }
                    Step::Dwell(d)
                };
                push(&mut steps, step, key, s.span());
            }
        }
        other => {
            return Err(cx.at(
                file.task.get_ref().kind.span(),
                "task.type",
                format!(
                    "unknown task type '{other}' (expected joint_waypoints, cartesian_waypoints, line, pick_and_place, plan or sequence)"
                ),
            ))
        }
    }
    Ok(steps)
}

/// Largest side of a grasped part and farthest its centre may lie from the tool (m): the
/// planner covers it with spheres like a link, so its size sets the set-up's work.
pub const MAX_PART: f64 = 2.0;

/// The grasped part (only for pick and place).
pub(super) fn part(
    sx: &Sections,
) -> Result<Option<crate::scenarios::arm::planner_settings::Part>, ScenarioError> {
    let cx = &sx.cx;
    let tsec = sx.file.task.get_ref();
    let kind = tsec.kind.get_ref().as_str();
    let part = match &tsec.part {
        None => None,
        Some(p) => {
            let v = p.get_ref();
            if kind != "pick_and_place" {
                return Err(cx.at(
                    p.span(),
                    "task.part",
                    "only a pick_and_place task grasps a part",
                ));
            }
            let size_ok = v.size.iter().all(|x| finite_pos(*x) && *x <= MAX_PART);
            if !(size_ok && v.xyz.iter().all(|x| x.is_finite() && x.abs() <= MAX_PART)) {
                return Err(cx.at(
                    p.span(),
                    "task.part",
                    format!(
                        "size must be positive and xyz finite, each within {MAX_PART} m \
                         (a part the tool carries; got size {:?}, xyz {:?})",
                        v.size, v.xyz
                    ),
                ));
            }
            Some(crate::scenarios::arm::planner_settings::Part {
                size: v.size,
                xyz: v.xyz,
            })
        }
    };
    Ok(part)
}

/// The `[planner]` settings when the task plans (the table is refused otherwise).
pub(super) fn planner_settings(
    cx: &Source,
    file: &ArmFile,
    dir: &Path,
    model: &Model,
    plans: bool,
    warnings: &mut Vec<String>,
) -> Result<Option<crate::scenarios::arm::planner_settings::PlannerSettings>, ScenarioError> {
    let sec = file.planner.as_ref();
    if !plans {
        return match sec {
            Some(s) => Err(cx.at(
                s.span(),
                "planner",
                "the task plans nothing (use task type 'plan' or task.planner = \"rrt-connect\")",
            )),
            None => Ok(None),
        };
    }
    let p = sec.map(|s| s.get_ref());
    let ms = match p.and_then(|p| p.time_limit_ms.as_ref()) {
        None => 1000.0,
        Some(t) if finite_pos(*t.get_ref()) && *t.get_ref() <= MAX_TIME_LIMIT_MS => *t.get_ref(),
        Some(t) => {
            let msg = format!(
                "must be positive and at most {MAX_TIME_LIMIT_MS:e} ms, got {}",
                fmt_num(*t.get_ref())
            );
            return Err(cx.at(t.span(), "planner.time_limit_ms", msg));
        }
    };
    let (lo, hi) = OVERSHOOT_RANGE;
    let max_overshoot = match p.and_then(|p| p.max_overshoot.as_ref()) {
        None => 0.01,
        Some(t) if (lo..=hi).contains(t.get_ref()) => *t.get_ref(),
        Some(t) => {
            let msg = format!("must lie in {lo} … {hi} m, got {}", fmt_num(*t.get_ref()));
            return Err(cx.at(t.span(), "planner.max_overshoot", msg));
        }
    };
    let range = match p.and_then(|p| p.range.as_ref()) {
        None => 1.0,
        Some(t) if (RANGE_LIMITS.0..=RANGE_LIMITS.1).contains(t.get_ref()) => *t.get_ref(),
        Some(t) => {
            return Err(cx.at(
                t.span(),
                "planner.range",
                format!(
                    "must be a joint-space distance in {} … {}, got {}",
                    RANGE_LIMITS.0,
                    RANGE_LIMITS.1,
                    fmt_num(*t.get_ref())
                ),
            ))
        }
    };
    let srdf = match p.and_then(|p| p.srdf.as_ref()) {
        None => None,
        Some(f) => {
            let path = dir.join(f.get_ref());
            let (pairs, w) = crate::planning::srdf::load_disabled_pairs(&path, model)
                .map_err(|e| cx.at(f.span(), "planner.srdf", e.to_string()))?;
            warnings.extend(w.iter().map(|w| format!("{w}")));
            Some((path.display().to_string(), pairs))
        }
    };
    let (algorithm, budget) = planner_algorithm(cx, p)?;
    Ok(Some(
        crate::scenarios::arm::planner_settings::PlannerSettings {
            seed: p.and_then(|p| p.seed).unwrap_or(0),
            time_limit: std::time::Duration::from_secs_f64(ms / 1e3),
            simplify: p.and_then(|p| p.simplify).unwrap_or(true),
            range,
            max_overshoot,
            srdf,
            algorithm,
            budget,
        },
    ))
}

/// `[planner] algorithm`, `budget_iterations` and `budget_ms` (the budget is refused with
/// RRT-Connect, which stops at its first path).
fn planner_algorithm(
    cx: &Source,
    p: Option<&PlannerSec>,
) -> Result<(PlannerKind, OptimiseBudget), ScenarioError> {
    let mut budget = OptimiseBudget::default();
    let algorithm = match p.and_then(|p| p.algorithm.as_ref()) {
        None => PlannerKind::RrtConnect,
        Some(a) => PlannerKind::from_name(a.get_ref()).ok_or_else(|| {
            let msg = format!(
                "expected \"rrt-connect\" or \"aorrtc\", got {:?}",
                a.get_ref()
            );
            cx.at(a.span(), "planner.algorithm", msg)
        })?,
    };
    let Some(p) = p else {
        return Ok((algorithm, budget));
    };
    if algorithm == PlannerKind::RrtConnect {
        let given = [
            (
                "planner.budget_iterations",
                p.budget_iterations.as_ref().map(|b| b.span()),
            ),
            ("planner.budget_ms", p.budget_ms.as_ref().map(|b| b.span())),
        ];
        if let Some((key, Some(span))) = given.into_iter().find(|(_, s)| s.is_some()) {
            let msg = "applies to algorithm = \"aorrtc\" (RRT-Connect stops at its first path)";
            return Err(cx.at(span, key, msg));
        }
    }
    if let Some(n) = &p.budget_iterations {
        let v = *n.get_ref();
        if v < 1 || v as u64 > MAX_OPTIMISE_ITERATIONS as u64 {
            let msg = format!("must lie in 1 … {MAX_OPTIMISE_ITERATIONS}, got {v}");
            return Err(cx.at(n.span(), "planner.budget_iterations", msg));
        }
        budget.iterations = v as usize;
    }
    if let Some(t) = &p.budget_ms {
        let v = *t.get_ref();
        if !(finite_pos(v) && v <= MAX_TIME_LIMIT_MS) {
            let msg = format!(
                "must be positive and at most {MAX_TIME_LIMIT_MS:e} ms, got {}",
                fmt_num(v)
            );
            return Err(cx.at(t.span(), "planner.budget_ms", msg));
        }
        budget.time = Some(std::time::Duration::from_secs_f64(v / 1e3));
    }
    Ok((algorithm, budget))
}

/// Refuses `[planner] algorithm = "aorrtc"` with a `task.goal_pose` or
/// `task.path_constraints` (the optimiser plans to joint goals without constraints, as
/// `armsim plan` refuses it with such MoveIt requests).
pub(super) fn optimiser_applies(
    cx: &Source,
    file: &ArmFile,
    queries: bool,
) -> Result<(), ScenarioError> {
    let algorithm = file
        .planner
        .as_ref()
        .and_then(|p| p.get_ref().algorithm.as_ref());
    match algorithm {
        Some(a) if queries && a.get_ref() == "aorrtc" => Err(cx.at(
            a.span(),
            "planner.algorithm",
            "\"aorrtc\" plans to joint goals without path constraints; this task has \
             task.goal_pose or task.path_constraints (use \"rrt-connect\")",
        )),
        _ => Ok(()),
    }
}

/// Whether a pick-and-place plans its transfers (`task.planner`).
fn uses_planner(cx: &Source, tsec: &TaskSec) -> Result<bool, ScenarioError> {
    match &tsec.planner {
        None => Ok(false),
        Some(p) => match p.get_ref().as_str() {
            "rrt-connect" => Ok(true),
            "none" => Ok(false),
            other => Err(cx.at(
                p.span(),
                "task.planner",
                format!("unknown planner '{other}' (expected rrt-connect or none)"),
            )),
        },
    }
}

/// The `[task]` keys each task type reads (besides `type`); an unknown type is reported
/// with its list where it is matched.
const TASK_KEYS: &[(&str, &[&str])] = &[
    ("joint_waypoints", &["waypoints", "degrees"]),
    ("cartesian_waypoints", &["poses", "position_only"]),
    ("line", &["goal", "position_only"]),
    (
        "pick_and_place",
        &[
            "pick",
            "place",
            "approach",
            "dwell",
            "part",
            "planner",
            "position_only",
        ],
    ),
    (
        "plan",
        &[
            "goal",
            "goal_q",
            "goal_pose",
            "path_constraints",
            "degrees",
            "position_only",
        ],
    ),
    ("sequence", &["steps", "degrees", "position_only"]),
];

/// Refuses a `[task]` key its type does not read (it was silently ignored), as a misspelt
/// key is refused.
fn task_keys_apply(cx: &Source, span: Range<usize>, t: &TaskSec) -> Result<(), ScenarioError> {
    let kind = t.kind.get_ref().as_str();
    let Some((_, keys)) = TASK_KEYS.iter().find(|(k, _)| *k == kind) else {
        return Ok(());
    };
    let written = [
        ("waypoints", t.waypoints.is_some()),
        ("poses", t.poses.is_some()),
        ("goal", t.goal.is_some()),
        ("goal_q", t.goal_q.is_some()),
        ("goal_pose", t.goal_pose.is_some()),
        ("path_constraints", t.path_constraints.is_some()),
        ("planner", t.planner.is_some()),
        ("part", t.part.is_some()),
        ("pick", t.pick.is_some()),
        ("place", t.place.is_some()),
        ("approach", t.approach.is_some()),
        ("dwell", t.dwell.is_some()),
        ("steps", t.steps.is_some()),
        ("degrees", t.degrees),
        ("position_only", t.position_only.is_some()),
    ];
    match written.iter().find(|(k, w)| *w && !keys.contains(k)) {
        Some((k, _)) => Err(cx.err(
            cx.key_line(&span, k),
            format!("task.{k}"),
            format!(
                "does not apply to a '{kind}' task (it reads {})",
                keys.join(", ")
            ),
        )),
        None => Ok(()),
    }
}

/// Most waypoints, poses or steps one task lists: each becomes a timed segment, planned,
/// checked and simulated (10⁵ waypoints took 22 s to be refused by the step budget, with
/// every one named).
pub const MAX_TASK_STEPS: usize = 10_000;

fn too_many(cx: &Source, span: Range<usize>, key: &str, n: usize) -> Result<(), ScenarioError> {
    if n > MAX_TASK_STEPS {
        return Err(cx.at(
            span,
            key,
            format!("{n} entries: more than the {MAX_TASK_STEPS} one task accepts"),
        ));
    }
    Ok(())
}
