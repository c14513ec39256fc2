//! `armsim.plan` and `Robot.plan`: collision-free RRT-Connect paths (`armsim plan`) around
//! the obstacles of a MoveIt `PlanningScene` file, start and goal given or read from a
//! MoveIt `MotionPlanRequest` file, self pairs from an SRDF or by sampling.

use crate::args::vector;
use crate::errors::{err, require_file};
use armsim::model::Model;
use armsim::planning::{moveit, srdf, PlanOptions, PlanStatus, Planner};
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::time::Duration;

/// What a plan call takes besides the model.
pub struct PlanArgs<'py> {
    pub start: Option<Bound<'py, PyAny>>,
    pub goal: Option<Bound<'py, PyAny>>,
    pub scene: Option<PathBuf>,
    pub request: Option<PathBuf>,
    pub srdf: Option<PathBuf>,
    pub seed: u64,
    pub time_limit_ms: f64,
    pub simplify: bool,
    pub range: f64,
}

/// Plans on `model`; returns the result as a dict (`status`, `reason`, `path` as an
/// `(N, nv)` array, `iterations`, `plan_time_us`, `simplify_time_us`, `cost_initial`,
/// `cost`, `joints`).
pub fn plan<'py>(py: Python<'py>, model: &Model, a: PlanArgs<'py>) -> PyResult<Bound<'py, PyDict>> {
    let (start, goal) = ends(model, &a)?;
    let root = model.links[0].name.clone();
    let obstacles = match &a.scene {
        Some(p) => {
            require_file(p)?;
            moveit::load_scene_in(p, &[root.as_str()]).map_err(err)?
        }
        None => Vec::new(),
    };
    let pairs = match &a.srdf {
        Some(p) => {
            require_file(p)?;
            Some(srdf::load_disabled_pairs(p, model).map_err(err)?.0)
        }
        None => None,
    };
    if !(a.time_limit_ms.is_finite() && a.time_limit_ms > 0.0) {
        return Err(err(format!(
            "time_limit_ms: expected a positive number, got {}",
            a.time_limit_ms
        )));
    }
    if !(a.range.is_finite() && a.range > 0.0 && a.range <= 100.0) {
        return Err(err(format!(
            "range: expected a positive joint-space distance (at most 100), got {}",
            a.range
        )));
    }
    let mut opts = PlanOptions {
        seed: a.seed,
        time_limit: Some(Duration::from_secs_f64(a.time_limit_ms / 1e3)),
        simplify: a.simplify,
        ..Default::default()
    };
    opts.rrt.range = a.range as f32;
    let r = py.detach(|| -> Result<_, String> {
        let mut planner = Planner::new(model, &obstacles, pairs.as_deref(), opts)?;
        Ok(planner.plan(&start, &goal))
    });
    let r = r.map_err(err)?;
    let d = PyDict::new(py);
    let status = match r.status {
        PlanStatus::Solved => "solved",
        PlanStatus::Failed => "failed",
        PlanStatus::InvalidStart => "invalid_start",
        PlanStatus::InvalidGoal => "invalid_goal",
    };
    d.set_item("status", status)?;
    d.set_item("reason", r.reason)?;
    let path = if r.path.is_empty() {
        PyArray2::<f64>::zeros(py, [0, model.nv], false)
    } else {
        PyArray2::from_vec2(py, &r.path).map_err(err)?
    };
    d.set_item("path", path)?;
    d.set_item("iterations", r.iterations)?;
    d.set_item("plan_time_us", r.plan_time_us)?;
    d.set_item("simplify_time_us", r.simplify_time_us)?;
    d.set_item("cost_initial", r.cost_initial)?;
    d.set_item("cost", r.cost)?;
    d.set_item("joints", model.dof_names())?;
    Ok(d)
}

/// Start and goal: given, or read from the request file (given ones win).
fn ends(model: &Model, a: &PlanArgs<'_>) -> PyResult<(Vec<f64>, Vec<f64>)> {
    let req = match &a.request {
        Some(p) => {
            require_file(p)?;
            Some(moveit::load_request(p, model).map_err(err)?.0)
        }
        None => None,
    };
    let pick =
        |given: &Option<Bound<'_, PyAny>>, what: &str, from: Option<&Vec<f64>>| match (given, from)
        {
            (Some(q), _) => Ok(vector(q, what, model.nv)?.slice().to_vec()),
            (None, Some(q)) => Ok(q.clone()),
            (None, None) => Err(err(format!("{what}: give it, or a request file"))),
        };
    let start = pick(&a.start, "start", req.as_ref().map(|r| &r.start))?;
    let goal = pick(&a.goal, "goal", req.as_ref().map(|r| &r.goal))?;
    Ok((start, goal))
}

/// Plans a collision-free path for `model` (see the module docs).
#[pyfunction(name = "plan")]
#[pyo3(signature = (model, start=None, goal=None, scene=None, request=None, srdf=None, seed=0, time_limit_ms=1000.0, simplify=true, range=1.0))]
#[allow(clippy::too_many_arguments)]
pub fn plan_py<'py>(
    py: Python<'py>,
    model: PyRef<'py, crate::model::PyModel>,
    start: Option<Bound<'py, PyAny>>,
    goal: Option<Bound<'py, PyAny>>,
    scene: Option<PathBuf>,
    request: Option<PathBuf>,
    srdf: Option<PathBuf>,
    seed: u64,
    time_limit_ms: f64,
    simplify: bool,
    range: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let m = std::sync::Arc::clone(&model.model);
    plan(
        py,
        &m,
        PlanArgs {
            start,
            goal,
            scene,
            request,
            srdf,
            seed,
            time_limit_ms,
            simplify,
            range,
        },
    )
}
