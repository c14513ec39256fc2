//! MoveIt `MotionPlanRequest` YAML → start and goal joint values in the model's coordinate
//! order.
//!
//! Read: `start_state.joint_state` (`name` and `position` lists of equal length) and
//! `goal_constraints[0].joint_constraints[]` (`joint_name`, `position`; tolerances and
//! weights are ignored), plus `group_name`, `planner_id` and `allowed_planning_time` when
//! present. Joints are matched to the model by name:
//! - a name the model does not have is an error (wrong robot);
//! - a joint the model has but does not move (a fixed finger joint of a spherized model, a
//!   mimic joint) is a warning, and its value is ignored;
//! - a coordinate of the model missing from the start or from the goal is an error naming
//!   every missing joint.
//!
//! A start state whose `multi_dof_joint_state` moves the base (MoveIt's virtual joint, not
//! the identity) is refused: armsim's world is the model's root frame.
//!
//! A goal of position and orientation constraints is a tool pose ([`Request::goal_pose`]),
//! and `path_constraints` are read too ([`Request::path_constraints`]); see
//! `pose_constraints.rs` for what is supported. Visibility constraints are refused; goal
//! constraints after the first (MoveIt's alternative goals) are ignored with a warning.

use crate::model::Model;
use crate::planning::moveit::pose_constraints::{goal_pose, path_constraints};
use crate::planning::moveit::scene::components;
use crate::planning::moveit::yaml::{Doc, Node};
use crate::planning::path_constraints::PathConstraint;
use crate::planning::plan_error::{PlanningInputError, PlanningInputWarning};
use crate::planning::pose_goal::PoseGoal;

/// A motion planning problem for one model: start and goal joint values, in the model's
/// coordinate order ([`Model::dof_names`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    /// Coordinate names, in model order (`start` and `goal` follow it).
    pub joints: Vec<String>,
    /// Start configuration.
    pub start: Vec<f64>,
    /// Goal configuration (empty when the goal is a pose, [`Request::goal_pose`]).
    pub goal: Vec<f64>,
    /// The tool pose to reach, when the goal is given by position and orientation
    /// constraints.
    pub goal_pose: Option<PoseGoal>,
    /// Constraints the whole path keeps (`path_constraints`).
    pub path_constraints: Vec<PathConstraint>,
    /// MoveIt planning group (`group_name`), if given.
    pub group: Option<String>,
    /// MoveIt planner id (`planner_id`), if given.
    pub planner_id: Option<String>,
    /// Time budget the request asks for (`allowed_planning_time`, s), if given.
    pub allowed_planning_time: Option<f64>,
}

/// Values by coordinate while reading: where each one was set (for duplicates).
struct Slots<'a> {
    doc: &'a Doc<'a>,
    model: &'a Model,
    values: Vec<Option<f64>>,
    lines: Vec<usize>,
    warnings: &'a mut Vec<PlanningInputWarning>,
}

impl Slots<'_> {
    /// Sets joint `name` (from node `at`) to `value`.
    fn set(
        &mut self,
        node: &Node,
        at: &str,
        name: &str,
        value: f64,
    ) -> Result<(), PlanningInputError> {
        let Some(j) = self.model.joint_id(name) else {
            return Err(self.doc.err(
                node,
                at,
                format!(
                    "joint '{name}' is not in model '{}' (its coordinates: {})",
                    self.model.name,
                    self.model.dof_names().join(", ")
                ),
            ));
        };
        let joint = &self.model.joints[j];
        let Some(k) = joint.dof else {
            let why = if joint.mimic.is_some() {
                "a mimic joint"
            } else {
                "not movable in the model (fixed)"
            };
            self.warnings.push(self.doc.err(
                node,
                at,
                format!("joint '{name}' is {why}: its value {value} is ignored"),
            ));
            return Ok(());
        };
        let line = node.span.start.line();
        if self.values[k].is_some() {
            return Err(self.doc.err(
                node,
                at,
                format!(
                    "joint '{name}' is given twice (first on line {})",
                    self.lines[k]
                ),
            ));
        }
        self.values[k] = Some(value);
        self.lines[k] = line;
        Ok(())
    }

    /// The values in model order, or an error at `node` naming the missing joints.
    fn finish(self, node: &Node, at: &str) -> Result<Vec<f64>, PlanningInputError> {
        let missing: Vec<String> = (0..self.values.len())
            .filter(|&k| self.values[k].is_none())
            .map(|k| format!("'{}'", self.model.dof_joint(k).name))
            .collect();
        if !missing.is_empty() {
            return Err(self.doc.err(
                node,
                at,
                format!(
                    "no value for joint(s) {} of model '{}'",
                    missing.join(", "),
                    self.model.name
                ),
            ));
        }
        Ok(self.values.into_iter().map(|v| v.unwrap_or(0.0)).collect())
    }
}

/// Parses MotionPlanRequest text read from `file` (used in messages) for `model`.
/// Returns the request and the warnings.
pub fn parse_request(
    text: &str,
    file: &str,
    model: &Model,
) -> Result<(Request, Vec<PlanningInputWarning>), PlanningInputError> {
    let (doc, root) = Doc::parse(text, file)?;
    let mut warnings = Vec::new();
    let start = start_state(&doc, &root, model, &mut warnings)?;
    let (goal, goal_pose) = goal(&doc, &root, model, &mut warnings)?;
    let path_constraints = path_constraints(&doc, &root, model, &mut warnings)?;
    let opt_str = |key: &str| -> Result<Option<String>, PlanningInputError> {
        doc.get(&root, key)
            .map(|n| doc.str(n, key).map(str::to_string))
            .transpose()
    };
    let allowed_planning_time = doc
        .get(&root, "allowed_planning_time")
        .map(|n| doc.num(n, "allowed_planning_time"))
        .transpose()?;
    Ok((
        Request {
            joints: model.dof_names(),
            start,
            goal,
            goal_pose,
            path_constraints,
            group: opt_str("group_name")?,
            planner_id: opt_str("planner_id")?,
            allowed_planning_time,
        },
        warnings,
    ))
}

fn slots<'a>(
    doc: &'a Doc<'a>,
    model: &'a Model,
    warnings: &'a mut Vec<PlanningInputWarning>,
) -> Slots<'a> {
    Slots {
        doc,
        model,
        values: vec![None; model.nv],
        lines: vec![0; model.nv],
        warnings,
    }
}

fn start_state(
    doc: &Doc<'_>,
    root: &Node,
    model: &Model,
    warnings: &mut Vec<PlanningInputWarning>,
) -> Result<Vec<f64>, PlanningInputError> {
    let at = "start_state.joint_state";
    let js = doc
        .get(root, "start_state")
        .map(|s| doc.map(s, "start_state"))
        .transpose()?
        .and_then(|s| doc.get(s, "joint_state"))
        .ok_or_else(|| {
            doc.err(
                root,
                at,
                "missing: armsim needs the start joint values (it has no current state)",
            )
        })?;
    doc.map(js, at)?;
    if let Some(state) = doc.get(root, "start_state") {
        fixed_base(doc, state)?;
    }
    let names_node = doc.req(js, at, "name")?;
    let names = doc.seq(names_node, &format!("{at}.name"))?;
    let pos_node = doc.req(js, at, "position")?;
    let positions = doc.seq(pos_node, &format!("{at}.position"))?;
    if names.len() != positions.len() {
        return Err(doc.err(
            pos_node,
            format!("{at}.position"),
            format!(
                "{} position(s) for {} joint name(s)",
                positions.len(),
                names.len()
            ),
        ));
    }
    let mut s = slots(doc, model, warnings);
    for (i, (n, p)) in names.iter().zip(positions).enumerate() {
        let name = doc.str(n, &format!("{at}.name[{i}]"))?;
        let value = doc.num(p, &format!("{at}.position[{i}] ('{name}')"))?;
        s.set(n, &format!("{at}.name[{i}]"), name, value)?;
    }
    s.finish(js, at)
}

/// `start_state.multi_dof_joint_state.transforms[]` (MoveIt's virtual joint between the
/// world and the robot's root) must be the identity: armsim's world is the model's root.
fn fixed_base(doc: &Doc<'_>, state: &Node) -> Result<(), PlanningInputError> {
    let Some(md) = doc.get(state, "multi_dof_joint_state") else {
        return Ok(());
    };
    let at = "start_state.multi_dof_joint_state";
    doc.map(md, at)?;
    for (i, t) in doc.opt_seq(md, at, "transforms")?.iter().enumerate() {
        let tat = format!("{at}.transforms[{i}]");
        doc.map(t, &tat)?;
        let p = match doc.get(t, "translation") {
            Some(n) => components(doc, n, &format!("{tat}.translation"), ["x", "y", "z"])?,
            None => [0.0; 3],
        };
        let q = match doc.get(t, "rotation") {
            Some(n) => components(doc, n, &format!("{tat}.rotation"), ["x", "y", "z", "w"])?,
            None => [0.0, 0.0, 0.0, 1.0],
        };
        let identity = p.iter().chain(&q[..3]).all(|c| c.abs() < 1e-12) && q[3] != 0.0;
        if !identity {
            return Err(doc.err(
                t,
                tat,
                "a moved base (translation or rotation not the identity) is not supported: the model's root is the world",
            ));
        }
    }
    Ok(())
}

fn goal(
    doc: &Doc<'_>,
    root: &Node,
    model: &Model,
    warnings: &mut Vec<PlanningInputWarning>,
) -> Result<(Vec<f64>, Option<PoseGoal>), PlanningInputError> {
    let gc_node = doc.req(root, "request", "goal_constraints")?;
    let gcs = doc.seq(gc_node, "goal_constraints")?;
    let Some(g) = gcs.first() else {
        return Err(doc.err(gc_node, "goal_constraints", "empty: no goal"));
    };
    if let Some(extra) = gcs.get(1) {
        warnings.push(doc.err(
            extra,
            "goal_constraints[1]",
            format!(
                "{} goal constraints: only the first is used (armsim plans to one goal)",
                gcs.len()
            ),
        ));
    }
    let at = "goal_constraints[0]";
    doc.map(g, at)?;
    if let Some(c) = doc.opt_seq(g, at, "visibility_constraints")?.first() {
        return Err(doc.err(
            c,
            format!("{at}.visibility_constraints[0]"),
            "visibility constraints are not supported (joint values or a tool pose are)",
        ));
    }
    if let Some(pose) = goal_pose(doc, g, at, model)? {
        if let Some(j) = doc.opt_seq(g, at, "joint_constraints")?.first() {
            return Err(doc.err(
                j,
                format!("{at}.joint_constraints[0]"),
                "a goal of joint values and a tool pose together is not supported",
            ));
        }
        return Ok((Vec::new(), Some(pose)));
    }
    let jc_node = doc.req(g, at, "joint_constraints")?;
    let jcs = doc.seq(jc_node, &format!("{at}.joint_constraints"))?;
    let mut s = slots(doc, model, warnings);
    for (i, c) in jcs.iter().enumerate() {
        let cat = format!("{at}.joint_constraints[{i}]");
        doc.map(c, &cat)?;
        let n = doc.req(c, &cat, "joint_name")?;
        let name = doc.str(n, &format!("{cat}.joint_name"))?;
        let p = doc.req(c, &cat, "position")?;
        let value = doc.num(p, &format!("{cat}.position"))?;
        s.set(n, &format!("{cat}.joint_name"), name, value)?;
    }
    Ok((s.finish(jc_node, &format!("{at}.joint_constraints"))?, None))
}
