//! The query arguments of `armsim.plan` / `Planner.plan` beyond joint values: the search
//! (`planner`, `budget_iterations`, `budget_ms`), a tool-pose goal (`goal_pose`) and path
//! constraints (`path_constraints`), read from Python values into the crate's
//! [`PlannerKind`], [`OptimiseBudget`], [`PoseGoal`] and [`PathConstraint`].
//!
//! - `goal_pose`: a dict `{"link": name or index (default the tool link,
//!   `Model::tool_link`), "pose": 4×4 homogeneous transform of the link frame in the
//!   world}` or, to reach a position in any
//!   orientation, `{"link": …, "position": [x, y, z]}` (exactly one of the two). The
//!   planner reaches the pose exactly (every goal is checked to 1e-9 m and rad), so there
//!   are no tolerance keys.
//! - `path_constraints`: a list of dicts, each with `type` and `link` (default the tool):
//!   `"axis"` with `axis` (link frame), `direction` (world) and `tolerance` (rad, in
//!   (0, π)): the link's axis stays within the angle of the direction; `"orientation"`
//!   with `rotation` (3×3, world) and `tolerance`: the geodesic angle to it; `"position"`
//!   with `offset` (link frame, default 0), `shape` (`box` with `size`, full extents;
//!   `sphere` with `radius`; `cylinder` with `radius` and `length`, full length along its
//!   `z`), `xyz` and `rpy` (the region's frame, default the world's): the point stays in
//!   the region. Shapes and placements read as the obstacle dicts do.
//!
//! Every key is checked (finite, in range); unknown keys and keys of another kind are
//! refused, each error naming `goal_pose.key` or `path_constraints[i].key`.

use crate::args;
use crate::errors::err;
use armsim::core::spatial::{Mat3, Se3, Vec3};
use armsim::model::Model;
use armsim::planning::path_constraints::{ConstraintKind, PathConstraint, RegionShape};
use armsim::planning::plan_options::{
    OptimiseBudget, PlannerKind, MAX_OPTIMISE_ITERATIONS, MAX_TIME_LIMIT_MS,
};
use armsim::planning::pose_goal::PoseGoal;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::time::Duration;

/// Largest coordinate or size (m) a pose dict accepts.
const MAX_LENGTH: f64 = 1e4;

/// The search a query asks for: `planner` and its budget (refused with RRT-Connect, which
/// stops at its first path, as `armsim plan` refuses `--budget-*`).
pub fn search(
    planner: &str,
    budget_iterations: Option<args::Int>,
    budget_ms: Option<f64>,
) -> PyResult<(PlannerKind, OptimiseBudget)> {
    let kind = PlannerKind::from_name(planner).ok_or_else(|| {
        err(format!(
            "planner: expected 'rrt-connect' or 'aorrtc', got '{planner}'"
        ))
    })?;
    let mut budget = OptimiseBudget::default();
    if kind == PlannerKind::RrtConnect {
        for (key, given) in [
            ("budget_iterations", budget_iterations.is_some()),
            ("budget_ms", budget_ms.is_some()),
        ] {
            if given {
                return Err(err(format!(
                    "{key} applies to planner='aorrtc' (RRT-Connect stops at its first path)"
                )));
            }
        }
        return Ok((kind, budget));
    }
    if let Some(n) = budget_iterations {
        let n = args::size(n, "budget_iterations")?;
        if !(1..=MAX_OPTIMISE_ITERATIONS).contains(&n) {
            return Err(err(format!(
                "budget_iterations: expected 1 … {MAX_OPTIMISE_ITERATIONS}, got {n}"
            )));
        }
        budget.iterations = n;
    }
    if let Some(t) = budget_ms {
        if !(t.is_finite() && t > 0.0 && t <= MAX_TIME_LIMIT_MS) {
            return Err(err(format!(
                "budget_ms: expected a positive number of milliseconds (at most 1e9), got {t}"
            )));
        }
        budget.time = Some(Duration::from_secs_f64(t / 1e3));
    }
    Ok((kind, budget))
}

/// One dict's keys, read with its place (`goal_pose` or `path_constraints[i]`) in errors.
struct Keys<'a, 'py> {
    d: &'a Bound<'py, PyDict>,
    at: String,
}

impl Keys<'_, '_> {
    fn key(&self, k: &str) -> String {
        format!("{}.{k}", self.at)
    }

    fn get(&self, k: &str) -> PyResult<Option<Bound<'_, PyAny>>> {
        self.d.get_item(k)
    }

    fn required(&self, k: &str) -> PyResult<Bound<'_, PyAny>> {
        self.get(k)?
            .ok_or_else(|| err(format!("{}: missing", self.key(k))))
    }

    /// Refuses keys outside `allowed` (`what` says what the dict is).
    fn only(&self, allowed: &[&str], what: &str) -> PyResult<()> {
        for k in self.d.keys() {
            let k: String = k
                .extract()
                .map_err(|_| err(format!("{}: keys must be strings", self.at)))?;
            if !allowed.contains(&k.as_str()) {
                return Err(err(format!(
                    "{}: not a key of {what} (its keys: {})",
                    self.key(&k),
                    allowed.join(", ")
                )));
            }
        }
        Ok(())
    }

    /// The link `link` names (a name or an index), the tool link when not given.
    fn link(&self, model: &Model) -> PyResult<usize> {
        match self.get("link")? {
            None => Ok(model.tool_link()),
            Some(v) => args::frame(model, &v)
                .map_err(|e| err(format!("{}: {}", self.key("link"), e.value(self.d.py())))),
        }
    }

    /// A number in `(0, max]` (`open_max`: `(0, max)`), with its unit in the message.
    fn positive(&self, k: &str, max: f64, open_max: bool, unit: &str) -> PyResult<f64> {
        let v: f64 = self
            .required(k)?
            .extract()
            .map_err(|_| err(format!("{}: expected a number", self.key(k))))?;
        let below = if open_max { v < max } else { v <= max };
        if v.is_finite() && v > 0.0 && below {
            Ok(v)
        } else {
            let close = if open_max { ")" } else { "]" };
            Err(err(format!(
                "{}: expected a number in (0, {max}{close} {unit}, got {v}",
                self.key(k)
            )))
        }
    }

    /// Three finite numbers of magnitude at most [`MAX_LENGTH`] (`default` when absent).
    fn triple(&self, k: &str, default: Option<[f64; 3]>) -> PyResult<[f64; 3]> {
        let v = match (self.get(k)?, default) {
            (Some(v), _) => v,
            (None, Some(d)) => return Ok(d),
            (None, None) => return Err(err(format!("{}: missing", self.key(k)))),
        };
        let x: Vec<f64> = v
            .extract()
            .map_err(|_| err(format!("{}: expected three numbers", self.key(k))))?;
        if x.len() != 3 || !x.iter().all(|v| v.is_finite() && v.abs() <= MAX_LENGTH) {
            return Err(err(format!(
                "{}: expected three finite numbers (at most {MAX_LENGTH:e} in magnitude), got {x:?}",
                self.key(k)
            )));
        }
        Ok([x[0], x[1], x[2]])
    }

    /// A unit vector: three finite numbers, not zero, normalised.
    fn direction(&self, k: &str) -> PyResult<Vec3> {
        let [x, y, z] = self.triple(k, None)?;
        let v = Vec3::new(x, y, z);
        if v.norm() < 1e-9 {
            return Err(err(format!(
                "{}: expected a non-zero direction, got [{x}, {y}, {z}]",
                self.key(k)
            )));
        }
        Ok(v / v.norm())
    }

    /// An `n`×`n` matrix of finite numbers, row-major.
    fn matrix(&self, k: &str, n: usize) -> PyResult<Vec<f64>> {
        let rows: Vec<Vec<f64>> = self
            .required(k)?
            .extract()
            .map_err(|_| err(format!("{}: expected a {n}×{n} array", self.key(k))))?;
        if rows.len() != n || rows.iter().any(|r| r.len() != n) {
            return Err(err(format!(
                "{}: expected a {n}×{n} array, got {} rows",
                self.key(k),
                rows.len()
            )));
        }
        let flat: Vec<f64> = rows.into_iter().flatten().collect();
        if let Some(i) = flat.iter().position(|v| !v.is_finite()) {
            return Err(err(format!(
                "{}[{}, {}] is not finite",
                self.key(k),
                i / n,
                i % n
            )));
        }
        Ok(flat)
    }

    /// A rotation matrix (orthonormal to 1e-6, determinant +1), re-orthonormalised.
    fn rotation(&self, k: &str) -> PyResult<Mat3> {
        let m = self.matrix(k, 3)?;
        let mut t = [0.0; 16];
        for r in 0..3 {
            t[4 * r..4 * r + 3].copy_from_slice(&m[3 * r..3 * r + 3]);
        }
        t[15] = 1.0;
        crate::convert::check_pose(&t).map_err(|e| err(format!("{}: {e}", self.key(k))))?;
        Ok(orthonormal(crate::convert::se3_from_4x4(&t).rot))
    }
}

/// The nearest rotation to `r` (an almost orthonormal matrix, by its polar factor).
fn orthonormal(r: Mat3) -> Mat3 {
    let svd = r.svd(true, true);
    match (svd.u, svd.v_t) {
        (Some(u), Some(v_t)) => u * v_t,
        _ => r,
    }
}

fn dict<'a, 'py>(obj: &'a Bound<'py, PyAny>, at: &str) -> PyResult<Keys<'a, 'py>> {
    let d = obj
        .cast::<PyDict>()
        .map_err(|_| err(format!("{at}: expected a dict")))?;
    Ok(Keys {
        d,
        at: at.to_string(),
    })
}

/// `goal_pose` (module docs).
pub fn goal_pose(model: &Model, obj: &Bound<'_, PyAny>) -> PyResult<PoseGoal> {
    let k = dict(obj, "goal_pose")?;
    k.only(&["link", "pose", "position"], "a goal pose")?;
    let link = k.link(model)?;
    let (has_pose, has_position) = (k.get("pose")?.is_some(), k.get("position")?.is_some());
    match (has_pose, has_position) {
        (true, false) => {
            let m = k.matrix("pose", 4)?;
            let mut t = [0.0; 16];
            t.copy_from_slice(&m);
            crate::convert::check_pose(&t).map_err(|e| err(format!("goal_pose.pose: {e}")))?;
            let mut target = crate::convert::se3_from_4x4(&t);
            target.rot = orthonormal(target.rot);
            Ok(PoseGoal {
                link,
                target,
                position_only: false,
            })
        }
        (false, true) => {
            let [x, y, z] = k.triple("position", None)?;
            Ok(PoseGoal {
                link,
                target: Se3 {
                    rot: Mat3::identity(),
                    trans: Vec3::new(x, y, z),
                },
                position_only: true,
            })
        }
        _ => Err(err(
            "goal_pose: give exactly one of 'pose' (a 4×4 transform) and 'position' (reach it in any orientation)",
        )),
    }
}

/// `path_constraints` (module docs), each checked against the model.
pub fn path_constraints(model: &Model, obj: &Bound<'_, PyAny>) -> PyResult<Vec<PathConstraint>> {
    let list = obj
        .cast::<PyList>()
        .map_err(|_| err("path_constraints: expected a list of dicts"))?;
    let mut out = Vec::with_capacity(list.len());
    for (i, item) in list.iter().enumerate() {
        let c = constraint(model, &dict(&item, &format!("path_constraints[{i}]"))?)?;
        if let Some(why) = c.problem(model) {
            return Err(err(format!("path_constraints[{i}]: {why}")));
        }
        out.push(c);
    }
    Ok(out)
}

fn constraint(model: &Model, k: &Keys<'_, '_>) -> PyResult<PathConstraint> {
    let kind: String = k
        .required("type")
        .map_err(|_| {
            err(format!(
                "{}: missing (axis, orientation or position)",
                k.key("type")
            ))
        })?
        .extract()
        .map_err(|_| err(format!("{}: expected a string", k.key("type"))))?;
    let pi = std::f64::consts::PI;
    let kind = match kind.as_str() {
        "axis" => {
            k.only(
                &["type", "link", "axis", "direction", "tolerance"],
                "an axis constraint",
            )?;
            ConstraintKind::Axis {
                axis: k.direction("axis")?,
                direction: k.direction("direction")?,
                tolerance: k.positive("tolerance", pi, true, "rad")?,
            }
        }
        "orientation" => {
            k.only(
                &["type", "link", "rotation", "tolerance"],
                "an orientation constraint",
            )?;
            ConstraintKind::Orientation {
                rotation: k.rotation("rotation")?,
                tolerance: k.positive("tolerance", pi, true, "rad")?,
            }
        }
        "position" => position(k)?,
        other => {
            return Err(err(format!(
                "{}: expected axis, orientation or position, got '{other}'",
                k.key("type")
            )))
        }
    };
    Ok(PathConstraint {
        link: k.link(model)?,
        kind,
    })
}

/// A position constraint: the point `offset` inside a box, sphere or cylinder.
fn position(k: &Keys<'_, '_>) -> PyResult<ConstraintKind> {
    let shape: String = k
        .required("shape")
        .map_err(|_| {
            err(format!(
                "{}: missing (box, sphere or cylinder)",
                k.key("shape")
            ))
        })?
        .extract()
        .map_err(|_| err(format!("{}: expected a string", k.key("shape"))))?;
    let common = ["type", "link", "offset", "shape", "xyz", "rpy"];
    let (region, own): (RegionShape, &[&str]) = match shape.as_str() {
        "box" => {
            let [x, y, z] = k.triple("size", None)?;
            if !(x > 0.0 && y > 0.0 && z > 0.0) {
                return Err(err(format!(
                    "{}: expected three sizes > 0 (m), got [{x}, {y}, {z}]",
                    k.key("size")
                )));
            }
            let half = [x / 2.0, y / 2.0, z / 2.0];
            (RegionShape::Box { half }, &["size"])
        }
        "sphere" => (
            RegionShape::Sphere {
                radius: k.positive("radius", MAX_LENGTH, false, "m")?,
            },
            &["radius"],
        ),
        "cylinder" => (
            RegionShape::Cylinder {
                radius: k.positive("radius", MAX_LENGTH, false, "m")?,
                half_length: k.positive("length", MAX_LENGTH, false, "m")? / 2.0,
            },
            &["radius", "length"],
        ),
        other => {
            return Err(err(format!(
                "{}: expected box, sphere or cylinder, got '{other}'",
                k.key("shape")
            )))
        }
    };
    let allowed: Vec<&str> = common.iter().chain(own).copied().collect();
    k.only(&allowed, &format!("a {shape} position constraint"))?;
    let [ox, oy, oz] = k.triple("offset", Some([0.0; 3]))?;
    let xyz = k.triple("xyz", Some([0.0; 3]))?;
    let rpy = k.triple("rpy", Some([0.0; 3]))?;
    Ok(ConstraintKind::Position {
        offset: Vec3::new(ox, oy, oz),
        pose: Se3::from_xyz_rpy(xyz, rpy),
        shape: region,
    })
}
